"""reduce=True merges bisimilar states and keeps every observable run."""

import copy
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from sm_generation import generate_state_machine, load_automaton, validate_state_machine
from respec.robot import robot_system
from sm_generation.config import StateConfig, flexbe_config
from sm_generation.generator import machine_from_view
from sm_generation.abstract_machine import AutomatonView, AbstractMachine, AbstractState
from sm_generation.reduction import bisimulation_blocks
from sm_generation.traces import TRUNCATED, runs

AUTOMATA = Path(__file__).resolve().parents[1] / 'automata'
DEPTH = 6


def test_runs_of_a_small_machine():
    machine = generate_state_machine(load_automaton(AUTOMATA / 'look_down.yaml'), robot_system('atlas'))
    stand = ('ChangeControlModeActionState', '', ('"stand"',))
    look = ('TiltHeadState', '', ('-45.0',))
    assert runs(machine, DEPTH) == {
        (((stand,), ((stand, 'changed'),)), ((look,), ((look, 'done'),)), ('exit', 'finished')),
        (((stand,), ((stand, 'changed'),)), ((look,), ((look, 'failed'),)), ('exit', 'failed')),
        (((stand,), ((stand, 'failed'),)), ('exit', 'failed')),
    }
    assert runs(machine, 1) == {
        (((stand,), ((stand, 'changed'),)), TRUNCATED),
        (((stand,), ((stand, 'failed'),)), ('exit', 'failed')),
    }


@pytest.mark.parametrize('path', sorted(AUTOMATA.glob('*.yaml')), ids=lambda p: p.stem)
def test_reduced_machine_has_the_same_runs(path):
    automaton = load_automaton(path)
    plain = generate_state_machine(automaton, robot_system('atlas'))
    reduced = generate_state_machine(automaton, robot_system('atlas'), reduce=True)
    assert validate_state_machine(reduced.to_instantiations()) == []
    assert len(reduced.to_instantiations()) <= len(plain.to_instantiations())
    assert runs(reduced, DEPTH) == runs(plain, DEPTH)


def _loop_automaton():
    """stand -> look_down, where a failed look_down retries through two copies of the same loop."""
    automaton = load_automaton(AUTOMATA / 'look_down.yaml')
    states = {s.name: s for s in automaton.states}
    # Replace the failure of look_down by a retry: 2 --look_down_f--> 2b (same outputs as 2),
    # 2b --look_down_f--> 2 ; so 2 and 2b are bisimilar copies.
    retry = copy.deepcopy(states['2'])
    retry.name = '2b'
    retry.input_valuation = [False, False, True, False, False, True]
    retry.transitions = ['2b', '3', '2']
    states['2'].transitions = ['2', '3', '2b']
    automaton.states = [states[n] for n in ('0', '1', '2', '3', '5')] + [retry]
    return automaton


def test_bisimilar_loop_copies_are_merged():
    automaton = _loop_automaton()
    plain = generate_state_machine(automaton, robot_system('atlas'))
    reduced = generate_state_machine(automaton, robot_system('atlas'), reduce=True)
    assert [s.name for s in plain.walk() if s.parent_path == '/'] == ['stand', 'look_down_1', 'look_down_2',
                                                               'finished', 'failed']
    assert [s.name for s in reduced.walk() if s.parent_path == '/'] == ['stand', 'look_down', 'finished', 'failed']
    look = next(s for s in reduced.walk() if s.name == 'look_down')
    assert dict(zip(look.outcomes, look.transitions)) == {'done': 'finished', 'failed': 'look_down'}
    assert runs(reduced, 8) == runs(plain, 8)


def test_blocks_separate_states_with_different_futures():
    view = AutomatonView(load_automaton(AUTOMATA / 'sensors.yaml'), flexbe_config(robot_system('atlas')))
    machine = machine_from_view(view, None)
    blocks = bisimulation_blocks(machine)
    assert blocks['4'] == blocks['5']        # both ask for the template, then finish or fail
    assert blocks['1'] != blocks['4']
    assert len(set(blocks.values())) == len(machine.states) - 1


# --- Hopcroft against a naive reference ----------------------------------------------------

_PARTS = [StateConfig(f'p{i}_a', 'S', '', (), (), {f'p{i}_c': ('done',)}, {'done': 0}, (), ()) for i in range(2)]
_OBSERVATIONS = [(('p0_a', 'p0_c'),), (('p1_a', 'p1_c'),)]


def _naive_blocks(machine):
    """Moore's refinement: split by (block, block of each successor) until stable."""
    def target(t, blocks):
        return (t[0], blocks[t[1]]) if t[0] == 'state' else t
    blocks = {k: (tuple(p.proposition for p in s.parts), tuple(o for o, _ in s.transitions))
              for k, s in machine.states.items()}
    while True:
        refined = {k: (blocks[k], tuple((o, target(t, blocks)) for o, t in s.transitions))
                   for k, s in machine.states.items()}
        if len(set(refined.values())) == len(set(blocks.values())):
            return refined
        blocks = refined


@st.composite
def machines(draw):
    size = draw(st.integers(1, 9))
    keys = [str(i) for i in range(size)]
    targets = st.one_of(st.sampled_from([('state', k) for k in keys]),
                        st.sampled_from([('outcome', 'finished'), ('outcome', 'failed')]))
    states = {}
    for key in keys:
        part = draw(st.sampled_from(_PARTS))
        chosen = draw(st.lists(st.sampled_from(_OBSERVATIONS), unique=True, max_size=2))
        states[key] = AbstractState(key, (part,), [(o, draw(targets)) for o in sorted(chosen)])
    return AbstractMachine(states=states, initial='0', outcomes=['finished', 'failed'])


@settings(max_examples=200, deadline=None)
@given(machines())
def test_hopcroft_finds_the_coarsest_bisimulation(machine):
    fast, naive = bisimulation_blocks(machine), _naive_blocks(machine)
    for a in machine.states:
        for b in machine.states:
            assert (fast[a] == fast[b]) == (naive[a] == naive[b]), (a, b)
