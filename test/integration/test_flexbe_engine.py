"""Synthesized behaviors on the real FlexBE engine (FLEXBE_SOURCES) against the simulated ATLAS.

The exported behavior package loads in flexbe_core and its ``create()`` builds the machine;
closed loops (the paper's two tasks, a failure, a retry) run on the engine the way
flexbe_onboard runs a behavior, its states driving the atlas_sim node over ROS 2, and the
trace checks clean against the specification.
"""

import pytest
from rclpy.node import Node
from rclpy.parameter import Parameter

from atlas_sim.executive.trace_check import check_trace
from atlas_sim.simulator.factory import make_simulator, parse_faults
from ltl_specification import compile_task
from ltl_synthesizer import synthesize
from respec.automaton import automaton_from_strategy
from sm_generation import generate_state_machine
from respec.robot import robot_system
from sm_generation.config import flexbe_config
from sm_generation.flexbe_behavior import behavior_package
from synthesis_manager.nodes.atlas_sim_node import AtlasSimNode

pytestmark = [pytest.mark.usefixtures('flexbe'), pytest.mark.ros, pytest.mark.mujoco, pytest.mark.flexbe]

PICKUP = (['stand_prep'], ['look_down', 'pickup_object'])
FOOTSTEPS = (['manipulate'], ['footstep_execution'])


def synthesized(initial_conditions, goals, sm_outcomes=('finished', 'failed')):
    spec = compile_task(robot_system('atlas'), initial_conditions, goals, sm_outcomes=sm_outcomes)
    automaton = automaton_from_strategy(synthesize(spec).strategy, spec)
    return spec, generate_state_machine(automaton, robot_system('atlas'), initial_conditions=initial_conditions)


def test_exported_behavior_loads_in_flexbe_core_and_create_builds_the_machine(ros, tmp_path):
    from flexbe_core import ConcurrencyContainer, OperatableStateMachine, set_node

    from synthesis_manager.ros.flexbe_engine import load_behavior_class, reset_flexbe_proxies

    _, machine = synthesized(*PICKUP)
    package = behavior_package(machine, flexbe_config(robot_system('atlas')), 'Look Down And Pickup')
    states = machine.to_instantiations()
    behavior_class, _ = load_behavior_class(package, tmp_path)
    node = ros.add_node(Node, 'flexbe_create_test')
    set_node(node)
    try:
        behavior = behavior_class(node)
        machine = behavior.create()
    finally:
        reset_flexbe_proxies(ros.executor, node)
    assert isinstance(machine, OperatableStateMachine)
    root = states[0]
    assert list(machine.outcomes) == root.outcomes
    top = {s.name: s for s in states if s.parent_path == '/' and s.state_class != ':OUTCOME'}
    assert {s.name for s in machine._states} == set(top)
    assert machine._states[0].name == root.initial_state_name  # the first state added starts
    for state in machine._states:
        entry = top[state.name]
        assert list(state.outcomes) == entry.outcomes
        transitions = {o: t for o, t in machine._transitions[state.name].items() if o != 'preempted'}  # FlexBE's own
        assert transitions == dict(zip(entry.outcomes, entry.transitions))
        assert isinstance(state, ConcurrencyContainer) == (entry.state_class == ':CONCURRENCY')
    pickup = next(s for s in machine._states if s.name == 'pickup_object')
    assert 'template_id' in pickup.input_keys


def run_task(ros, initial_conditions, goals, sm_outcomes=('finished', 'failed'), faults=None):
    from synthesis_manager.ros.flexbe_engine import run_on_flexbe

    spec, states = synthesized(initial_conditions, goals, sm_outcomes)
    simulator = make_simulator(robot_system('atlas'), initial_conditions=initial_conditions, faults=faults)
    node = ros.add_node(AtlasSimNode, simulator=simulator, parameter_overrides=[
        Parameter('speed', value=20.0), Parameter('state_rate', value=50.0)])
    run = run_on_flexbe(states, simulator, node.lock, ros.domain_id, robot_system('atlas'), max_wall_time=120.0)
    report = check_trace(run.trace, spec, goals=goals)
    assert report.ok, report.summary()
    assert not run.fallen
    return run, simulator


