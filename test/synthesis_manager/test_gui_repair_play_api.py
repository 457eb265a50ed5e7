"""The GUI's "Suggest fixes" (POST /api/repair) and play (POST /api/jobs/{id}/play) against the
real in-process pipeline, for ATLAS and a CNU capability robot (issue 33, items 2 and 3)."""

import re
import shutil
import threading
from concurrent.futures import ThreadPoolExecutor

import pytest
from fastapi.testclient import TestClient

from respec.robot import SystemCatalog
from respec.robot.system import ServedCatalog, catalog_to_json
from synthesis_manager.programs.gui import ros_backend
from synthesis_manager.web import plays as plays_module
from synthesis_manager.web import repairs as repairs_module
from synthesis_manager.web.backend import SynthesisBackend
from synthesis_manager.web.routes import create_app

from gui_jobs import gui_args, run_job

pytestmark = pytest.mark.ros

WRONG_ORDER = {'system': 'atlas', 'initial_conditions': ['stand_prep'], 'goals': ['look_down', 'stand_prep']}
PAPER_TASK = {'system': 'atlas', 'initial_conditions': ['stand_prep'], 'goals': ['look_down', 'pickup_object']}
# The delivery rover asked to drive and not to drive: its capability game cannot be won.
ROVER_CONTRADICTION = {'system': 'delivery_rover', 'initial_conditions': [], 'goals': ['drive', '!drive']}
ROVER_TASK = {'system': 'delivery_rover', 'initial_conditions': [], 'goals': ['drive', 'hand_over']}


@pytest.fixture(scope='module')
def gui(tmp_path_factory, flexbe):
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv('AMENT_PREFIX_PATH', str(flexbe))  # the rover's FlexBE state classes
        with ros_backend(gui_args(tmp_path_factory.mktemp('gui-repair'))) as backend, \
                TestClient(create_app(backend)) as client:
            # The default 10 s search ended before its robot changes at load 7 on the 2 cores.
            backend.repairs.time_budget = 30.0
            yield backend, client


@pytest.fixture
def client(gui):
    return gui[1]


def play(client, job_id, moves):
    return client.post(f'/api/jobs/{job_id}/play', json={'moves': moves})


@pytest.mark.flexbe
def test_suggest_fixes_offers_verified_changes_and_an_applied_one_succeeds(client):
    _, refused = run_job(client, WRONG_ORDER)
    assert refused['outcome']['error_name'] == 'SPEC_UNSYNTHESIZABLE'
    response = client.post('/api/repair', json=WRONG_ORDER)
    assert response.status_code == 200, response.text
    repairs = response.json()
    assert repairs['problem'].startswith('SPEC_UNSYNTHESIZABLE: Goal 2 (stand_prep) can never be achieved')
    proposals = repairs['proposals']
    assert proposals and all(p['verified'] for p in proposals)
    assert [p['kind'] for p in proposals][:2] == ['goals_in_any_order', 'reorder_goals']
    robot = [p for p in proposals if p['changes_robot']]
    assert robot and all('config_patch' in p and 'request' not in p for p in robot)
    assert robot[0]['config_patch']['file'] == 'config/atlas.yaml'
    for proposal in proposals[:2]:
        _, fixed = run_job(client, proposal['request'])
        assert fixed['outcome']['error_name'] == 'SUCCESS', proposal['summary']


@pytest.mark.flexbe
def test_fixes_stream_as_json_lines_as_they_are_found(client):
    import json

    with client.stream('POST', '/api/repair', json=WRONG_ORDER, headers={'Accept': 'application/x-ndjson'}) as answer:
        assert answer.status_code == 200 and answer.headers['content-type'].startswith('application/x-ndjson')
        lines = [json.loads(line) for line in answer.iter_lines() if line]
    *found, last = lines
    assert found and all(set(line) == {'proposal'} for line in found), last
    assert [line['proposal'] for line in found] == last['result']['proposals']
    with client.stream('POST', '/api/repair', json={**WRONG_ORDER, 'system': 'nowhere'},
                       headers={'Accept': 'application/x-ndjson'}) as refused:
        assert refused.status_code == 404     # refusals come before the stream, as plain answers


