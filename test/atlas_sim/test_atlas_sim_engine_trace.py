"""EngineTraceRecorder: the trace of a run driven by another engine, from its states and the simulator.

Here the "engine" is the test itself (no FlexBE needed): it enters the machine's states,
starts their capabilities on the simulator as FlexBE's states would and reports the
outcomes; the recorded trace must check clean and match what our executive records.
"""

import pytest

from atlas_sim.executive.engine_trace import EngineTraceRecorder
from atlas_sim.executive.executor import execute_state_machine
from atlas_sim.executive.trace_check import check_trace
from atlas_sim.simulated_robot import SimulatedRobot
from atlas_sim.simulator.factory import make_simulator
from ltl_specification import compile_task
from ltl_synthesizer import synthesize
from respec.automaton import automaton_from_strategy
from respec.robot import robot_system
from sm_generation import generate_state_machine

pytestmark = pytest.mark.mujoco

ATLAS = robot_system('atlas')

INITIAL, GOALS = ['stand_prep'], ['walk']


def machine():
    spec = compile_task(ATLAS, INITIAL, GOALS)
    automaton = automaton_from_strategy(synthesize(spec).strategy, spec)
    return spec, generate_state_machine(automaton, ATLAS, initial_conditions=INITIAL)


def drive(machine, simulator, recorder):
    """Run the top-level states one by one like an engine: enter, request, wait, return."""
    outcomes = {'changed': 'completed', 'failed': 'failed'}
    by_name = {s.name: s for s in machine.states}
    current = machine.initial_state_name
    while current in by_name:
        state = by_name[current]
        recorder.entered(current)
        request = simulator.start(current)  # these machines activate the capability named like the state
        while request.result is None:
            simulator.step()
        outcome = next(o for o in state.outcomes if outcomes[o] == request.result.outcome)
        recorder.returned(current, outcome)
        current = state.transitions[state.outcomes.index(outcome)]
    return current


def test_recorded_trace_checks_clean_and_matches_our_executive():
    spec, states = machine()
    simulator = make_simulator(ATLAS, initial_conditions=INITIAL)
    recorder = EngineTraceRecorder(states, simulator, ATLAS)
    end = drive(states, simulator, recorder)
    recorder.close()
    run = recorder.result()
    assert end == 'finished' and run.outcome == 'finished' and not run.fallen
    assert check_trace(run.trace, spec, goals=GOALS).ok
    ours = execute_state_machine(states, SimulatedRobot(make_simulator(ATLAS, initial_conditions=INITIAL)), ATLAS)
    assert [(s.state, s.activated, s.state_outcome, s.transition) for s in run.trace.steps] == \
        [(s.state, s.activated, s.state_outcome, s.transition) for s in ours.trace.steps]
    assert [s.outcomes_at_exit for s in run.trace.steps] == [s.outcomes_at_exit for s in ours.trace.steps]
    assert all(r['capability'] in s.capabilities and not r['abandoned'] for s in run.trace.steps for r in s.results)
