"""A capability robot (config/delivery_rover) over the GUI's API (issue 45): the form's choices
come from the robot through its view (web/robot_views.py), and Simulate runs its machine on the
simulated capability robot (no MuJoCo) with the operator in the loop: forced outcomes, held
sensors, each step's outcome and who chose it, the trace check."""

import pytest
from starlette.testclient import TestClient

from gui_jobs import follow_simulation, gui_args, operate, run_job

from synthesis_manager.programs.gui import ros_backend
from synthesis_manager.web.routes import create_app

pytestmark = [pytest.mark.ros, pytest.mark.flexbe]

ROVER_TASK = {'system': 'delivery_rover', 'goals': ['hand_over']}


@pytest.fixture(scope='module')
def client(tmp_path_factory, flexbe):
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv('AMENT_PREFIX_PATH', str(flexbe))  # the delivery rover's FlexBE state classes
        with ros_backend(gui_args(tmp_path_factory.mktemp('gui-rover'))) as backend, \
                TestClient(create_app(backend)) as client:
            yield client


def test_the_form_offers_what_the_capabilities_make_true_and_the_sensor_with_its_reporter(client):
    choices = client.get('/api/systems/delivery_rover').json()
    assert choices['drawing'] == 'capabilities' and choices['control_modes'] == []
    assert [g['type'] for g in choices['initial_groups']] == ['checkbox']
    assert [i['name'] for i in choices['initial_groups'][0]['items']] == ['battery_ok', 'battery_low']
    assert choices['default_initial_conditions'] == []   # the spec's own start
    made_true = choices['goal_groups'][0]['items']
    assert [g['name'] for g in made_true] == ['battery_ok', '!battery_ok', 'drive', 'hand_over']
    assert made_true[1]['hint'] == 'set by check_battery on low'
    assert choices['sensors'] == [{'name': 'battery_low', 'reported_by': ['check_battery']}]
    graph = {c['name']: c for c in choices['capability_graph']['capabilities']}
    assert graph['drive']['needs'] == [{'name': 'battery_ok', 'negated': False, 'text': 'battery_ok'}]
    assert {(m['text'], m['outcome']) for m in graph['check_battery']['makes']} == {('battery_ok', 'completed'),
                                                                                     ('!battery_ok', 'low')}
    assert choices['simulation'] == {'available': True, 'note': '', 'frames': False, 'sensors': ['battery_low'],
                                     'simulator': 'a simulated capability robot: each state answers one of its '
                                                  'outcomes, no physics',
                                     'faults': 'this capability answers the outcome it fails with, every time '
                                               '(fault injection)'}
    check = client.post('/api/goal-check', json={'system': 'delivery_rover', 'goals': []}).json()
    assert check['impossible_next'] == {}   # every goal offered can come first
    atlas = client.get('/api/systems/atlas').json()
    assert atlas['drawing'] == 'modes' and atlas['initial_groups'][0]['title'] == 'Control mode (one)'
    assert atlas['sensors'] == [] and atlas['default_initial_conditions'] == ['stand_prep']


def test_simulate_a_capability_robot_unattended_and_with_the_operator_forcing_outcomes(client):
    _, job = run_job(client, ROVER_TASK)
    assert job['outcome']['error_name'] == 'SUCCESS', job['outcome']['message']
    unattended = follow_simulation(client, client.post(f"/api/jobs/{job['id']}/simulations", json={}).json()['id'])
    assert unattended['outcome'] == 'finished' and unattended['check']['ok'] is True, unattended
    assert [s['capabilities'] for s in unattended['steps']] == [['check_battery'], ['drive'], ['hand_over']]
    assert {s['chosen_by'] for s in unattended['steps']} == {'the robot'}

    started = client.post(f"/api/jobs/{job['id']}/simulations", json={'autonomy': 0}).json()
    asked = []

    def answer(waiting):  # the battery is low, then the drive fails; anything else as the robot says
        asked.append(waiting)
        state = waiting['state'].rsplit('/', 1)[-1]
        if state.startswith('check_battery') and len(asked) == 1:
            return {'command': 'force', 'state': waiting['state'], 'outcome': 'low'}
        if state.startswith('drive'):
            return {'command': 'force', 'state': waiting['state'], 'outcome': 'failed'}
        return {'command': 'confirm', 'state': waiting['state']}
    run = operate(client, started['id'], answer)
    assert run['outcome'] == 'failed' and run['check']['ok'] is True, run
    steps = [(s['capabilities'][0], s['state_outcome'], s['chosen_by']) for s in run['steps']]
    assert steps[0] == ('check_battery', 'low', 'the operator') and steps[1][0] == 'charge'
    assert steps[-1] == ('drive', 'failed', 'the operator')
    assert asked[0] == {**asked[0], 'kind': 'confirm', 'outcome': 'ok', 'required': 0}

    held = client.post(f"/api/jobs/{job['id']}/simulations",
                       json={'autonomy': 0, 'sensors': {'battery_low': False}}).json()
    run = operate(client, held['id'], lambda waiting: {'command': 'force', 'state': waiting['state'], 'outcome': 'low'})
    assert run['check']['ok'] is False
    assert run['check']['violations'][0]['message'].startswith(
        "The operator forced 'low' on check_battery at step 1 with battery_low=false; the task assumed env_trans")
    refused = client.post(f"/api/jobs/{job['id']}/simulations", json={'sensors': {'sonar': True}})
    assert refused.status_code == 422 and refused.json()['item'] == 'sonar'


