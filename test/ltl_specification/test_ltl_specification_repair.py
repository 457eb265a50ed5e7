"""Verified repairs (ltl_specification.repair, ``behavior-synthesis repair``).

Every proposal the command prints is re-checked here the way a user would check it: its
request (and custom LTL, and robot patch in a copy of the config directory) compiled by
``behavior-synthesis compile`` and synthesized by ``gr1synth``, which must say realizable.
"""

import contextlib
import functools
import io
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from ltl_specification.repair import (ADD_ASSUMPTION, ADD_GOAL, ADD_POSTCONDITION, ADD_TRANSITION, DROP_GOAL,
                                      REORDER, UNORDERED, WEAKEN_GUARANTEE, ConfigPatch, TaskRequest,
                                      patched_text, propose_repairs)
from respec.robot import robot_system

ROOT = Path(__file__).resolve().parents[2]
FLEXBE_PREFIX = Path(sys.prefix) / 'flexbe'


def command(program, *args, env=None):
    module = {'behavior-synthesis': 'synthesis_manager.programs.cli', 'gr1synth': 'ltl_synthesizer'}[program]
    environment = dict(os.environ, PYTHONPATH=str(ROOT), **(env or {}))
    return subprocess.run([sys.executable, '-m', module, *map(str, args)], cwd=ROOT, env=environment,
                          capture_output=True, text=True, timeout=120)


def in_process(program, *args):
    """``program`` run through its own ``main`` in this process: what a user's check runs, without
    starting an interpreter per proposal (the checks, not the subject of these tests)."""
    from ltl_synthesizer.cli import main as gr1synth
    from synthesis_manager.programs.cli import main as behavior_synthesis
    main = {'behavior-synthesis': behavior_synthesis, 'gr1synth': gr1synth}[program]
    stdout, stderr = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(stdout), contextlib.redirect_stderr(stderr):
        status = main([str(arg) for arg in args])
    return subprocess.CompletedProcess([program, *args], status, stdout.getvalue(), stderr.getvalue())


def repair_json(*task, env=None):
    done = command('behavior-synthesis', 'repair', *task, '--json', env=env)
    assert done.returncode in (0, 1), done.stderr
    return done, json.loads(done.stdout)


def realizable_by_the_tools(tmp_path, proposal, task: dict, config_dir=None, custom_ltl=None, env=None) -> bool:
    """Compile the proposal's task with the CLI and synthesize it with gr1synth."""
    request = proposal.get('request', task)
    arguments = ['--system', request['system'], '--goals', ','.join(request['goals']),
                 '--initial-conditions', ','.join(request['initial_conditions']),
                 '--sm-outcomes', ','.join(request['sm_outcomes'])]
    if request.get('unordered'):
        arguments.append('--unordered')
    custom = proposal.get('custom_ltl', custom_ltl)
    if custom is not None:
        custom_file = tmp_path / f'custom-{id(proposal)}.yaml'
        custom_file.write_text(yaml.safe_dump(custom))
        arguments += ['--custom-ltl', custom_file]
    if 'config_patch' in proposal:
        config_dir = apply_patch_to_copy(tmp_path / f'config-{id(proposal)}', proposal['config_patch'],
                                         config_dir or ROOT / 'config')
    if config_dir is not None:
        arguments += ['--config-dir', config_dir]
    spec = tmp_path / f'spec-{id(proposal)}.slugsin'
    # With an environment of its own (AMENT_PREFIX_PATH) the compile runs as a process of its own.
    compile_spec = functools.partial(command, env=env) if env else in_process
    compiled = compile_spec('behavior-synthesis', 'compile', *arguments, '--format', 'slugsin', '-o', spec)
    assert compiled.returncode == 0, compiled.stderr
    synthesized = in_process('gr1synth', '--sysInitRoboticsSemantics', spec)
    assert synthesized.returncode == 0, synthesized.stderr
    return 'RESULT: Specification is realizable.' in synthesized.stderr


def apply_patch_to_copy(target: Path, patch: dict, source: Path) -> Path:
    """A copy of the config directory with the proposal's patch applied, as a user would edit it."""
    shutil.copytree(source, target)
    edited = target / Path(patch['file']).relative_to(Path(patch['file']).parts[0])
    edited.write_text(patched_text(edited.read_text(), ConfigPatch(patch['file'], tuple(patch['path']),
                                                                   patch['value'], patch['previous'])))
    return target


