"""The operator in the loop over the GUI's API: autonomy, confirmations, forced outcomes,
InputState answers and stop reach the simulation's child while it runs."""

import pytest

from gui_jobs import PAPER_TASK, follow_simulation, operate, run_job

pytestmark = pytest.mark.ros


# Not 2x faster (issue 50): a synthesis and two simulations, unattended and operated confirmation by confirmation
# (4.6 s).
def test_high_autonomy_waits_for_confirmations_and_robot_time_does_not_count_the_wait(client):
    _, job = run_job(client, PAPER_TASK)
    unattended = follow_simulation(client, client.post(f"/api/jobs/{job['id']}/simulations", json={}).json()['id'])
    assert unattended['operator']['autonomy'] == 3 and unattended['outcome'] == 'finished'
    started = client.post(f"/api/jobs/{job['id']}/simulations", json={'autonomy': 2}).json()
    asked = []
    run = operate(client, started['id'], lambda waiting: asked.append(waiting) or (
        {'command': 'input', 'state': waiting['state'], 'value': waiting['default']} if waiting['kind'] == 'input'
        else {'command': 'confirm', 'state': waiting['state']}))
    assert run['outcome'] == 'finished' and run['check']['ok'] is True
    assert {w['kind'] for w in asked} == {'confirm', 'input'}
    assert all(w['required'] >= 2 for w in asked if w['kind'] == 'confirm')
    assert [s['state'] for s in run['steps']] == [s['state'] for s in unattended['steps']]
    assert abs(run['robot_time'] - unattended['robot_time']) < 0.05
    assert [e['command'] for e in run['operator_events']] == [w['kind'] for w in asked]


def test_a_forced_outcome_and_an_aborted_input_change_the_run_and_stop_ends_it(client):
    _, job = run_job(client, PAPER_TASK)
    started = client.post(f"/api/jobs/{job['id']}/simulations", json={'autonomy': 0}).json()

    def fail_first_wait(waiting):
        if waiting['kind'] == 'input':
            return {'command': 'input', 'state': waiting['state'], 'value': None}
        return {'command': 'force', 'state': waiting['state'], 'outcome': waiting['outcomes'][-1]}
    run = operate(client, started['id'], fail_first_wait)
    assert run['outcome'] == 'failed' and run['operator_events']

    started = client.post(f"/api/jobs/{job['id']}/simulations", json={'autonomy': 0}).json()
    run = operate(client, started['id'], lambda waiting: {'command': 'stop'})
    assert run['error']['code'] in ('PREEMPTED', -9) and 'the operator stopped the run' in run['error']['message']
    assert client.post(f"/api/simulations/{run['id']}/control", json={'command': 'pause'}).status_code == 409
    bad = client.post(f"/api/simulations/{run['id']}/control", json={'command': 'dance'})
    assert bad.status_code == 422 and bad.json()['item'] == 'command'
    assert client.post(f"/api/jobs/{job['id']}/simulations", json={'autonomy': 9}).status_code == 422
