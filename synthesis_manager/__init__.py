"""synthesis_manager: the /behavior_synthesis action server, the command line and the ROS runtime.

Modules:
    server_node   the action server orchestrating compilation, synthesis and generation
    suite         the four pipeline nodes, their settings, and an in-process suite
    client        a client of /behavior_synthesis (send-goal, demo, execute, GUI)
    conversions   ROS messages <-> the ROS-free cores
    requests      goal-string parsing and option checks
    ros_env       prepares the ROS 2 environment (DDS on loopback) before rclpy.init()
    harness       in-process ROS (private domain, executor thread) for tests and tools
    node_main     running nodes in a process until SIGINT/SIGTERM
    cli           the ``behavior-synthesis`` console script and its subcommands
    webapp, gui   the web GUI
"""