@pytest.mark.parametrize('task', [PICKUP, FOOTSTEPS], ids=['pickup', 'footsteps'])
def test_paper_tasks_finish_on_the_flexbe_engine(ros, task):
    run, simulator = run_task(ros, *task)
    assert run.outcome == 'finished'
    assert run.trace.steps[-1].state_outcome and run.trace.steps[-1].transition == 'finished'
    if 'pickup_object' in task[1]:
        assert simulator.snapshot()['holding_object']


def test_a_failing_pickup_ends_failed_on_the_flexbe_engine(ros):
    run, simulator = run_task(ros, *PICKUP, faults=parse_faults(fail=['pickup_object']))
    assert run.outcome == 'failed'
    assert [s.state for s in run.trace.steps][-1] == '/pickup_object'
    assert not simulator.snapshot()['holding_object']


def test_retry_until_finished_on_the_flexbe_engine(ros):
    run, simulator = run_task(ros, *PICKUP, sm_outcomes=('finished',),
                              faults=parse_faults(fail_first=['pickup_object:2']))
    assert run.outcome == 'finished'
    attempts = [r for s in run.trace.steps for r in s.results if r['capability'] == 'pickup_object']
    assert [r['outcome'] for r in attempts] == ['failed', 'failed', 'completed']
    assert simulator.snapshot()['holding_object']


def test_an_outcome_the_operator_forces_on_the_engine_is_the_operators_in_the_trace(ros):
    """Autonomy Off: the first state waits for the operator, who forces ``failed`` with FlexBE's
    transition command (as the WebUI's Runtime Control does); the trace says who chose it."""
    import threading

    from flexbe_msgs.msg import OutcomeRequest

    from synthesis_manager.ros.flexbe_engine import run_on_flexbe

    spec, machine = synthesized(*PICKUP)
    first = next(s for s in machine.states if s.name == machine.initial_state_name)
    simulator = make_simulator(robot_system('atlas'), initial_conditions=PICKUP[0])
    node = ros.add_node(AtlasSimNode, simulator=simulator, parameter_overrides=[
        Parameter('speed', value=20.0), Parameter('state_rate', value=50.0)])
    operator = ros.add_node(Node, 'forcing_operator')
    commands = operator.create_publisher(OutcomeRequest, 'flexbe/command/transition', 10)
    done = {}
    runner = threading.Thread(target=lambda: done.update(run=run_on_flexbe(
        machine, simulator, node.lock, ros.domain_id, robot_system('atlas'), autonomy=0, max_wall_time=60.0)))
    runner.start()
    while runner.is_alive():  # the command is read while the state waits (buffered until then)
        commands.publish(OutcomeRequest(outcome=first.outcomes.index('failed'), target=first.name))
        runner.join(timeout=0.5)
    run = done['run']
    assert run.outcome == 'failed'
    step = run.trace.steps[0]
    assert (step.state, step.state_outcome, step.forced) == (first.state_path, 'failed', 'failed')
    assert step.forced_propositions == [f'{first.name}_f']  # read as reported: the operator's failure
    # Never blamed on the machine: whether the robot had changed mode when the operator said
    # failed decides whether the task's assumptions hold; if not, the check says who broke them.
    report = check_trace(run.trace, spec, goals=PICKUP[1])
    assert all(v.kind == 'forced_outcome' and v.message.startswith(f'the operator forced failed on {first.name} at step 0')
               for v in report.violations), report.summary()


def run_cli(capsys, *arguments):
    from synthesis_manager.programs.cli import main

    code = main(list(arguments))
    return code, capsys.readouterr()


@pytest.mark.parametrize('arguments, code, outcome', [
    ((), 0, 'finished'),
    (('--fail', 'pickup_object'), 6, 'failed'),  # ExitStatus.OTHER_OUTCOME
    (('--sm-outcomes', 'finished', '--fail-first', 'pickup_object:2'), 0, 'finished')],
    ids=['finished', 'failed', 'retry'])
def test_execute_on_the_flexbe_engine_prints_the_usual_report(capsys, arguments, code, outcome):
    import json

    exit_code, output = run_cli(capsys, 'execute', '--engine', 'flexbe', '--json', '--speed', '20',
                                '--initial-conditions', 'stand_prep', '--goals', 'look_down,pickup_object',
                                *arguments)
    report = json.loads(output.out)
    assert exit_code == code, output.err[-2000:]
    assert report['outcome'] == outcome and report['fallen'] is False
    assert report['trace_check']['ok'] and report['trace']['steps'][-1]['state'].startswith('/pickup_object')


