"""synthesis_manager: the /behavior_synthesis action server, the command line and the ROS runtime.

Modules:
    ros_env      prepares the ROS 2 environment (DDS on loopback) before rclpy.init()
    cli          the ``behavior-synthesis`` console script
"""