@pytest.mark.flexbe
def test_a_refusal_before_synthesis_gets_fixes_too(client):
    from_stand = {**WRONG_ORDER, 'initial_conditions': ['stand']}
    _, refused = run_job(client, from_stand)
    assert refused['outcome']['error_name'] == 'INVALID_GOALS'
    repairs = client.post('/api/repair', json=from_stand).json()
    assert repairs['problem'].startswith('INVALID_GOALS') and repairs['proposals']
    applied = next(p for p in repairs['proposals'] if 'request' in p)
    assert run_job(client, applied['request'])[1]['outcome']['error_name'] == 'SUCCESS'


@pytest.mark.flexbe
def test_the_page_learns_which_refusals_can_be_repaired_and_the_search_budget(client):
    from ltl_specification.repair import REPAIRABLE

    assert client.get('/api/vocabulary').json()['repairable'] == sorted(REPAIRABLE) == [
        'ABSTRACTION_CONFIG_INVALID', 'INVALID_GOALS', 'SPEC_UNSYNTHESIZABLE']
    assert client.get('/api/info').json()['repair_time_budget'] == 30.0  # the module's GUI's


@pytest.mark.flexbe
def test_a_task_that_can_be_done_needs_no_fix_and_bad_requests_are_refused(client):
    repairs = client.post('/api/repair', json=PAPER_TASK).json()
    assert repairs['realizable'] is True and repairs['proposals'] == []
    unknown = client.post('/api/repair', json={**PAPER_TASK, 'system': 'nowhere'})
    assert unknown.status_code == 404 and unknown.json()['item'] == 'nowhere'
    no_goals = client.post('/api/repair', json={**PAPER_TASK, 'goals': []})
    assert no_goals.status_code == 422 and no_goals.json()['item'] == 'goals'


@pytest.mark.flexbe
def test_custom_ltl_is_part_of_the_request_and_a_weakened_guarantee_is_proposed(client):
    forbidden = {**PAPER_TASK, 'goals': ['look_down'], 'custom_ltl': {'sys_trans': ['!look_down_a']}}
    _, refused = run_job(client, forbidden)
    assert refused['outcome']['error_name'] == 'SPEC_UNSYNTHESIZABLE'
    assert '!look_down_a' in refused['outcome']['ltl_specification']['sys_trans']
    proposals = client.post('/api/repair', json=forbidden).json()['proposals']
    weakened = next(p for p in proposals if p['kind'] == 'weaken_guarantee')
    _, fixed = run_job(client, {**forbidden, 'custom_ltl': weakened['custom_ltl']})
    assert fixed['outcome']['error_name'] == 'SUCCESS'
    bad = client.post('/api/jobs', json={**forbidden, 'custom_ltl': {'sys_nonsense': ['x']}})
    assert bad.status_code == 422 and bad.json()['item'] == 'sys_nonsense'


