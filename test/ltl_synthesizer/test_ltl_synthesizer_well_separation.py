"""Well-separation (issue 33 item 4): a realizable specification whose controller can win by
forcing the environment to break its assumptions is flagged, naming the assumptions involved;
the generated ATLAS specifications are well-separated."""

import itertools
import subprocess
import sys
import time

import pytest

from ltl_specification import compile_task
from ltl_specification.systems import load_task_abstraction
from ltl_synthesizer.errors import SynthesisTimeoutError
from ltl_synthesizer.interrupt import Limits
from ltl_synthesizer.synthesizer import is_realizable, solve
from ltl_synthesizer.well_separation import check_well_separation
from respec.vocabulary.errors import CodedError
from respec.parsing import spec_from_text_sections
from respec.robot import robot_system


def spec(**sections):
    """A specification over one input x and one output y, with the given sections."""
    base = {'env_props': ['x'], 'sys_props': ['y'], 'env_init': [], 'sys_init': [], 'env_trans': [],
            'sys_trans': [], 'env_liveness': [], 'sys_liveness': []}
    return spec_from_text_sections({**base, **sections})


# y forces the next x; the environment also promises !x infinitely often. A system that keeps y
# on forever breaks the promise for the environment: its goal y "holds" by cheating.
CHEATING = dict(env_trans=['y -> next(x)'], env_liveness=['!x'], sys_liveness=['y'])


def test_a_controller_that_can_force_a_broken_liveness_assumption_is_flagged_with_both_assumptions():
    cheating = spec(**CHEATING)
    assert is_realizable(cheating)
    report = check_well_separation(cheating)
    assert not report.well_separated
    assert report.assumptions == ["env_trans #0 'y -> next(x)'", "env_liveness #0 '!x'"]
    assert report.cheating_initial_positions == 4   # from every start: the system turns y on
    assert report.warning().startswith('Warning: the controller can win by forcing the environment to break')
    assert "env_trans #0 'y -> next(x)'; env_liveness #0 '!x'" in report.warning()


def test_a_safety_assumption_the_system_can_make_impossible_is_flagged_alone():
    # with y on, no next x satisfies both: the environment has no legal move (an unrelated
    # assumption is not named: the set is minimal)
    report = check_well_separation(spec(env_trans=['y -> next(x)', 'y -> next(!x)', 'x -> next(x) | next(!x)'],
                                        env_liveness=['x | !x'], sys_liveness=['y']))
    assert not report.well_separated
    assert report.assumptions == ["env_trans #0 'y -> next(x)'", "env_trans #1 'y -> next(!x)'"]


@pytest.mark.parametrize('sections', [
    dict(env_liveness=['x'], sys_trans=['next(y) <-> next(x)'], sys_liveness=['y']),   # an honest follower
    dict(CHEATING, sys_trans=['!y'], sys_liveness=['!y']),          # the system may never turn y on
    dict(CHEATING, sys_trans=['y -> !next(y)']),                    # nor keep it on two steps running
    dict(env_trans=['y -> next(x)', 'y -> next(!x)'], sys_init=['!y'], sys_trans=['!next(y)'], sys_liveness=['!y']),
])
def test_specifications_where_the_environment_can_always_keep_its_assumptions_are_well_separated(sections):
    report = check_well_separation(spec(**sections))
    assert report.well_separated and report.assumptions == [] and report.warning() == ''


@pytest.mark.parametrize('sections', [
    CHEATING, dict(env_liveness=['x'], sys_trans=['next(y) <-> next(x)'], sys_liveness=['y']),
    dict(env_trans=['y -> next(x)', 'y -> next(!x)', 'x -> next(x) | next(!x)'], env_liveness=['x | !x'],
         sys_liveness=['y'])])
def test_the_check_on_the_solved_game_answers_as_on_a_game_of_its_own(sections):
    # The synthesis child checks the game it solved (not built again); the answer is the same.
    solved = solve(spec(**sections))
    assert solved.realizable
    assert check_well_separation(spec(**sections), Limits(), solved.game) == check_well_separation(spec(**sections))


