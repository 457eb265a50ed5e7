"""ROS 2 runtime helpers shared by the nodes and the command line.

    env           prepares the environment (DDS on loopback) before rclpy.init()
    node_main     runs nodes in a process until SIGINT/SIGTERM
    conversions   synthesis_msgs messages <-> the ROS-free cores' types
    harness       in-process ROS (private domain, executor thread) for tests and tools
    robot_state   the latest synthesis_msgs/RobotState of a robot (synthesis on the fly)
"""