@pytest.mark.flexbe
def test_playing_the_robot_of_an_unrealizable_job_until_it_loses(client):
    _, job = run_job(client, WRONG_ORDER)
    start = play(client, job['id'], [])
    assert start.status_code == 200, start.text
    turn = start.json()
    assert turn['play'] == 'robot' and turn['step'] == 0 and 'now in stand_prep' in turn['happened']
    # A game with an end, in the task's words: the goal it cannot reach named once, progress first.
    assert turn['blocked_goal'] == ('the environment keeps goal 1 (the state machine ends finished or the state '
                                    'machine ends failed) from ever holding, whichever move the robot makes')
    assert turn['max_moves'] == 12 and turn['verdict'] == ''
    assert turn['goals'] == [{'words': 'the state machine ends finished or the state machine ends failed',
                              'reached': False}]
    assert turn['moves'][0]['words'].endswith(' starts') and not turn['moves'][0]['repeats']
    ranks = [2 if m['dead_end'] else 1 if m['repeats'] else 0 for m in turn['moves']]
    assert ranks == sorted(ranks)  # live moves, then loops, then dead ends
    dead_end = next(move for move in turn['moves'] if move['dead_end'])
    lost = play(client, job['id'], [dead_end['index']]).json()
    assert lost['lost'] and 'deadlock' in lost['lost'] and lost['moves'] == []
    assert lost['verdict'] == f"the environment wins: {lost['lost']}"
    keep = next(m for m in turn['moves'] if m['words'] == 'keep every output as it is')
    assert keep['repeats']
    again = play(client, job['id'], [keep['index']]).json()
    assert again['verdict'].startswith('the environment wins: the robot came back to a position of this play')
    assert again['moves'] == [] and again['history'] == ['nothing changes']
    # Progress moves until the end: a verdict within the bound, no line said twice, no raw "_a off".
    moves, said = [], {turn['blocked_goal']}
    while not turn['verdict']:
        assert len(moves) <= turn['max_moves']
        moves.append(turn['moves'][0]['index'])
        turn = play(client, job['id'], moves).json()
        assert not turn['blocked_goal'] or turn['blocked_goal'] not in said
        said.add(turn['blocked_goal'])
        assert all(not re.search(r'\b\w+_a off\b', m['words']) for m in turn['moves'])
        assert all(not re.search(r'\b\w+_a off\b', line) for line in turn['history'])
    assert turn['verdict'].startswith('the environment wins: ') and turn['moves'] == []

    wrong = play(client, job['id'], [999])
    assert wrong.status_code == 400
    assert (wrong.json()['error'], wrong.json()['item']) == ('BAD_MOVE', 'moves')
    assert 'move 999 at step 0 does not exist' in wrong.json()['message']
    assert play(client, job['id'], ['look_down']).status_code == 422   # a robot's moves are indices


@pytest.mark.flexbe
def test_playing_the_environment_of_a_machine_until_it_ends(client):
    _, job = run_job(client, PAPER_TASK)
    turn = play(client, job['id'], []).json()
    assert turn['play'] == 'environment' and turn['active'] and turn['outcomes']
    moves = []
    while turn['ended'] is None:      # report the first outcome (success) of each state
        moves.append(turn['outcomes'][0])
        turn = play(client, job['id'], moves).json()
        assert len(moves) < 20
    assert turn['ended'] == 'finished' and turn['active'] is None and turn['outcomes'] == []
    assert [state for state, _ in turn['history']][:1] == [play(client, job['id'], []).json()['active']]

    wrong = play(client, job['id'], [moves[0], 'exploded'])
    assert wrong.status_code == 400 and wrong.json()['error'] == 'BAD_MOVE'
    assert "move 'exploded' at step 1 does not exist" in wrong.json()['message']
    after_the_end = play(client, job['id'], [*moves, moves[0]])
    assert after_the_end.status_code == 400 and 'already ended' in after_the_end.json()['message']
    assert play(client, job['id'], [0]).status_code == 422    # an environment's moves are outcomes
    assert client.post(f"/api/jobs/{job['id']}/play", json={'moves': [], 'extra': 1}).status_code == 422


@pytest.mark.flexbe
def test_nothing_to_play_and_unknown_jobs(client):
    _, compiled = run_job(client, {**PAPER_TASK, 'option': 'ltl_compilation_only'})
    nothing = play(client, compiled['id'], [])
    assert nothing.status_code == 409 and nothing.json()['item'] == compiled['id']
    assert play(client, 'no-such-job', []).status_code == 404


