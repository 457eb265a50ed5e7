"""Our own example specifications (test/specs/), checked with the synthesizer, the independent
oracle, the gr1synth command line and ltl_synthesizer.external.

Each file exercises one phenomenon of slugs' examples (which we may not ship): the robotics
initial-state semantics, unrealizability found only by the outermost fixpoint, pure safety
games, next-step livenesses, and unrealizable specifications with an explanation.
"""

import json
import os
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from gr1_oracle import Oracle
from counterstrategies import synthesize_with_counterstrategy
from ltl_synthesizer import SynthesisCancelledError, synthesize
from ltl_synthesizer.external import ExternalSynthesizerError, run_external_synthesizer
from respec.parsing import parse_slugsin, parse_structuredslugs

SPECS = Path(__file__).parents[1] / 'specs'
REPOSITORY = Path(__file__).resolve().parents[2]

# file -> (realizable under standard semantics, realizable under robotics semantics)
EXPECTED = {
    'lamp_robotics_semantics.structuredslugs': (True, False),
    'conveyor_outermost_fixpoint.structuredslugs': (False, False),
    'copy_safety.structuredslugs': (True, True),
    'predict_safety.structuredslugs': (False, False),
    'activation_outcome.structuredslugs': (True, True),
    'activation_without_fairness.structuredslugs': (False, False),
    'two_goals_next_liveness.slugsin': (True, True),
}


def load(name):
    parse = parse_slugsin if name.endswith('.slugsin') else parse_structuredslugs
    return parse((SPECS / name).read_text(), name)


def test_every_spec_file_has_an_expectation():
    assert sorted(p.name for p in SPECS.iterdir()) == sorted(EXPECTED)


@pytest.mark.parametrize('name', sorted(EXPECTED))
def test_oracle_decides_as_expected(name):
    oracle = Oracle(load(name))
    assert (oracle.realizable(robotics_semantics=False), oracle.realizable(robotics_semantics=True)) \
        == EXPECTED[name]


@pytest.mark.parametrize('name', sorted(EXPECTED))
@pytest.mark.parametrize('robotics_semantics', [False, True], ids=['standard', 'robotics'])
def test_synthesizer_decides_as_expected_with_checked_strategies(name, robotics_semantics):
    spec = load(name)
    expected = EXPECTED[name][robotics_semantics]
    result = synthesize_with_counterstrategy(spec, robotics_semantics)
    assert result.realizable == expected
    oracle = Oracle(spec)
    if expected:
        assert result.strategy['nodes'], 'a realizable example must have initial states'
        assert oracle.check_strategy(result.strategy, robotics_semantics) == []
        assert result.explanation == ''
    else:
        assert oracle.check_counterstrategy(result.counterstrategy, robotics_semantics) == []
        assert result.explanation.strip()


def test_unrealizable_explanations_point_at_the_cause():
    conveyor = synthesize(load('conveyor_outermost_fixpoint.structuredslugs')).explanation
    assert 'at_station' in conveyor
    fairness = synthesize(load('activation_without_fairness.structuredslugs')).explanation
    assert 'grasp_m' in fairness
    lamp = synthesize(load('lamp_robotics_semantics.structuredslugs'), robotics_semantics=True).explanation
    assert 'robotics semantics' in lamp
    # A safety failure names the requirement that cannot be met.
    prediction = synthesize(load('predict_safety.structuredslugs')).explanation
    assert 'guess <-> next(coin)' in prediction


def test_identical_requests_give_byte_identical_strategies():
    spec = load('activation_outcome.structuredslugs')
    first, second = synthesize(spec).strategy, synthesize(load('activation_outcome.structuredslugs')).strategy
    assert json.dumps(first, sort_keys=False) == json.dumps(second, sort_keys=False)


# --- the oracle's model checker catches broken strategies -----------------------------------

def copy_safety_strategy():
    spec = load('copy_safety.structuredslugs')
    return spec, synthesize(spec, robotics_semantics=True).strategy


def test_checker_catches_an_unanswered_environment_move():
    spec, strategy = copy_safety_strategy()
    name, node = next((n, node) for n, node in strategy['nodes'].items() if node['trans'])
    node['trans'] = node['trans'][1:]
    problems = Oracle(spec).check_strategy(strategy)
    assert any(p.startswith(f'node {name} ') and 'has no answer' in p for p in problems)


