"""The ROS-free command line: python -m ltl_specification (behavior-synthesis compile)."""

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from ltl_specification import compile_task
from ltl_specification.cli import add_arguments, run
from respec.robot import robot_system

ROOT = Path(__file__).resolve().parents[2]
DEMO = ['--system', 'atlas', '--initial-conditions', 'stand_prep', '--goals', 'look_down,pickup_object']


def cli(*args, hash_seed='0'):
    env = dict(os.environ, PYTHONHASHSEED=hash_seed, PYTHONPATH=str(ROOT))
    return subprocess.run([sys.executable, '-m', 'ltl_specification', *args], cwd=ROOT, env=env,
                          capture_output=True, text=True, timeout=60)


def test_structuredslugs_by_default():
    result = cli(*DEMO)
    assert result.returncode == 0, result.stderr
    assert result.stdout == compile_task(robot_system('atlas'),
                                         ['stand_prep'], ['look_down', 'pickup_object']).to_structuredslugs()


def test_output_is_byte_identical_across_processes_and_hash_seeds():
    outputs = {cli(*DEMO, '--format', 'slugsin', hash_seed=seed).stdout for seed in ('1', '2', '3')}
    assert len(outputs) == 1 and outputs.pop().startswith('[INPUT]\nstand_prep_c\n')


def test_json_is_the_ltl_specification_sections(tmp_path):
    target = tmp_path / 'spec.json'
    result = cli(*DEMO, '--format', 'json', '--unordered', '--sm-outcomes', 'finished', '-o', str(target))
    assert result.returncode == 0 and result.stdout == ''
    sections = json.loads(target.read_text())
    assert list(sections) == ['env_props', 'sys_props', 'env_init', 'sys_init', 'env_trans', 'sys_trans',
                              'env_liveness', 'sys_liveness']
    assert sections['sys_liveness'] == ['finished']
    assert 'next(look_down_c) | look_down_m <-> next(look_down_m)' in sections['sys_trans']


def test_custom_ltl_file_and_explain(tmp_path):
    custom = tmp_path / 'custom.yaml'
    custom.write_text('sys_trans: ["!walk_a"]\n')
    result = cli('--system', 'atlas', '--goals', 'step', '--custom-ltl', str(custom), '--explain')
    assert result.returncode == 0, result.stderr
    assert '\n!walk_a\n' in result.stdout
    assert 'walk (mentioned in custom LTL)' in result.stderr


@pytest.mark.parametrize('args, code, item', [
    (['--system', 'atlas', '--goals', 'look_down,dance'], 'UNKNOWN_PROPOSITION', "'dance'"),
    (['--system', 'robby', '--goals', 'look_down'], 'UNKNOWN_SYSTEM', "'robby'"),
    (['--system', 'atlas', '--initial-conditions', 'stand,walk', '--goals', 'look_down'],
     'INVALID_INITIAL_CONDITIONS', "'walk'"),
    (['--system', 'atlas', '--goals', 'walk', '--sm-outcomes', 'failed'], 'INVALID_SM_OUTCOMES', "'failed'"),
])
def test_bad_input_exits_1_with_one_line_naming_the_item(args, code, item):
    result = cli(*args)
    assert result.returncode == 1 and result.stdout == ''
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1
    assert lines[0].startswith(f'error: {code}: ') and f'[item: {item}]' in lines[0]


def test_unreadable_custom_ltl_file():
    result = cli('--system', 'atlas', '--goals', 'walk', '--custom-ltl', '/nonexistent/custom.yaml')
    assert result.returncode == 1 and 'INVALID_FORMULA' in result.stderr


def test_add_arguments_and_run_in_process(tmp_path, capsys):
    parser = argparse.ArgumentParser()
    add_arguments(parser)
    target = tmp_path / 'walk.slugsin'
    assert run(parser.parse_args(['--system', 'atlas', '--goals', 'walk', '--format', 'slugsin',
                                  '-o', str(target)])) == 0
    assert target.read_text() == compile_task(robot_system('atlas'), [], ['walk']).to_slugsin()
    assert run(parser.parse_args(['--system', 'atlas', '--goals', ''])) == 1  # ExitStatus.FAILED
    assert 'INVALID_GOALS' in capsys.readouterr().err


def test_diagnose_says_why_a_task_cannot_be_done():
    impossible = cli('--system', 'atlas', '--goals', 'look_down,stand_prep', '--diagnose')
    assert impossible.returncode == 1 and impossible.stdout.startswith('[INPUT]')
    assert impossible.stderr.startswith('SPEC_UNSYNTHESIZABLE: Goal 2 (stand_prep) can never be achieved')
    assert 'stand -> stand_prep is not a transition in config/atlas.yaml' in impossible.stderr.splitlines()[0]
    possible = cli(*DEMO, '--diagnose')
    assert possible.returncode == 0 and possible.stderr == ''


def test_a_capability_robot_without_its_flexbe_states_is_a_coded_error_not_a_traceback():
    env = {key: value for key, value in os.environ.items() if key != 'AMENT_PREFIX_PATH'}
    result = subprocess.run([sys.executable, '-m', 'ltl_specification', '--system', 'delivery_rover', '--goals', 'drive'],
                            cwd=ROOT, env=dict(env, PYTHONPATH=str(ROOT)), capture_output=True, text=True, timeout=60)
    assert result.returncode == 1 and 'Traceback' not in result.stderr
    assert result.stderr.startswith("error: CONFIG_VARIABLE_CONFIG_INVALID: delivery_rover: capability 'check_battery' "
                                    "uses state class 'OperatorDecisionState'")
    assert "[item: 'check_battery.interface']" in result.stderr