@pytest.mark.flexbe
def test_a_capability_robot_offers_its_capabilities_as_actions_and_negated_goals(client):
    choices = client.get('/api/systems/delivery_rover').json()
    assert choices['control_modes'] == []
    assert {a['name']: a['preconditions'] for a in choices['actions']} == {
        'check_battery': [], 'charge': ['!battery_ok'], 'drive': ['battery_ok'], 'hand_over': ['drive']}
    negated = [g['name'] for group in choices['goal_groups'] for g in group['items'] if g['name'].startswith('!')]
    assert negated == ['!battery_ok', '!drive', '!hand_over']   # CNU's goals may be negated
    atlas = client.get('/api/systems/atlas').json()
    assert not any(g['name'].startswith('!') for group in atlas['goal_groups'] for g in group['items'])


@pytest.mark.flexbe
def test_a_capability_robot_plays_both_ways_and_is_repaired(client):
    _, refused = run_job(client, ROVER_CONTRADICTION)
    assert refused['outcome']['error_name'] == 'SPEC_UNSYNTHESIZABLE', refused['outcome']['message']
    turn = play(client, refused['id'], []).json()
    assert turn['play'] == 'robot' and turn['moves'] and turn['happened'] == 'check_battery_a'
    moves = []
    for _ in range(12):               # always the first move: the play goes round, never won
        if turn['lost'] or not turn['moves']:
            break
        moves.append(turn['moves'][0]['index'])
        turn = play(client, refused['id'], moves).json()
        assert not (turn['values']['finished'] or turn['values']['failed'])
    assert turn['verdict'].startswith('the environment wins: ')  # the play has an end

    repairs = client.post('/api/repair', json=ROVER_CONTRADICTION).json()
    dropped = next(p for p in repairs['proposals'] if p['kind'] == 'drop_goal')
    _, fixed = run_job(client, dropped['request'])
    assert fixed['outcome']['error_name'] == 'SUCCESS'

    _, job = run_job(client, ROVER_TASK)
    assert job['outcome']['error_name'] == 'SUCCESS', job['outcome']['message']
    turn, moves = play(client, job['id'], []).json(), []
    while turn['ended'] is None and len(moves) < 20:
        moves.append(turn['outcomes'][0])
        turn = play(client, job['id'], moves).json()
    assert turn['ended'] == 'finished'


def test_repairs_use_the_robot_system_the_gui_has_not_a_file_here(tmp_path):
    """A GUI attached to a remote suite has its systems as served text: the search in the
    child process must use them (here the file is gone once the catalog was read)."""
    config = tmp_path / 'config'
    config.mkdir()
    shutil.copy('config/atlas.yaml', config / 'atlas_elsewhere.yaml')
    served = ServedCatalog.from_json(catalog_to_json(SystemCatalog(str(config))))
    shutil.rmtree(config)
    backend = SynthesisBackend(run_goal=None, systems=served)
    with TestClient(create_app(backend)) as client:
        repairs = client.post('/api/repair', json={**WRONG_ORDER, 'system': 'atlas_elsewhere'})
    assert repairs.status_code == 200, repairs.text
    assert repairs.json()['proposals'][0]['request']['system'] == 'atlas_elsewhere'


def busy_while_the_slots_are_held(monkeypatch, owner, method: str, slots: int, send) -> tuple:
    """Send ``slots`` requests whose ``owner.method`` waits, then one more: (held answers, that answer)."""
    running, release = threading.Semaphore(0), threading.Event()
    real = getattr(owner, method)

    def held(*args):
        running.release()
        release.wait(30)
        return real(*args)

    monkeypatch.setattr(owner, method, held)
    with ThreadPoolExecutor(slots) as pool:
        waiting = [pool.submit(send) for _ in range(slots)]
        try:
            for _ in waiting:
                assert running.acquire(timeout=30)
            busy = send()
        finally:
            release.set()
        return [future.result() for future in waiting], busy