def test_goals_in_the_wrong_order_get_reorderings_first_then_robot_changes_then_dropped_goals(tmp_path):
    task = ['--system', 'atlas', '--initial-conditions', 'stand_prep', '--goals', 'look_down,stand_prep']
    done, result = repair_json(*task)
    assert done.returncode == 0 and not result['realizable']
    assert result['problem'].startswith('SPEC_UNSYNTHESIZABLE: Goal 2 (stand_prep) can never be achieved')
    kinds = [p['kind'] for p in result['proposals']]
    assert kinds[:2] == [UNORDERED, REORDER] and kinds[-1] == DROP_GOAL and ADD_TRANSITION in kinds
    assert result['proposals'][1]['request']['goals'] == ['stand_prep', 'look_down']
    keeps = [p['keeps_goals'] for p in result['proposals']]
    assert keeps == sorted(keeps, reverse=True)       # every goal kept before any dropped
    assert all(p['verified'] and p['synthesis_seconds'] > 0 for p in result['proposals'])
    original = {'system': 'atlas', 'initial_conditions': ['stand_prep'], 'goals': ['look_down', 'stand_prep'],
                'sm_outcomes': ['finished', 'failed'], 'unordered': False}
    assert result['request'] == original
    for proposal in result['proposals']:
        assert realizable_by_the_tools(tmp_path, proposal, original), proposal['summary']
    assert 'found: Let the goals be achieved in any order' in done.stderr   # progress as they are verified


def test_a_goal_the_robot_cannot_reach_gets_the_missing_transition_verified_in_the_config(tmp_path):
    task = {'system': 'atlas', 'initial_conditions': ['stand'], 'goals': ['look_down', 'stand_prep'],
            'sm_outcomes': ['finished', 'failed'], 'unordered': False}
    done, result = repair_json('--system', 'atlas', '--initial-conditions', 'stand', '--goals',
                               'look_down,stand_prep')
    assert result['problem'].startswith('INVALID_GOALS: Goal 2 (stand_prep) can never be achieved')
    first = result['proposals'][0]
    assert first['kind'] == ADD_TRANSITION and first['changes_robot'] and 'request' not in first
    assert first['config_patch'] == {'file': 'config/atlas.yaml', 'path': ['abstraction', 'control_modes', 'stand'],
                                     'value': ['manipulate', 'step', 'walk', 'stand_prep'],
                                     'previous': ['manipulate', 'step', 'walk'], 'changes_robot': True}
    assert realizable_by_the_tools(tmp_path, first, task)
    assert [p for p in result['proposals'] if p['kind'] == DROP_GOAL][0]['request']['goals'] == ['look_down']


def test_custom_ltl_that_needs_another_goal_first_gets_that_prerequisite_goal(tmp_path):
    # stand_m is the memory of a goal stand (eq. (20)); without that goal the name is unknown.
    custom = {'sys_trans': ['look_down_a -> stand_m']}
    repairs = propose_repairs(robot_system('atlas'), TaskRequest('atlas', ('stand_prep',), ('look_down',)), custom)
    assert repairs.problem.startswith("UNKNOWN_PROPOSITION: custom LTL names unknown proposition 'stand_m'")
    first = repairs.proposals[0]
    assert first.kind == ADD_GOAL and first.request.goals == ('stand', 'look_down')
    assert first.summary == 'Add the goal stand before goal 1 (look_down) (the custom LTL uses stand_m, its goal memory).'
    task = {'system': 'atlas', 'initial_conditions': ['stand_prep'], 'goals': ['look_down'],
            'sm_outcomes': ['finished', 'failed'], 'unordered': False}
    assert realizable_by_the_tools(tmp_path, first.to_dict(), task, custom_ltl=custom)


