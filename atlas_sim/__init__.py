"""atlas_sim: a MuJoCo humanoid that emulates ATLAS, and the executive that runs synthesized
behaviors on a robot (ROS-free). One job per sub-package:

``atlas_sim.simulator``  the MuJoCo simulator of a robot-system config's capabilities (control
                         modes, actions, sensors), robot-agnostic of the state machine.
``atlas_sim.executive``  the FlexBE-compatible executive that runs a synthesized state machine
                         on any robot with the ``Robot`` protocol, and the trace check
                         (robot-agnostic; reads ``sm_generation``'s StateMachine tree).
``simulated_robot``      the simulator as the executive's robot (``SimulatedRobot``).
``closed_loop``          ``run_and_check``: execute on the simulator, record key frames, check,
                         draw the timeline.

``atlas_sim/flexbe/`` holds the FlexBE state and behavior packages for the simulator node
(ROS packages of their own, not part of this Python package).

How to drive the simulator from Python (a typical session and the AtlasSimulator API):
docs/simulation.md, "The simulator from Python".
"""
