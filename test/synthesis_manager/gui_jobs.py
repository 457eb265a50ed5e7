"""The GUI's JSON API driven as the page drives it: a job to its end, a simulation followed and operated."""

import json

from synthesis_manager.programs.cli import build_parser

PAPER_TASK = {'system': 'atlas', 'initial_conditions': ['stand_prep'], 'goals': ['look_down', 'pickup_object']}


def gui_args(byproducts_dir, *more):
    """The settings ``behavior-synthesis gui`` would get, parsed by the real command line."""
    return build_parser(only='gui').parse_args(
        ['gui', '--byproducts-dir', str(byproducts_dir), '--synthesis-timeout', '60',
         '--goal-timeout', '120', *more])


def follow(client, job_id):
    """Read the job's event stream to its end; returns (progress events, final job)."""
    progress, final = [], None
    with client.stream('GET', f'/api/jobs/{job_id}/events', timeout=180) as response:
        assert response.status_code == 200
        assert response.headers['content-type'].startswith('text/event-stream')
        kind = None
        for line in response.iter_lines():
            if line.startswith('event: '):
                kind = line[len('event: '):]
            elif line.startswith('data: '):
                job = json.loads(line[len('data: '):])
                if kind == 'finished':
                    final = job
                else:
                    progress.append(job)
    return progress, final


def run_job(client, request):
    response = client.post('/api/jobs', json=request)
    assert response.status_code == 202, response.text
    return follow(client, response.json()['id'])


def follow_simulation(client, simulation_id):
    with client.stream('GET', f'/api/simulations/{simulation_id}/events', timeout=300) as response:
        last = None
        for line in response.iter_lines():
            if line.startswith('data: '):
                last = json.loads(line[len('data: '):])
    return last


def operate(client, simulation_id, answer):
    """Follow the run; ``answer(waiting) -> command`` for each thing it waits for. The final run."""
    answered, last = set(), None
    with client.stream('GET', f'/api/simulations/{simulation_id}/events', timeout=300) as response:
        for line in response.iter_lines():
            if not line.startswith('data: '):
                continue
            last = json.loads(line[len('data: '):])
            waiting = (last.get('operator') or {}).get('waiting')
            key = json.dumps([len(last['steps']), waiting], sort_keys=True)
            if waiting and key not in answered:
                answered.add(key)
                sent = client.post(f'/api/simulations/{simulation_id}/control', json=answer(waiting))
                assert sent.status_code == 202, sent.text
    return last
