"""Playing the robot against the environment of an unrealizable task (ltl_specification.play)."""

import pytest

from ltl_specification import compile_task
from ltl_specification.play import MAX_PLAY_STEPS, PlayError, RobotPlay
from ltl_synthesizer.synthesizer import solve
from respec.ltl import evaluate
from respec.robot import robot_system


@pytest.fixture(scope='module')
def wrong_order():
    spec = compile_task(robot_system('atlas'), ['stand_prep'], ['look_down', 'stand_prep'])
    return spec, RobotPlay(spec, spec.provenance.meanings)


def test_the_play_starts_where_the_environment_wins_told_in_words(wrong_order):
    spec, play = wrong_order
    turn = play.turn([])
    meanings = spec.provenance.meanings     # what each proposition turning true means, in FlexBE's terms
    assert turn.step == 0 and turn.happened == meanings['stand_prep_c'] and not turn.lost
    assert 'now in stand_prep' in turn.happened
    assert turn.moves and all(move.words for move in turn.moves)
    assert meanings['stand_a'] in [move.words for move in turn.moves]
    assert turn.blocked_goal.startswith('the environment keeps system goal 1 (finished | failed) from ever holding')
    assert all(evaluate(f, turn.values, {}) for f in spec.env_init + spec.sys_init)


def test_every_move_is_allowed_by_the_robots_safety_and_the_goal_never_holds(wrong_order):
    """Whatever the user chooses (here: each listed move in turn, round robin, for 30 steps),
    each step satisfies sys_trans and the blocked goal (finished | failed) never holds."""
    spec, play = wrong_order
    moves, turn = [], play.turn([])
    for step in range(30):
        if turn.lost or not turn.moves:
            break
        candidates = [m for m in turn.moves if not m.dead_end] or turn.moves
        moves.append(candidates[step % len(candidates)].index)
        following = play.turn(moves)
        assert all(evaluate(f, turn.values, following.values) for f in spec.sys_trans + spec.env_trans)
        assert not (following.values['finished'] or following.values['failed'])
        turn = following
    assert len(moves) >= 10 or turn.lost


def test_a_dead_end_move_leaves_the_robot_stuck(wrong_order):
    _, play = wrong_order
    turn = play.turn([])
    dead = next(move for move in turn.moves if move.dead_end)
    after = play.turn([dead.index])
    assert after.lost and 'deadlock' in after.lost and after.moves == []
    stuck = play.turn([dead.index, 0])     # the environment's answer: no output is allowed
    assert stuck.lost.startswith('The environment answered so that no response') and stuck.moves == []
    with pytest.raises(PlayError, match='does not exist'):
        play.turn([dead.index, 0, 0])


def test_a_move_back_to_a_visited_position_is_marked(wrong_order):
    _, play = wrong_order
    keep = next(m for m in play.turn([]).moves if m.words == 'keep every output as it is')
    again = next(m for m in play.turn([keep.index]).moves if m.words == 'keep every output as it is')
    assert again.repeats


def test_moves_that_do_not_exist_and_overlong_plays_are_refused(wrong_order):
    _, play = wrong_order
    with pytest.raises(PlayError, match="move 999 at step 0 does not exist"):
        play.turn([999])
    with pytest.raises(PlayError, match='longer than'):
        play.turn([0] * (MAX_PLAY_STEPS + 1))


def test_a_realizable_task_has_no_environment_play():
    spec = compile_task(robot_system('atlas'), ['stand_prep'], ['look_down'])
    assert solve(spec).realizable
    with pytest.raises(PlayError, match='realizable'):
        RobotPlay(spec)


def test_the_same_play_gives_the_same_turns():
    spec = compile_task(robot_system('atlas'), ['stand_prep'], ['look_down', 'stand_prep'])
    first, second = RobotPlay(spec, spec.provenance.meanings), RobotPlay(spec, spec.provenance.meanings)
    assert first.turn([0, 0, 0]).to_dict() == second.turn([0, 0, 0]).to_dict()
