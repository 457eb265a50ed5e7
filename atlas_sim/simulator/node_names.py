"""The ROS 2 names under which the simulator node serves the simulator (plain strings, ROS-free).

One place for both sides of that interface: the node (``synthesis_manager.nodes.atlas_sim_node``)
serves them, the FlexBE states (``atlas_sim/flexbe/atlas_sim_flexbe_states``) and the FlexBE
engine runner (``synthesis_manager.ros.flexbe_engine``) call them.
"""

NODE_NAME = 'atlas_sim'
# synthesis_msgs/action/ExecuteCapability: any capability named in the goal.
ACTION_NAME = 'atlas_sim/execute'
# One ExecuteCapability action per capability or sensor: FlexBE's proxy action client keeps one
# goal per action name, so states running at once (a concurrency container) each need their own.
CAPABILITY_ACTION_PREFIX = 'atlas_sim/capabilities/'
# synthesis_msgs/msg/RobotState.
STATE_TOPIC = 'atlas_sim/state'
