"""One diagnosis, every channel (issue 33 item 1): whichever stage finds an impossible task, the
command line, the GUI's HTTP API (form check and job result) and both actions' results carry
the same leading sentence, the same unrealizable core and the same environment play.

ATLAS from ``stand`` with goals ``look_down, stand_prep`` is refused by the compiler
(INVALID_GOALS: no route reaches stand_prep); from ``stand_prep`` it is compiled and found
unrealizable by synthesis (SPEC_UNSYNTHESIZABLE). A CNU capability robot's goal that no
capability can make true is refused up front with the capability pre-check's sentence.
"""

import os
import subprocess
import sys
from argparse import Namespace

import pytest
from fastapi.testclient import TestClient

from suite_settings import suite_args
from synthesis_manager.client import SynthesisClient, make_flexbe_goal, make_goal
from synthesis_manager.programs.gui import RosGoalRunner
from synthesis_manager.suite import suite_node_factories
from synthesis_manager.web.backend import SynthesisBackend
from synthesis_manager.web.routes import create_app

pytestmark = pytest.mark.ros

GOALS = ['look_down', 'stand_prep']
SENTENCE = ('Goal 2 (stand_prep) can never be achieved: goal 1 (look_down) needs the robot in stand, and '
            'stand -> stand_prep is not a transition in config/atlas.yaml (from stand the robot can only change '
            'to manipulate, step, walk).')
COMPILATION_FAILED = 'LTL compilation failed: '   # the stage that refused, before the sentence
CORE_HEADING = 'Unrealizable core'
PLAY_HEADING = 'How the environment wins'


@pytest.fixture
def channels(ros, tmp_path):
    """An in-process suite, with our action's client, CNU's action's client and the GUI's API."""
    from rclpy.node import Node

    for factory in suite_node_factories(suite_args(tmp_path)):
        ros.add_node(factory)
    node = ros.add_node(Node, 'diagnosis_channels')
    ours, cnus = SynthesisClient(node, 'behavior_synthesis'), SynthesisClient(node, 'flexbe_synthesis')
    assert ours.wait_for_server(timeout=10.0) and cnus.wait_for_server(timeout=10.0)
    with TestClient(create_app(SynthesisBackend(RosGoalRunner(ours, goal_timeout=120)))) as gui:
        yield Namespace(ours=ours, cnus=cnus, gui=gui)


def cli_compile(*arguments, env=None) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, '-m', 'synthesis_manager', 'compile', *arguments, '-o', os.devnull],
                          capture_output=True, text=True, timeout=120, env=env)


def diagnosis_part(message: str) -> str:
    """A message from its sentence through the environment play (without what a stage adds: the
    stage's name before, the synthesizer's own details after)."""
    message = message.removeprefix(COMPILATION_FAILED)
    return without_fixes(message).split('\n\nDetails from the synthesizer:')[0]


def without_fixes(message: str) -> str:
    """A result's message without the verified fixes the server suggests after it
    (test_suggested_fixes.py), or a CNU result's messages[] (joined) without their lines."""
    message = message.split('\n\nVerified fixes')[0]
    return '\n'.join(line for line in message.split('\n') if not line.startswith('Suggested fix '))


def gui_job(gui, request: dict) -> dict:
    started = gui.post('/api/jobs', json=request)
    assert started.status_code == 202, started.text
    job_id = started.json()['id']
    with gui.stream('GET', f'/api/jobs/{job_id}/events', timeout=180) as events:
        for _ in events.iter_lines():
            pass
    return gui.get(f'/api/jobs/{job_id}').json()


@pytest.mark.parametrize('start, code, cnu_code', [('stand', 'INVALID_GOALS', 'SPEC_COMPILATION_FAILED'),
                                                   ('stand_prep', 'SPEC_UNSYNTHESIZABLE', 'SPEC_UNSYNTHESIZABLE')])