def test_the_shelf_picker_on_the_same_surfaces(client):
    """config/shelf_picker, the second shipped capability robot: its sensor and its grasp that fails."""
    choices = client.get('/api/systems/shelf_picker').json()
    assert choices['sensors'] == [{'name': 'item_on_shelf', 'reported_by': ['look']}]
    assert [g['name'] for g in choices['goal_groups'][0]['items']] == ['item_seen', '!item_seen', 'grasp', 'place']
    _, job = run_job(client, {'system': 'shelf_picker', 'goals': ['place']})
    assert job['outcome']['error_name'] == 'SUCCESS', job['outcome']['message']
    run = follow_simulation(client, client.post(f"/api/jobs/{job['id']}/simulations",
                                                json={'fail_first': ['grasp']}).json()['id'])
    assert run['outcome'] == 'failed' and run['check']['ok'] is True
    assert [(s['capabilities'][0], s['state_outcome'], s['chosen_by']) for s in run['steps']] == [
        ('look', 'seen', 'the robot'), ('grasp', 'failed', 'the script')]
    started = client.post(f"/api/jobs/{job['id']}/simulations", json={'autonomy': 0}).json()
    answers = iter(['empty', 'seen', 'done', 'done'])   # the shelf is empty at first, then restocked
    run = operate(client, started['id'], lambda waiting: {'command': 'force', 'state': waiting['state'],
                                                          'outcome': next(answers)})
    assert run['outcome'] == 'finished' and run['check']['ok'] is True
    assert [s['state_outcome'] for s in run['steps']] == ['empty', 'seen', 'done', 'done']


def test_the_operator_sets_a_sensor_during_a_run_and_the_robot_answers_by_it(client):
    _, job = run_job(client, ROVER_TASK)
    started = client.post(f"/api/jobs/{job['id']}/simulations", json={'autonomy': 0}).json()
    refused = client.post(f"/api/simulations/{started['id']}/control",
                          json={'command': 'sensor', 'name': 'sonar', 'value': True})
    assert refused.status_code == 422 and refused.json()['item'] == 'sonar'
    asked = []

    def answer(waiting):  # at the first answer the battery reads low; confirm what the robot says
        if not asked:
            sent = client.post(f"/api/simulations/{started['id']}/control",
                               json={'command': 'sensor', 'name': 'battery_low', 'value': True})
            assert sent.status_code == 202, sent.text
        asked.append(waiting)
        return {'command': 'confirm', 'state': waiting['state']}
    run = operate(client, started['id'], answer)
    assert run['outcome'] == 'finished' and run['check']['ok'] is True, run
    steps = [(s['capabilities'][0], s['state_outcome'], s['chosen_by']) for s in run['steps']]
    # the robot read the sensor the operator set: low, so it charged (which leaves the battery not low)
    assert steps[:2] == [('check_battery', 'low', 'the robot'), ('charge', 'done', 'the robot')], steps
    assert steps[-1] == ('hand_over', 'done', 'the robot')
    assert {'command': 'sensor', 'name': 'battery_low', 'value': True} in run['operator_events']