def test_the_check_on_a_solved_game_stops_by_its_own_limits_and_says_so():
    solved = solve(spec(**CHEATING), limits=Limits(deadline=time.monotonic() + 600))
    interrupt = solved.game.interrupt
    with pytest.raises(SynthesisTimeoutError, match='checking well-separation'):
        check_well_separation(spec(**CHEATING), Limits(deadline=time.monotonic() - 1), solved.game)
    assert solved.game.interrupt is interrupt   # the game's own is back


def test_a_system_that_can_only_block_itself_does_not_cheat():
    # the system's only way to stop the environment is to have no legal move itself: that breaks
    # its own guarantee, the environment keeps its assumptions
    assert check_well_separation(spec(env_trans=['y -> next(x)'], env_liveness=['!x'],
                                      sys_trans=['!y'])).well_separated


def test_an_unsatisfiable_env_init_is_flagged():
    report = check_well_separation(spec(env_init=['x & !x']))
    assert not report.well_separated and report.assumptions[0].startswith('env_init')


def test_gr1synth_reports_the_check_only_when_asked(tmp_path):
    source = tmp_path / 'cheating.structuredslugs'
    source.write_text(spec(**CHEATING).to_structuredslugs())
    honest = tmp_path / 'honest.structuredslugs'
    honest.write_text(spec(env_liveness=['x'], sys_trans=['next(y) <-> next(x)'], sys_liveness=['y'])
                      .to_structuredslugs())

    def gr1synth(*arguments):
        return subprocess.run([sys.executable, '-m', 'ltl_synthesizer', *map(str, arguments)],
                              capture_output=True, text=True, timeout=60)

    flagged = gr1synth('--check-well-separation', source)
    assert flagged.returncode == 0
    assert flagged.stderr.splitlines()[0] == 'RESULT: Specification is realizable.'
    assert flagged.stderr.splitlines()[1] == check_well_separation(spec(**CHEATING)).warning()
    assert gr1synth(source).stderr == 'RESULT: Specification is realizable.\n'  # unchanged without the flag
    assert gr1synth('--check-well-separation', honest).stderr.splitlines()[1].startswith('Well-separated:')
    timed = gr1synth('--check-well-separation', '--timeout', '30', source)   # in a child process too
    assert 'not well-separated' in timed.stderr


def test_compile_diagnose_warns_of_a_custom_assumption_the_robot_can_force_broken(tmp_path):
    # "look_down never completes while active": with failures retried, the robot keeps look_down
    # active and the environment cannot keep look_down's completion fairness
    custom = tmp_path / 'custom.yaml'
    custom.write_text('env_trans:\n  - "look_down_a -> !next(look_down_c)"\n')
    compiled = subprocess.run([sys.executable, '-m', 'synthesis_manager', 'compile', '--system', 'atlas',
                               '--initial-conditions', 'stand', '--goals', 'look_down', '--sm-outcomes', 'finished',
                               '--custom-ltl', custom, '--diagnose', '-o', tmp_path / 'spec'],
                              capture_output=True, text=True, timeout=120)
    assert compiled.returncode == 0
    assert compiled.stderr.startswith('Warning: the controller can win by forcing the environment')
    # each assumption named as the unrealizable core names a requirement
    assert 'custom LTL env_trans[0] (request custom LTL): look_down_a -> !next(look_down_c)' in compiled.stderr
    assert ('eq. (7) completion fairness for look_down (actions.look_down in config/atlas.yaml: preconditions '
            'stand): !look_down_a | next(look_down_c)') in compiled.stderr


def atlas_tasks():
    """Every single goal and the first 60 pairs of goals, from every control mode, with both
    outcome sets: the tasks the compiler accepts."""
    abstraction = load_task_abstraction(robot_system('atlas'))
    items = abstraction.items()
    goal_lists = [[item] for item in items] + [list(pair) for pair in itertools.combinations(items, 2)][:60]
    for start, goals, outcomes in itertools.product(abstraction.control_modes, goal_lists,
                                                    (('finished', 'failed'), ('finished',))):
        try:
            yield compile_task(robot_system('atlas'), [start], goals, sm_outcomes=outcomes, explain_refusal=False)
        except CodedError:   # refused (a goal mode no route reaches): no specification to check
            continue


def test_the_generated_atlas_specifications_are_well_separated():
    checked = [check_well_separation(task).well_separated for task in atlas_tasks()]
    assert len(checked) == 634 and all(checked)