def test_the_same_diagnosis_in_every_channel_whichever_stage_finds_it(channels, start, code, cnu_code):
    # the command line, offline
    cli = cli_compile('--system', 'atlas', '--initial-conditions', start, '--goals', ','.join(GOALS), '--diagnose')
    assert cli.returncode == 1
    first, _, rest = cli.stderr.partition('\n')
    if code == 'INVALID_GOALS':
        assert first == f"error: INVALID_GOALS: {SENTENCE} [item: 'stand_prep']"
        cli_diagnosis = f'{SENTENCE}\n{rest.rstrip()}'
    else:
        assert first == f'SPEC_UNSYNTHESIZABLE: {SENTENCE}'
        cli_diagnosis = cli.stderr.removeprefix('SPEC_UNSYNTHESIZABLE: ').rstrip()
    assert CORE_HEADING in cli_diagnosis and PLAY_HEADING in cli_diagnosis
    assert 'state look_down (TiltHeadState) starts' in cli_diagnosis    # the play in the machine's terms
    assert 'look_down returns done, goal look_down achieved' in cli_diagnosis

    # the GUI: the form's live check, then the job's result (its banner shows the first line)
    check = channels.gui.post('/api/goal-check', json={'system': 'atlas', 'initial_conditions': [start],
                                                        'goals': GOALS}).json()
    assert [finding['sentence'] for finding in check['findings']] == [SENTENCE]
    job = gui_job(channels.gui, {'system': 'atlas', 'initial_conditions': [start], 'goals': GOALS})
    assert job['outcome']['error_name'] == code
    assert diagnosis_part(job['outcome']['message']) == cli_diagnosis

    # both actions' results: error_code.message, and CNU's messages[]
    result = channels.ours.run(make_goal('atlas', [start], GOALS), timeout=120)
    assert result.error_name == code and diagnosis_part(result.message) == cli_diagnosis
    cnu = channels.cnus.run(make_flexbe_goal('atlas', [start], GOALS), timeout=120)
    assert cnu.error_name == cnu_code and cnu.message.startswith(f'{code}: ')
    assert diagnosis_part(cnu.message.removeprefix(f'{code}: ')) == cli_diagnosis

    # one environment play: the synthesizer's own play is left out of the message
    if code == 'SPEC_UNSYNTHESIZABLE':
        details = result.message.split('Details from the synthesizer:\n')[1]
        assert 'Environment play' not in details and 'step 0' not in details
        assert 'initial state(s)' in details   # what the synthesizer adds stays


@pytest.mark.flexbe
def test_a_goal_no_capability_makes_true_is_named_up_front_in_every_channel(channels, flexbe, monkeypatch):
    monkeypatch.setenv('AMENT_PREFIX_PATH', str(flexbe))
    sentence = ("Goal 'charge' can never be reached: no capability sets charge_m true and it starts false; "
                "add 'charge' to the postconditions of the capability that achieves it in "
                "delivery_rover/capabilities.yaml, or change the request's goals.")
    cli = cli_compile('--system', 'delivery_rover', '--goals', 'charge', '--diagnose',
                      env={**os.environ, 'AMENT_PREFIX_PATH': str(flexbe)})
    assert cli.returncode == 1 and cli.stderr == f"error: INVALID_GOALS: {sentence} [item: 'charge']\n"
    check = channels.gui.post('/api/goal-check', json={'system': 'delivery_rover', 'goals': ['charge']}).json()
    assert [finding['sentence'] for finding in check['findings']] == [sentence]
    # The form offers what capabilities make true (issue 45): none of them is impossible after 'charge' is refused.
    assert check['impossible_next'] == {}
    job = gui_job(channels.gui, {'system': 'delivery_rover', 'initial_conditions': [], 'goals': ['charge']})
    assert (job['outcome']['error_name'], without_fixes(job['outcome']['message'])) == \
        ('INVALID_GOALS', COMPILATION_FAILED + sentence)
    result = channels.ours.run(make_goal('delivery_rover', [], ['charge']), timeout=120)
    assert (result.error_name, without_fixes(result.message)) == ('INVALID_GOALS', COMPILATION_FAILED + sentence)
    cnu = channels.cnus.run(make_flexbe_goal('delivery_rover', [], ['charge']), timeout=120)
    assert without_fixes(cnu.message) == f'INVALID_GOALS: {COMPILATION_FAILED}{sentence}'


def test_a_specification_given_whole_is_diagnosed_by_its_formulas(channels):
    from ltl_specification.diagnosis import diagnose
    from respec.parsing import spec_from_text_sections

    sections = {'env_props': ['door_open'], 'sys_props': ['inside'], 'env_trans': ['!next(door_open)'],
                'sys_trans': ['next(inside) -> next(door_open)'], 'sys_liveness': ['inside']}
    result = channels.ours.run(make_goal('atlas', [], [], option='ltl_synthesis_only', ltl_specification=sections),
                               timeout=120)
    assert result.error_name == 'SPEC_UNSYNTHESIZABLE'
    offline = diagnose(spec_from_text_sections({**{s: [] for s in ('env_init', 'sys_init', 'env_liveness')},
                                                **sections}))
    assert diagnosis_part(result.message) == offline.message()
    assert 'formula sys_trans[0] (the specification): next(inside) -> next(door_open)' in result.message
    assert PLAY_HEADING in result.message and 'Details from the synthesizer' in result.message
