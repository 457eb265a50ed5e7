"""atlas_sim.executive: runs synthesized state machines on a robot and checks the runs (ROS-free).

Robot-agnostic: it drives anything with the ``Robot`` protocol and reads the machine as
``sm_generation``'s :class:`~sm_generation.state_machine.StateMachine` tree.

``robot``        the ``Robot`` protocol, ``CapabilityResult``.
``errors``       the executive's errors; ``next_target``.
``executor``     runs a synthesized state machine on a robot (``execute_state_machine``).
``engine_trace`` the same trace from a run on another engine (the real FlexBE).
``trace_check``  checks an executed trace against the specification and the goal order.
``timeline``     draws a trace's timeline.
"""
