"""Playing the robot as a game with an end (synthesis_manager.web.robot_game, ROS-free): moves
in the task's words, progress first, the blocked goal said once, a verdict within the bound."""

import re

import pytest

from ltl_specification import compile_task
from ltl_specification.play import RobotPlay
from synthesis_manager.web.robot_game import MAX_GAME_MOVES, game_turn
from respec.robot import robot_system

pytestmark = pytest.mark.ros


@pytest.fixture(scope='module')
def wrong_order():
    spec = compile_task(robot_system('atlas'), ['stand_prep'], ['look_down', 'stand_prep'])
    return RobotPlay(spec, spec.provenance.meanings), spec


def turn_after(game, moves):
    play, spec = game
    return game_turn(play, spec, play.meanings, moves)


@pytest.mark.parametrize('pick', ['first', 'last live'])
def test_every_play_ends_with_a_verdict_within_the_bound_told_in_the_tasks_words(wrong_order, pick):
    moves, turn = [], turn_after(wrong_order, [])
    assert turn['blocked_goal'].startswith('the environment keeps goal 1 (the state machine ends finished or')
    while not turn['verdict']:
        assert len(moves) <= MAX_GAME_MOVES
        live = [m for m in turn['moves'] if not m['dead_end'] and not m['repeats']] or turn['moves']
        moves.append((live[0] if pick == 'first' else live[-1])['index'])
        turn = turn_after(wrong_order, moves)
        assert turn['blocked_goal'] == ''  # said once, at the start
        for line in [m['words'] for m in turn['moves']] + turn['history']:
            assert not re.search(r'\b\w+_a off\b', line), line  # "state stand (...) stops" instead
    assert len(moves) <= MAX_GAME_MOVES
    assert turn['verdict'].startswith('the environment wins: ') and turn['moves'] == []
    assert [goal['words'] for goal in turn['goals']] == [
        'the state machine ends finished or the state machine ends failed']
    if 'deadlock' not in turn['verdict']:  # a goal that held ends the play, unless the robot is stuck there
        assert not turn['goals'][0]['reached']


def test_progress_moves_come_first_then_loops_then_dead_ends(wrong_order):
    turn = turn_after(wrong_order, [])
    ranks = [2 if m['dead_end'] else 1 if m['repeats'] else 0 for m in turn['moves']]
    assert ranks == sorted(ranks) and ranks[0] == 0
    assert turn['moves'][0]['words'] == 'state stand (ChangeControlModeActionState) starts'
    loop = next(m for m in turn['moves'] if m['repeats'])
    assert turn_after(wrong_order, [loop['index']])['verdict'].startswith(
        'the environment wins: the robot came back to a position of this play')


def test_a_play_longer_than_the_bound_is_refused(wrong_order):
    from ltl_specification.play import PlayError
    with pytest.raises(PlayError, match='a play ends within 12 moves; 13 were sent'):
        turn_after(wrong_order, [0] * (MAX_GAME_MOVES + 1))


# A robot that may wave once only: the environment wins in the long run (the goal cannot hold
# again and again), but a play in which the robot waves has reached every goal.
WAVE_ONCE = """[INPUT]
door_open

[OUTPUT]
wave
waved

[SYS_INIT]
!wave
!waved

[SYS_TRANS]
waved' <-> (waved | wave)
waved -> !wave'

[SYS_LIVENESS]
wave
"""


def test_a_play_in_which_every_goal_holds_ends_you_reached_every_goal():
    from respec.parsing.specifications import parse_structuredslugs

    spec = parse_structuredslugs(WAVE_ONCE)
    play = RobotPlay(spec, {'wave': 'the robot waves'})
    first = game_turn(play, spec, play.meanings, [])
    assert first['verdict'] == '' and first['goals'] == [{'words': 'the robot waves', 'reached': False}]
    assert first['moves'][0]['words'] == 'the robot waves'  # the progress move comes first
    turn = game_turn(play, spec, play.meanings, [first['moves'][0]['index']])
    assert turn['verdict'] == 'you reached every goal'
    assert turn['goals'] == [{'words': 'the robot waves', 'reached': True}] and turn['moves'] == []
