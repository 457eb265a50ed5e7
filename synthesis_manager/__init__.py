"""synthesis_manager: the ROS/HTTP shell around the ROS-free cores.

Modules:
    nodes/        the service/action nodes (compilation, synthesis, generation, server, atlas_sim)
    ros/          ROS runtime: environment, node main, message conversions, in-process harness
    web/          the web GUI (FastAPI routes, jobs, downloads, static files)
    suite         the four pipeline nodes, their settings, and an in-process suite
    client        a client of /behavior_synthesis (send-goal, demo, execute, GUI)
    requests      option checks of behavior synthesis requests
    cli           the ``behavior-synthesis`` console script and its subcommands
    gui           ``behavior-synthesis gui``: the web GUI wired to ROS
"""