def test_repairs_beyond_the_limit_are_busy(monkeypatch):
    backend = SynthesisBackend(run_goal=None, max_repairs=1)
    with TestClient(create_app(backend)) as client:
        held, busy = busy_while_the_slots_are_held(monkeypatch, repairs_module.RepairSearch, 'run', 1,
                                                   lambda: client.post('/api/repair', json=WRONG_ORDER))
        assert [answer.status_code for answer in held] == [200]
        assert (busy.status_code, busy.json()['error'], busy.json()['item']) == (429, 'BUSY', 'repairs')
        assert busy.headers['retry-after'] == str(int(backend.repairs.time_budget))
        monkeypatch.undo()
        assert client.post('/api/repair', json=WRONG_ORDER).status_code == 200   # the slot is free again


@pytest.mark.flexbe
def test_plays_beyond_the_limit_are_busy(gui, monkeypatch):
    backend, client = gui
    _, job = run_job(client, WRONG_ORDER)
    held, busy = busy_while_the_slots_are_held(monkeypatch, plays_module.Plays, 'turn', backend.plays.max_at_once,
                                               lambda: play(client, job['id'], []))
    assert [answer.status_code for answer in held] == [200] * backend.plays.max_at_once
    assert (busy.status_code, busy.json()['error'], busy.json()['item']) == (429, 'BUSY', 'plays')
    assert busy.headers['retry-after'] == '1'


def search_settings(time_budget=10.0):
    from ltl_specification.repair import TaskRequest
    from respec.robot import robot_system

    robot = robot_system('atlas')
    return {'system': robot.name, 'files': dict(robot.files), 'config_file': robot.config_file,
            'request': TaskRequest('atlas', ('stand_prep',), ('look_down', 'stand_prep')).to_dict(),
            'custom_ltl': None, 'time_budget': time_budget, 'max_proposals': 5}


def test_a_search_past_its_deadline_is_killed(monkeypatch):
    from ltl_specification import repair_process

    from respec.child_processes import runner

    monkeypatch.setattr(repair_process, 'ANSWER_GRACE', 0.0)
    monkeypatch.setattr(runner, 'DEADLINE_GRACE_SECONDS', 0.0)  # no time to report its own timeout
    search = repair_process.RepairSearch(search_settings(time_budget=0.01))
    with pytest.raises(repair_process.RepairSearchError, match='ended at its time budget'):
        search.run()
    assert search.child.process.poll() is not None


def test_stopping_the_gui_ends_a_running_search_at_once():
    import time

    from ltl_specification.repair_process import RepairSearch, RepairSearchError

    search = RepairSearch(search_settings())
    with ThreadPoolExecutor(1) as pool:
        answer = pool.submit(search.run)
        started = time.monotonic()
        search.stop()
        with pytest.raises(RepairSearchError):
            answer.result(timeout=10)
    assert time.monotonic() - started < 2.0 and search.child.process.poll() is not None


@pytest.mark.flexbe
def test_a_client_that_goes_away_stops_its_search(gui):
    """Issue 48, item 7: a client disconnecting did not stop its search (a BDD bomb's ran to its
    hard kill). The stream's end stops it: its child is killed at once."""
    import time

    backend, _ = gui
    pairs = 26
    xs, ys = [f'x{i}' for i in range(pairs)], [f'y{i}' for i in range(pairs)]
    bomb = {'env_props': xs, 'sys_props': ys,
            'sys_trans': [' | '.join(xs + ys + ['!x0']), ' & '.join(f"(next(y{i}) <-> x{i})" for i in range(pairs))]}
    run = backend.repairs.start({**WRONG_ORDER, 'custom_ltl': bomb})
    deadline = time.monotonic() + 10
    while run.search is None or run.search.child.process.poll() is not None:
        assert time.monotonic() < deadline, 'the search never started'
        time.sleep(0.05)
    child = run.search.child.process
    stopped = time.monotonic()
    run.stop()
    child.wait(timeout=5)
    assert time.monotonic() - stopped < 2.0