def test_checker_catches_a_safety_violation():
    spec, strategy = copy_safety_strategy()
    display = strategy['variables'].index('display')
    for node in strategy['nodes'].values():
        node['state'][display] = 1 - node['state'][display]
    problems = Oracle(spec).check_strategy(strategy)
    assert any('sys_trans violated' in p for p in problems)


def test_checker_catches_a_missing_initial_state():
    spec, strategy = copy_safety_strategy()
    alarm, warning = strategy['variables'].index('alarm'), strategy['variables'].index('warning')
    initial = [n for n, node in strategy['nodes'].items()
               if node['state'][alarm] == 0 and node['state'][warning] == 0]
    assert initial
    for name in initial:
        for node in strategy['nodes'].values():
            node['trans'] = [t for t in node['trans'] if str(t) != name]
        del strategy['nodes'][name]
    problems = Oracle(spec).check_strategy(strategy)
    assert any('has no strategy node' in p for p in problems)


def test_checker_catches_a_fair_cycle_that_misses_the_goal():
    # A lazy controller that never activates grasp: the environment's fairness holds
    # vacuously on its self-loop, but the goal grasp_m never does.
    spec = load('activation_outcome.structuredslugs')
    lazy = {'version': 0, 'slugs': 'handmade', 'variables': ['grasp_c', 'grasp_a', 'grasp_m'],
            'nodes': {'0': {'rank': 0, 'state': [0, 0, 0], 'trans': [0]}}}
    problems = Oracle(spec).check_strategy(lazy)
    assert problems == ["fair cycle through nodes ['0'] never satisfies system liveness 0"]


def test_checker_rejects_wrong_variables():
    spec, strategy = copy_safety_strategy()
    strategy['variables'] = list(reversed(strategy['variables']))
    assert 'differ from inputs+outputs' in Oracle(spec).check_strategy(strategy)[0]


# --- gr1synth on the command line, slugs style ----------------------------------------------

def gr1synth(*arguments, cwd=REPOSITORY):
    return subprocess.run([sys.executable, '-m', 'ltl_synthesizer', *map(str, arguments)],
                          capture_output=True, text=True, cwd=cwd, timeout=120)


@pytest.mark.parametrize('name', ['lamp_robotics_semantics.structuredslugs', 'predict_safety.structuredslugs',
                                  'two_goals_next_liveness.slugsin'])
@pytest.mark.parametrize('robotics_semantics', [False, True], ids=['standard', 'robotics'])
def test_command_line_prints_the_result_line(tmp_path, name, robotics_semantics):
    slugsin = tmp_path / 'spec.slugsin'
    slugsin.write_text(load(name).to_slugsin())
    flags = ['--sysInitRoboticsSemantics'] if robotics_semantics else []
    completed = gr1synth(*flags, slugsin)
    assert completed.returncode == 0, completed.stderr
    realizable = EXPECTED[name][robotics_semantics]
    expected_line = f'RESULT: Specification is {"realizable" if realizable else "unrealizable"}.'
    assert expected_line in completed.stderr.splitlines()


# --- ltl_synthesizer.external, driven through gr1synth and through broken executables --------

def script(tmp_path, name, body):
    path = tmp_path / name
    path.write_text('#!/bin/sh\n' + body + '\n')
    path.chmod(0o755)
    return str(path)


@pytest.fixture
def gr1synth_executable(tmp_path):
    """Our synthesizer behind a slugs-like executable."""
    return script(tmp_path, 'gr1synth', f'cd "{REPOSITORY}" && exec "{sys.executable}" -m ltl_synthesizer "$@"')


def write_slugsin(tmp_path, name):
    path = tmp_path / (Path(name).stem + '.slugsin')
    path.write_text(load(name).to_slugsin())
    return path


@pytest.mark.external
@pytest.mark.parametrize('robotics_semantics', [False, True], ids=['standard', 'robotics'])
def test_external_run_reads_result_and_strategy(tmp_path, gr1synth_executable, robotics_semantics):
    name = 'lamp_robotics_semantics.structuredslugs'
    realizable, strategy, stderr = run_external_synthesizer(
        gr1synth_executable, write_slugsin(tmp_path, name), tmp_path / 'out.json',
        robotics_semantics=robotics_semantics, timeout=120)
    assert realizable == EXPECTED[name][robotics_semantics]
    assert 'RESULT: Specification is' in stderr
    if realizable:
        assert Oracle(load(name)).check_strategy(strategy, robotics_semantics) == []
    else:
        assert strategy is None and not (tmp_path / 'out.json').exists()


