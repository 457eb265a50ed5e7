"""Playing the environment against a synthesized machine (sm_generation.play)."""

from pathlib import Path

import pytest

from sm_generation import StateMachine, generate_state_machine, load_automaton
from sm_generation.play import MachinePlayError, play_machine
from respec.robot import robot_system

AUTOMATA = Path(__file__).resolve().parents[1] / 'automata'


@pytest.fixture(scope='module')
def concurrent():
    return StateMachine.from_instantiations(
        generate_state_machine(load_automaton(AUTOMATA / 'concurrent.yaml'), robot_system('atlas')).to_instantiations())


def test_the_play_starts_at_the_initial_state_with_its_outcomes(concurrent):
    turn = play_machine(concurrent, [])
    first = concurrent.initial_state()
    assert (turn.step, turn.active, turn.outcomes, turn.ended) == (0, f'/{first.name}', list(first.outcomes), None)


def test_reporting_outcomes_follows_the_transitions_to_the_machine_outcome(concurrent):
    """Always the first outcome: each step goes where the active state's transition says, and a
    concurrency container is played as one state with its own outcomes."""
    reported, turn, seen = [], play_machine(concurrent, []), []
    while turn.active is not None and len(reported) < 20:
        state = concurrent.state(turn.active.strip('/'))
        seen.append(state.state_class)
        outcome = turn.outcomes[0]
        expected = state.next_target(outcome)
        reported.append(outcome)
        turn = play_machine(concurrent, reported)
        assert turn.active == f'/{expected}' or (turn.active is None and turn.ended == expected)
    assert turn.ended in concurrent.outcomes and ':CONCURRENCY' in seen
    assert [outcome for _, outcome in turn.history] == reported


def test_a_failure_ends_the_machine_in_failed(concurrent):
    first = concurrent.initial_state()
    failure = next(o for o, t in zip(first.outcomes, first.transitions) if t == 'failed')
    turn = play_machine(concurrent, [failure])
    assert turn.active is None and turn.ended == 'failed' and turn.outcomes == []


def test_an_outcome_the_state_does_not_have_is_refused_naming_it(concurrent):
    first = concurrent.initial_state()
    with pytest.raises(MachinePlayError, match=f"{first.name} has no outcome 'exploded'"):
        play_machine(concurrent, ['exploded'])
    failure = next(o for o, t in zip(first.outcomes, first.transitions) if t == 'failed')
    with pytest.raises(MachinePlayError, match='already ended'):
        play_machine(concurrent, [failure, failure])

