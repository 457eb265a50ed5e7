"""The programs: the ``behavior-synthesis`` command line (``cli``) and its commands, each a thin
adapter over the helpers of ``synthesis_manager`` and the ROS-free cores.

    cli              the command line: one subcommand per module below
    demo             run the paper's task end to end and write the artifacts
    serve            the synthesis suite until SIGINT/SIGTERM (``launch_serve``: as ``ros2 launch`` arguments)
    send_goal        a goal to a running suite, its feedback and result
    execute          synthesize and run the behavior on the simulated robot
    export_behavior  synthesize and write a FlexBE behavior package
    start_behavior   start an installed behavior on the FlexBE onboard engine
    gui              the web GUI on 127.0.0.1
"""