@pytest.mark.external
def test_external_run_of_a_safety_game(tmp_path, gr1synth_executable):
    name = 'copy_safety.structuredslugs'
    realizable, strategy, _ = run_external_synthesizer(
        gr1synth_executable, write_slugsin(tmp_path, name), tmp_path / 'out.json', timeout=120)
    assert realizable
    assert Oracle(load(name)).check_strategy(strategy) == []


def test_missing_executable(tmp_path):
    missing = str(tmp_path / 'no-such-slugs')
    with pytest.raises(ExternalSynthesizerError) as caught:
        run_external_synthesizer(missing, write_slugsin(tmp_path, 'copy_safety.structuredslugs'), tmp_path / 'o.json')
    assert caught.value.code == 'SYNTHESIZER_BACKEND_FAILED'
    assert caught.value.item == missing
    assert 'cannot run synthesizer' in str(caught.value)


@pytest.mark.external
@pytest.mark.parametrize('body, message', [
    ('echo "Segmentation fault" >&2; kill -SEGV $$', 'without a RESULT line'),
    ('echo "RESULT: Specification is realizable." >&2; exit 3', 'exited with status 3'),
    ('echo "all good"; exit 0', 'without a RESULT line'),
    ('echo "RESULT: Specification is realizable." >&2', 'strategy'),
    ('echo "RESULT: Specification is realizable." >&2; echo "{not json" > "$5"', 'unreadable'),
])
def test_broken_executables_are_reported(tmp_path, body, message):
    broken = script(tmp_path, 'broken-slugs', body)
    with pytest.raises(ExternalSynthesizerError) as caught:
        run_external_synthesizer(broken, write_slugsin(tmp_path, 'copy_safety.structuredslugs'),
                                 tmp_path / 'out.json', timeout=30)
    assert caught.value.code == 'SYNTHESIZER_BACKEND_FAILED'
    assert caught.value.item == broken
    assert message in str(caught.value)


@pytest.mark.external
def test_arguments_follow_slugs_conventions(tmp_path):
    recorder = script(tmp_path, 'recorder', 'printf "%s\\n" "$@" > "$(dirname "$0")/args"; '
                      'echo "RESULT: Specification is unrealizable." >&2')
    spec_path = write_slugsin(tmp_path, 'copy_safety.structuredslugs')
    for robotics_semantics in (True, False):
        assert run_external_synthesizer(recorder, spec_path, tmp_path / 'o.json',
                                        robotics_semantics=robotics_semantics)[:2] == (False, None)
        arguments = (tmp_path / 'args').read_text().split('\n')[:-1]
        semantics = ['--sysInitRoboticsSemantics'] if robotics_semantics else []
        assert arguments == ['--explicitStrategy', '--jsonOutput', *semantics, str(spec_path),
                             str(tmp_path / 'o.json')]


def sleeper(tmp_path):
    return script(tmp_path, 'slow-slugs', 'echo $$ > "$(dirname "$0")/pid"; exec sleep 60')


def assert_killed(tmp_path):
    pid = int((tmp_path / 'pid').read_text())
    with pytest.raises(ProcessLookupError):
        os.kill(pid, 0)


@pytest.mark.external
def test_timeout_kills_the_process(tmp_path):
    started = time.monotonic()
    with pytest.raises(SynthesisCancelledError) as caught:
        run_external_synthesizer(sleeper(tmp_path), write_slugsin(tmp_path, 'copy_safety.structuredslugs'),
                                 tmp_path / 'o.json', timeout=0.5)
    assert (caught.value.reason, caught.value.code) == ('timeout', 'SYNTHESIS_TIMEOUT')
    assert time.monotonic() - started < 10
    assert_killed(tmp_path)


@pytest.mark.external
def test_cancel_kills_the_process(tmp_path):
    cancel = threading.Event()
    threading.Timer(0.5, cancel.set).start()
    with pytest.raises(SynthesisCancelledError) as caught:
        run_external_synthesizer(sleeper(tmp_path), write_slugsin(tmp_path, 'copy_safety.structuredslugs'),
                                 tmp_path / 'o.json', cancel=cancel)
    assert caught.value.reason == 'cancelled'
    assert_killed(tmp_path)
