"""Requests whose synthesis runs until it is stopped: a specification whose strategy extraction
would take hours, and a robot system whose goal needs hundreds of parts assembled at once."""

import contextlib
import json
from pathlib import Path

import httpx

from synthesis_manager.client import make_goal

RUNAWAY_PARTS = 300


def many_parts_config(directory: Path, parts: int = RUNAWAY_PARTS) -> Path:
    """A robot system whose action ``assemble`` needs ``parts`` other actions completed first.

    Every part may be worked on at once and each may complete or fail at any time, so the
    specification for the goal ``assemble`` has 2 * (parts + 1) outcome inputs; with 300
    parts the whole pipeline runs for about 40 s (with 60 it ran for minutes until the
    synthesizer's static variable order of issue 44 made it 0.5 s).
    """
    names = [f'part{index}' for index in range(parts)]
    lines = ['system: many_parts', 'abstraction:', '  outcomes: [completed, failed]', '  initial_mode: idle',
             '  control_modes:', '    idle: []', '  actions:', f'    assemble: [{", ".join(names)}]',
             *(f'    {name}: []' for name in names),
             'flexbe:', '  sm_outcomes: {finished: finished, failed: failed}',
             '  packages: {states: many_parts_flexbe_states, behaviors: many_parts_flexbe_behaviors}', '  states:',
             *(f'    {name}_a: {{class_decl: {{name: RunState, param_names: [], param_values: []}}, '
               f'output_mapping: {{{name}_c: [done], {name}_f: [failed]}}, autonomy: [1, 0]}}'
               for name in ['idle', 'assemble', *names])]
    directory.mkdir(parents=True, exist_ok=True)
    (directory / 'many_parts.yaml').write_text('\n'.join(lines) + '\n')
    return directory


@contextlib.contextmanager
def runaway_gui_job(url: str):
    """A many_parts job started through the GUI's API, watched by its event stream (as the page
    does) until it synthesizes; yields the job's id with the stream still open."""
    answer = httpx.post(f'{url}api/jobs', json={'system': 'many_parts', 'initial_conditions': ['idle'],
                                                'goals': ['assemble']})
    assert answer.status_code == 202, answer.text
    job = answer.json()['id']
    with httpx.stream('GET', f'{url}api/jobs/{job}/events', timeout=30) as events:
        for line in events.iter_lines():
            if line.startswith('data:') and json.loads(line[5:])['status'].startswith('Synthesizing'):
                break
        yield job


# 200 unconstrained outputs: strategy extraction alone would run for hours.
RUNAWAY_SPEC = {'sys_props': [f'p{i}' for i in range(200)], 'env_props': ['e'], 'sys_liveness': ['p0']}


def runaway_goal(timeout=0.0):
    return make_goal('atlas', [], [], option='ltl_synthesis_only', ltl_specification=RUNAWAY_SPEC,
                     timeout=timeout)