def test_custom_ltl_gets_a_weakened_guarantee_or_a_mined_assumption(tmp_path):
    custom = {'env_props': ['door_open'], 'sys_liveness': ['door_open']}
    custom_file = tmp_path / 'custom.yaml'
    custom_file.write_text(yaml.safe_dump(custom))
    task = {'system': 'atlas', 'initial_conditions': ['stand_prep'], 'goals': ['look_down'],
            'sm_outcomes': ['finished', 'failed'], 'unordered': False}
    done, result = repair_json('--system', 'atlas', '--initial-conditions', 'stand_prep', '--goals', 'look_down',
                               '--custom-ltl', custom_file)
    kinds = [p['kind'] for p in result['proposals']]
    assert kinds[:2] == [ADD_ASSUMPTION, WEAKEN_GUARANTEE]
    mined, weakened = result['proposals'][:2]
    assert mined['custom_ltl'] == custom | {'env_liveness': ['door_open']}
    assert 'keeping door_open false' in mined['summary']      # what the environment's play showed
    assert weakened['custom_ltl'] == {'env_props': ['door_open']}
    for proposal in result['proposals']:
        assert realizable_by_the_tools(tmp_path, proposal, task, custom_ltl=custom), proposal['summary']


def test_an_assumption_that_lets_the_controller_win_by_cheating_is_never_proposed():
    # The environment may never open the door (env_trans): assuming it opens infinitely often
    # would make the assumptions unsatisfiable and the task realizable only vacuously.
    custom = {'env_props': ['door_open'], 'env_trans': ['!door_open'], 'sys_liveness': ['door_open']}
    repairs = propose_repairs(robot_system('atlas'), TaskRequest('atlas', ('stand_prep',), ('look_down',)), custom)
    assert repairs.proposals and ADD_ASSUMPTION not in [p.kind for p in repairs.proposals]
    assert repairs.proposals[0].kind == WEAKEN_GUARANTEE


@pytest.mark.skipif(not FLEXBE_PREFIX.is_dir(), reason='needs `make flexbe` (FlexBE state packages)')
def test_a_capability_robot_goal_no_capability_sets_gets_a_postcondition_patch(tmp_path):
    env = {'AMENT_PREFIX_PATH': str(FLEXBE_PREFIX)}
    done, result = repair_json('--system', 'delivery_rover', '--goals', 'charge', '--initial-conditions', 'drive',
                               env=env)
    assert result['problem'].startswith("INVALID_GOALS: Goal 'charge' can never be reached")
    patches = [p for p in result['proposals'] if p['kind'] == ADD_POSTCONDITION]
    assert patches and all(p['config_patch']['file'] == 'config/delivery_rover/capabilities.yaml' for p in patches)
    assert patches[0]['config_patch']['value'][-1] == 'charge'
    task = {'system': 'delivery_rover', 'initial_conditions': ['drive'], 'goals': ['charge'],
            'sm_outcomes': ['finished', 'failed'], 'unordered': False}
    for proposal in patches:
        assert realizable_by_the_tools(tmp_path, proposal, task, env=env), proposal['summary']


def test_a_refusal_no_change_of_the_task_can_fix_is_reported_as_it_is():
    done = command('behavior-synthesis', 'repair', '--system', 'atlas', '--goals', 'look_dwn')
    assert done.returncode == 1
    assert 'UNKNOWN_PROPOSITION' in done.stdout + done.stderr and 'look_dwn' in done.stdout + done.stderr
    assert 'Nothing to propose' in done.stdout


def test_a_task_that_can_be_done_needs_no_repair():
    done = command('behavior-synthesis', 'repair', '--system', 'atlas', '--goals', 'look_down')
    assert done.returncode == 0 and 'nothing to repair' in done.stdout


def test_proposals_are_deterministic():
    def without_times(repairs):
        data = repairs.to_dict()
        for key in ('seconds', 'first_proposal_seconds'):
            data.pop(key)
        for proposal in data['proposals']:
            proposal.pop('synthesis_seconds')
        return data

    request = TaskRequest('atlas', ('stand_prep',), ('look_down', 'stand_prep'))
    assert without_times(propose_repairs(robot_system('atlas'),
                                         request)) == without_times(propose_repairs(robot_system('atlas'), request))


def test_guarantees_that_contradict_each_other_get_both_dropped_when_one_is_not_enough():
    custom = {'sys_trans': ['look_down_a', '!look_down_a']}
    repairs = propose_repairs(robot_system('atlas'), TaskRequest('atlas', ('stand_prep',), ('look_down',)), custom)
    assert [p.custom_ltl for p in repairs.proposals if p.kind == WEAKEN_GUARANTEE] == [{}]
    assert repairs.proposals[0].summary == ("Drop the custom guarantees sys_trans[0] 'look_down_a' and "
                                            "sys_trans[1] '!look_down_a'.")
