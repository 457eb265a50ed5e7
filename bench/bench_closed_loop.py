"""Robot (sim) time vs wall time of the closed-loop tasks, direct and over ROS (prints a table)."""
import time
from rclpy.node import Node
from rclpy.parameter import Parameter
from ltl_specification import compile_task
from ltl_synthesizer import synthesize
from ltl_synthesizer.automaton import automaton_from_strategy
from sm_generation import generate_state_machine
from atlas_sim.executor import SimulatedRobot, execute_state_machine, make_simulator, parse_faults
from atlas_sim.trace_check import check_trace

TASKS = [('pickup', ['stand_prep'], ['look_down', 'pickup_object'], ('finished', 'failed'), {}),
         ('pickup fails', ['stand_prep'], ['look_down', 'pickup_object'], ('finished', 'failed'), {'fail': ['pickup_object']}),
         ('footsteps', ['manipulate'], ['footstep_execution'], ('finished', 'failed'), {}),
         ('walk', ['stand_prep'], ['walk'], ('finished', 'failed'), {}),
         ('retry x2', ['stand_prep'], ['look_down', 'pickup_object'], ('finished',), {'fail_first': ['pickup_object:2']})]

def machine(ic, goals, outs):
    spec = compile_task('atlas', ic, goals, sm_outcomes=outs)
    r = synthesize(spec)
    return spec, generate_state_machine(automaton_from_strategy(r.strategy, spec), 'atlas', initial_conditions=ic)

print(f"{'task':<14}{'path':<8}{'robot s':>9}{'wall s':>9}{'x real':>8}{'check s':>9}  outcome")
for name, ic, goals, outs, faults in TASKS:
    spec, states = machine(ic, goals, outs)
    sim = make_simulator('atlas', initial_conditions=ic, faults=parse_faults(**faults))
    t = time.perf_counter(); run = execute_state_machine(states, SimulatedRobot(sim)); w = time.perf_counter() - t
    t = time.perf_counter(); ok = check_trace(run.trace, spec, goals=goals).ok; c = time.perf_counter() - t
    print(f"{name:<14}{'direct':<8}{run.robot_time:9.2f}{w:9.2f}{run.robot_time / w:8.1f}{c:9.3f}  {run.outcome} ok={ok}")
from synthesis_manager.harness import RosHarness
from atlas_sim.node import AtlasSimNode
from atlas_sim.ros_robot import RosRobot
for speed in (10.0, 50.0):
    for name, ic, goals, outs, faults in TASKS:
        spec, states = machine(ic, goals, outs)
        with RosHarness() as ros:
            sim = make_simulator('atlas', initial_conditions=ic, faults=parse_faults(**faults))
            ros.add_node(AtlasSimNode, simulator=sim, parameter_overrides=[Parameter('speed', value=speed), Parameter('state_rate', value=50.0)])
            robot = RosRobot(ros.add_node(Node, 'bench')); robot.wait_until_ready()
            start_sim = sim.time
            t = time.perf_counter(); run = execute_state_machine(states, robot, max_wall_time=120); w = time.perf_counter() - t
            robot_s = run.duration
            ok = check_trace(run.trace, spec, goals=goals).ok
        print(f"{name:<14}{'ros x' + str(int(speed)):<8}{robot_s:9.2f}{w:9.2f}{robot_s / w:8.1f}{'':>9}  {run.outcome} ok={ok}")
