"""Record what the suite produces, so that a refactor can be shown byte-identical.

    AMENT_PREFIX_PATH=$PWD/.venv/flexbe .venv/bin/python bench/record_outputs.py /tmp/before
    ... change the code ...
    AMENT_PREFIX_PATH=$PWD/.venv/flexbe .venv/bin/python bench/record_outputs.py /tmp/after
    diff -r -x '*byproducts*' /tmp/before /tmp/after      # expected: nothing

For nine tasks on ATLAS, delivery_rover and shelf_picker it writes what the commands print:
``compile`` in three formats with ``--explain``, ``compile --diagnose``, ``repair --json``,
``export-behavior`` (the package too) and ``execute --json``; then the web GUI's answers
(systems, goal checks, jobs, state machines, plays, repairs, downloads) for four jobs, in
gui_answers.json. What changes from run to run (times, temporary paths, job ids, ROS log
stamps) is written as ``<v>``. About 3-4 minutes on a 2-core machine.
"""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
BIN = Path(sys.executable).parent
VOLATILE = re.compile(r'\d+\.\d+ ?(s|ms|seconds)\b|/tmp/\S+|\b\d{4}-\d\d-\d\dT\S+|pid \d+|\b\d+-[0-9a-f]{8}\b'
                      r'|_[0-9a-f]{8}\b|\[\d{9,}\.\d+\]|"\w*(seconds|time|elapsed|_at|_ms|_s)": [\d.e-]+')
# (name, system, initial conditions, goals, more arguments)
TASKS = [
    ('atlas_paper', 'atlas', 'stand_prep', 'look_down,pickup_object', []),
    ('atlas_retry', 'atlas', 'stand_prep', 'look_down,pickup_object', ['--sm-outcomes', 'finished']),
    ('atlas_unordered', 'atlas', 'stand_prep', 'walk,look_down,manipulate', ['--unordered']),
    ('atlas_wrong_order', 'atlas', 'stand_prep', 'look_down,stand_prep', []),
    ('atlas_bad_name', 'atlas', 'stand_prep', 'fly', []),
    ('rover', 'delivery_rover', '', 'hand_over', []),
    ('rover_two', 'delivery_rover', '', 'drive,hand_over', []),
    ('rover_contra', 'delivery_rover', '', 'drive,!drive', []),
    ('picker', 'shelf_picker', '', 'place', []),
]
GUI_JOBS = [
    {'system': 'atlas', 'initial_conditions': ['stand_prep'], 'goals': ['look_down', 'pickup_object']},
    {'system': 'atlas', 'initial_conditions': ['stand_prep'], 'goals': ['look_down', 'stand_prep']},
    {'system': 'delivery_rover', 'initial_conditions': [], 'goals': ['drive', 'hand_over']},
    {'system': 'shelf_picker', 'goals': ['place']},
]
DOWNLOADS = ('spec.structuredslugs', 'automaton.yaml', 'state_machine.yaml', 'state_machine.dot')


def steady(text: str, out: Path) -> str:
    return VOLATILE.sub('<v>', text.replace(str(out), '<OUT>'))


def record_command(out: Path, name: str, arguments: list[str]) -> None:
    done = subprocess.run([str(BIN / 'behavior-synthesis'), *arguments], cwd=ROOT, capture_output=True, text=True,
                          timeout=600)
    (out / name).write_text(f'exit {done.returncode}\n--- stdout\n{steady(done.stdout, out)}\n'
                            f'--- stderr\n{steady(done.stderr, out)}')


def record_commands(out: Path) -> None:
    for name, system, initial, goals, more in TASKS:
        task = ['--system', system, '--initial-conditions', initial, '--goals', goals, *more]
        for output_format in ('structuredslugs', 'slugsin', 'json'):
            record_command(out, f'compile_{name}.{output_format}',
                           ['compile', *task, '--format', output_format, '--explain'])
        record_command(out, f'diagnose_{name}', ['compile', *task, '--diagnose', '--format', 'json'])
        record_command(out, f'repair_{name}', ['repair', *task, '--json', '--time-budget', '60',
                                               '--max-proposals', '3'])
        record_command(out, f'export_{name}.log', ['export-behavior', *task, '--name', f'rec_{name}',
                                                   '--byproducts-dir', str(out / 'byproducts' / name),
                                                   '-o', str(out / f'export_{name}')])
        if system != 'atlas':
            record_command(out, f'execute_{name}', ['execute', *task, '--json',
                                                    '--byproducts-dir', str(out / 'byproducts-execute' / name)])
    record_command(out, 'execute_atlas_paper', ['execute', '--goals', 'look_down,pickup_object', '--json',
                                                '--byproducts-dir', str(out / 'byproducts-execute' / 'atlas')])


def record_gui_answers(out: Path) -> None:
    from fastapi.testclient import TestClient

    from synthesis_manager.programs.gui import ros_backend
    from synthesis_manager.web.routes import create_app

    sys.path.append(str(ROOT / 'test' / 'synthesis_manager'))  # after the packages: test/ mirrors their names
    from gui_jobs import gui_args, run_job

    answers = {}
    with ros_backend(gui_args(out / 'gui-byproducts')) as backend, TestClient(create_app(backend)) as client:
        answers['systems'] = client.get('/api/systems').json()
        for system in ('atlas', 'mobile_manipulator', 'delivery_rover', 'shelf_picker'):
            answers[f'system {system}'] = client.get(f'/api/systems/{system}').json()
            answers[f'goal-check {system}'] = client.post('/api/goal-check', json={'system': system, 'goals': []}).json()
        for request in GUI_JOBS:
            label = f"{request['system']} {','.join(request['goals'])}"
            _, job = run_job(client, request)
            answers[f'job {label}'] = {k: v for k, v in job.items() if k not in ('id', 'timeline', 'created')}
            job_id = client.post('/api/jobs', json=request).json()['id']
            for _ in range(600):  # the same request again: its answer, then what is asked of the job
                if client.get(f'/api/jobs/{job_id}').json().get('outcome'):
                    break
                time.sleep(0.1)
            answers[f'state-machine {label}'] = client.get(f'/api/jobs/{job_id}/state-machine').json()
            answers[f'play {label}'] = client.post(f'/api/jobs/{job_id}/play', json={'moves': []}).json()
            answers[f'repair {label}'] = client.post('/api/repair', json=request).json()
            for name in DOWNLOADS:
                answer = client.get(f'/api/jobs/{job_id}/artifacts/{name}')
                answers[f'download {label} {name}'] = [answer.status_code, answer.text]
    (out / 'gui_answers.json').write_text(steady(json.dumps(answers, indent=1, sort_keys=True, default=str), out))


def main(argv: list[str]) -> int:
    if len(argv) != 1:
        print(__doc__, file=sys.stderr)
        return 2
    out = Path(argv[0]).resolve()
    out.mkdir(parents=True, exist_ok=True)
    os.environ.setdefault('AMENT_PREFIX_PATH', str(ROOT / '.venv' / 'flexbe'))  # the capability robots' states
    record_commands(out)
    record_gui_answers(out)
    print(f'recorded into {out}')
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
