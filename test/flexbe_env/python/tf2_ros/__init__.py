"""Stand-in for ROS 2's tf2_ros where no real one is installed (it has no wheel).

flexbe_core imports tf2_ros at module level only for ProxyTransformListener; behaviors that
never look up transforms (ours) run without it. `make flexbe` puts this folder last on the
venv's path, so an installed tf2_ros (a ROS 2 installation, a colcon workspace) always wins.
A state that does ask for transforms gets a clear error instead of wrong data.
"""

_MISSING = ('tf2_ros is not installed (this is the FlexBE test environment stand-in); '
            'transforms need a ROS 2 installation with tf2_ros')


class Buffer:
    def __init__(self, *args, **kwargs):
        raise RuntimeError(_MISSING)


class TransformListener:
    def __init__(self, *args, **kwargs):
        raise RuntimeError(_MISSING)
