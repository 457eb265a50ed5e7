"""The ROS nodes: thin adapters between synthesis_msgs and the ROS-free cores (the robot that
drives atlas_sim_node for the executive is not a node: ``synthesis_manager.ros.atlas_sim_robot``).

    ltl_compilation_node   ``ltl_compilation`` service -> ltl_specification.compile_task
    ltl_synthesis_node     ``ltl_synthesis`` service -> ltl_synthesizer.service (our synthesizer or slugs)
    sm_generation_node     ``sm_generate`` service -> sm_generation.generate_state_machine
    server_node            the ``/behavior_synthesis`` action server orchestrating the three
    atlas_sim_node         ``atlas_sim/execute`` action and ``atlas_sim/state`` topic around atlas_sim
"""
