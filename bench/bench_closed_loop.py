"""Closed-loop runs on the simulated ATLAS: robot (sim) time against wall time.

Runs the closed-loop tasks directly on the simulator and through the simulator node over ROS
(at two pacing speeds), with the real FlexBE engine too when flexbe_core is importable
(`make flexbe`), checks every trace, and prints one table row per run.

    .venv/bin/python bench/bench_closed_loop.py
"""

from __future__ import annotations

import time
from respec.robot import robot_system

ATLAS = robot_system('atlas')

# name, initial conditions, goals, SM outcomes, faults
TASKS = [
    ('pickup', ['stand_prep'], ['look_down', 'pickup_object'], ('finished', 'failed'), {}),
    ('pickup fails', ['stand_prep'], ['look_down', 'pickup_object'], ('finished', 'failed'),
     {'fail': ['pickup_object']}),
    ('footsteps', ['manipulate'], ['footstep_execution'], ('finished', 'failed'), {}),
    ('walk', ['stand_prep'], ['walk'], ('finished', 'failed'), {}),
    ('retry x2', ['stand_prep'], ['look_down', 'pickup_object'], ('finished',),
     {'fail_first': ['pickup_object:2']}),
]
ROS_SPEEDS = (10.0, 50.0)


def synthesized_machine(initial_conditions, goals, sm_outcomes):
    """The specification and the state machine for a task, through the ROS-free cores."""
    from ltl_specification import compile_task
    from ltl_synthesizer import synthesize
    from respec.automaton import automaton_from_strategy
    from sm_generation import generate_state_machine

    spec = compile_task(ATLAS, initial_conditions, goals, sm_outcomes=sm_outcomes)
    automaton = automaton_from_strategy(synthesize(spec).strategy, spec)
    return spec, generate_state_machine(automaton, ATLAS, initial_conditions=initial_conditions)


def run_direct(states, initial_conditions, faults):
    from atlas_sim.executive.executor import execute_state_machine
    from atlas_sim.simulated_robot import SimulatedRobot
    from atlas_sim.simulator.factory import make_simulator, parse_faults

    simulator = make_simulator(ATLAS, initial_conditions=initial_conditions, faults=parse_faults(**faults))
    started = time.perf_counter()
    run = execute_state_machine(states, SimulatedRobot(simulator), ATLAS)
    return run, run.robot_time, time.perf_counter() - started


def run_over_ros(states, initial_conditions, faults, speed):
    from rclpy.node import Node
    from rclpy.parameter import Parameter

    from atlas_sim.executive.executor import execute_state_machine
    from atlas_sim.simulator.factory import make_simulator, parse_faults
    from synthesis_manager.nodes.atlas_sim_node import AtlasSimNode
    from synthesis_manager.ros.atlas_sim_robot import RosRobot
    from synthesis_manager.ros.harness import RosHarness

    with RosHarness() as ros:
        simulator = make_simulator(ATLAS, initial_conditions=initial_conditions,
                                   faults=parse_faults(**faults))
        ros.add_node(AtlasSimNode, simulator=simulator, parameter_overrides=[
            Parameter('speed', value=speed), Parameter('state_rate', value=50.0)])
        robot = RosRobot(ros.add_node(Node, 'bench_robot'))
        robot.wait_until_ready()
        started = time.perf_counter()
        run = execute_state_machine(states, robot, ATLAS, max_wall_time=120)
        return run, run.duration, time.perf_counter() - started


def run_on_flexbe_engine(states, initial_conditions, faults, speed):
    """The real FlexBE engine (flexbe_core from `make flexbe`) drives the simulator node."""
    from rclpy.parameter import Parameter

    from atlas_sim.simulator.factory import make_simulator, parse_faults
    from synthesis_manager.nodes.atlas_sim_node import AtlasSimNode
    from synthesis_manager.ros.flexbe_engine import run_on_flexbe
    from synthesis_manager.ros.harness import RosHarness

    with RosHarness() as ros:
        simulator = make_simulator(ATLAS, initial_conditions=initial_conditions,
                                   faults=parse_faults(**faults))
        node = ros.add_node(AtlasSimNode, simulator=simulator, parameter_overrides=[
            Parameter('speed', value=speed), Parameter('state_rate', value=50.0)])
        started = time.perf_counter()
        run = run_on_flexbe(states, simulator, node.lock, ros.domain_id, ATLAS, max_wall_time=300)
        return run, run.duration, time.perf_counter() - started


def flexbe_available() -> bool:
    try:
        import flexbe_core  # noqa: F401
    except ImportError:
        return False
    return True


def main() -> int:
    from atlas_sim.executive.trace_check import check_trace

    print(f"{'task':<14}{'path':<12}{'robot s':>9}{'wall s':>9}{'x real':>8}  outcome, trace check")
    for name, initial, goals, sm_outcomes, faults in TASKS:
        spec, states = synthesized_machine(initial, goals, sm_outcomes)
        runs = [('direct', lambda: run_direct(states, initial, faults))]
        runs += [(f'ros x{speed:g}', lambda speed=speed: run_over_ros(states, initial, faults, speed))
                 for speed in ROS_SPEEDS]
        if flexbe_available():  # the real FlexBE engine instead of our executive
            runs += [(f'flexbe x{speed:g}', lambda speed=speed: run_on_flexbe_engine(states, initial, faults, speed))
                     for speed in ROS_SPEEDS]
        for path, runner in runs:
            run, robot_seconds, wall_seconds = runner()
            verdict = 'ok' if check_trace(run.trace, spec, goals=goals).ok else 'VIOLATIONS'
            print(f'{name:<14}{path:<12}{robot_seconds:9.2f}{wall_seconds:9.2f}'
                  f'{robot_seconds / wall_seconds:8.1f}  {run.outcome}, {verdict}')
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