def test_export_behavior_writes_the_package_the_editor_would(capsys, tmp_path):
    import xml.etree.ElementTree as ET

    code, output = run_cli(capsys, 'export-behavior', '--system', 'atlas', '--initial-conditions', 'stand_prep',
                           '--goals', 'look_down,pickup_object', '-o', str(tmp_path))
    assert code == 0, output.err
    folder = tmp_path / 'synthesized_flexbe_behaviors'
    manifest = ET.parse(folder / 'manifest' / 'look_down_pickup_object.xml').getroot()
    assert manifest.get('name') == 'Look Down Pickup Object'
    executable = manifest.find('executable')
    module = executable.get('package_path').split('.')
    assert (folder / module[0] / f'{module[1]}.py').is_file() and executable.get('class') == 'LookDownPickupObjectSM'
    assert [c.get('name') for c in manifest.findall('contains')] == ['Pickup Object']
    assert '<flexbe_behaviors />' in (folder / 'package.xml').read_text()
    code, output = run_cli(capsys, 'export-behavior', '--name', '9 lives', '-o', str(tmp_path))
    assert code == 2 and "'9 lives'" in output.err
    assert 'export-behavior: no --goals given: using the demo task' in output.err  # said, not silent


@pytest.mark.parametrize('goals', [['dock'], ['place']])
def test_mobile_manipulator_tasks_on_the_flexbe_engine(ros, goals):
    """The other configured system: its states, the Dock At Charger behavior, userdata through the root."""
    from synthesis_manager.ros.flexbe_engine import run_on_flexbe

    spec = compile_task(robot_system('mobile_manipulator'), ['parked'], goals)
    automaton = automaton_from_strategy(synthesize(spec).strategy, spec)
    states = generate_state_machine(automaton, robot_system('mobile_manipulator'), initial_conditions=['parked'])
    simulator = make_simulator(robot_system('mobile_manipulator'), initial_conditions=['parked'])
    node = ros.add_node(AtlasSimNode, simulator=simulator, parameter_overrides=[
        Parameter('speed', value=20.0), Parameter('state_rate', value=50.0)])
    run = run_on_flexbe(states, simulator, node.lock, ros.domain_id, system=robot_system('mobile_manipulator'),
                        max_wall_time=120.0)
    assert run.outcome == 'finished' and run.trace.steps[-1].state == f'/{goals[-1]}'
    assert check_trace(run.trace, spec, goals=goals).ok


# Not 2x faster (issue 50): `execute --engine flexbe` runs twice (quiet, --verbose), each starting the suite and the
# onboard engine: the comparison is the subject (8.9 s).
def test_execute_on_the_flexbe_engine_is_quiet_unless_verbose():
    """flexbe_core logs ~100 INFO lines a run: shown with --verbose only; nothing else leaks out
    (no 'exception was never retrieved' from callbacks that failed as the nodes went down)."""
    import os
    import re
    import subprocess
    import sys
    from pathlib import Path

    command = [str(Path(sys.executable).parent / 'behavior-synthesis'), 'execute', '--engine', 'flexbe',
               '--speed', '20', '--initial-conditions', 'stand_prep', '--goals', 'look_down,pickup_object']
    quiet = subprocess.run(command, capture_output=True, text=True, timeout=300, env=dict(os.environ))
    assert quiet.returncode == 0, quiet.stderr[-2000:]
    assert 'outcome: finished' in quiet.stdout
    lines = [line for line in quiet.stderr.splitlines() if line.strip()]
    assert all(re.match(r'\[[#.]{30}\] +\d+% ', line) for line in lines), quiet.stderr  # the progress bar only
    assert '100% Generated a state machine' in lines[-1]
    verbose = subprocess.run([*command, '--verbose'], capture_output=True, text=True, timeout=300,
                             env=dict(os.environ))
    assert verbose.returncode == 0, verbose.stderr[-2000:]
    assert len([line for line in verbose.stderr.splitlines() if '[INFO]' in line and '[flexbe_onboard]' in line]) > 20
    assert 'never retrieved' not in verbose.stderr
