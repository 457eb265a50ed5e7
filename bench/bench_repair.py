"""Verified repairs of unrealizable tasks: how many get a fix, how soon, how many fixes.

    FLEXBE_SOURCES=../shared/third_party python bench/bench_repair.py [--markdown FILE] [--budget S]

The tasks (at least 30, all refused as asked):
* ATLAS variants: two-goal tasks from every control mode that cannot be done in the given order
  (every such pair from a deterministic enumeration, thinned to a fixed stride);
* ATLAS tasks with custom LTL that makes them impossible (a forbidden activation, a liveness on a
  sensor the environment controls, a memory of a goal not asked for, contradictions);
* custom-LTL games in the style of slugs' unrealizable examples (inputs the system cannot
  control, a guarantee that cannot recur), on a one-goal ATLAS task;
* CNU's capability examples (their files, pinned in ``FLEXBE_SOURCES``) and our delivery rover
  asked for a goal no capability sets, from a start where a precondition can never hold, or for
  goals that exclude each other.

For each: whether a verified proposal was found, the time to the first one (from the start of
the search, the original's own synthesis and diagnosis included), the number of proposals
within the budget, and the first proposal's kind.
"""

from __future__ import annotations

import argparse
import itertools
import os
import statistics
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / 'bench'))

from bench_cnu_capabilities import write_cnu_systems
from ltl_specification.repair import TaskRequest, attempt, propose_repairs
from respec.robot import robot_system
from respec.robot.state_library import workspace_state_library

ATLAS_STRIDE = 3
ATLAS_COUNT = 16
CUSTOM_ATLAS = [
    ('forbidden activation', ['stand_prep'], ['look_down'], {'sys_trans': ['stand_c -> !look_down_a']}),
    ('never activate stand', ['stand_prep'], ['look_down'], {'sys_trans': ['!stand_a']}),
    ('sensor liveness', ['stand_prep'], ['look_down'], {'sys_liveness': ['obj_detected']}),
    ('memory of a goal not asked', ['stand_prep'], ['look_down'], {'sys_trans': ['look_down_a -> stand_m']}),
    ('contradictory guarantees', ['stand_prep'], ['look_down'], {'sys_trans': ['look_down_a', '!look_down_a']}),
    ('pickup needs a sensor', ['stand_prep'], ['pickup_object'],
     {'sys_trans': ['pickup_object_a -> obj_detected'], 'env_trans': ['!obj_detected -> next(!obj_detected)']}),
]
SLUGS_STYLE = [
    ('input must recur', {'env_props': ['x'], 'sys_liveness': ['x']}),
    ('input must stay off', {'env_props': ['x'], 'sys_liveness': ['!x']}),
    ('one of two inputs', {'env_props': ['x', 'z'], 'sys_liveness': ['x | z']}),
    ('predict the input', {'env_props': ['x'], 'sys_props': ['y'], 'sys_trans': ['next(y) <-> x'],
                           'sys_liveness': ['y & !x']}),
    ('guarantee cannot recur', {'sys_props': ['y'], 'sys_init': ['y'], 'sys_trans': ['next(!y)'],
                                'sys_liveness': ['y']}),
    ('follow the input', {'env_props': ['x'], 'sys_props': ['y'], 'sys_trans': ['next(y) <-> !next(x)'],
                          'sys_liveness': ['y & x']}),
]
# (system, initial conditions, goals): a goal no capability sets, a precondition nothing
# establishes from the given start, goals that exclude each other.
CNU_TASKS = [
    ('coffee_maker', ('bd_a',), ('br',)),
    ('coffee_maker', ('bd_a',), ('bd',)),
    ('coffee_maker_extended', ('bd_a',), ('br',)),
    ('vending_demo', ('prep_pay_a',), ('soda', '!soda')),
    ('vending_demo_extended', ('prep_pay_a',), ('snack', '!snack')),
    ('hello_world', ('say_hello',), ('say_world',)),
    ('hello_world', (), ('say_world', '!say_hello')),
    ('delivery_rover', ('drive',), ('charge',)),
    ('delivery_rover', (), ('check_battery',)),
]


def atlas_variants() -> list[tuple[str, TaskRequest, dict | None]]:
    """Two-goal ATLAS tasks that cannot be done in the given order, every ``ATLAS_STRIDE``-th."""
    system = robot_system('atlas')
    abstraction = system.abstraction
    refused = []
    for initial in abstraction.control_modes:
        for goals in itertools.permutations(abstraction.items(), 2):
            request = TaskRequest('atlas', (initial,), goals)
            if not attempt(system, request, None).realizable:
                refused.append((f'atlas from {initial}: {", ".join(goals)}', request, None))
    return refused[::ATLAS_STRIDE][:ATLAS_COUNT]


def cnu_variants() -> list[tuple[str, TaskRequest, dict | None]]:
    """CNU's examples asked for what their files cannot give as they are."""
    return [(f'CNU {system}: {",".join(initial) or "-"} -> {",".join(goals)}', TaskRequest(system, initial, goals), None)
            for system, initial, goals in CNU_TASKS]


def run(tasks, config_dir: Path, library, budget: float) -> list[dict]:
    rows = []
    for label, request, custom in tasks:
        repairs = propose_repairs(robot_system(request.system, config_dir), request, custom, time_budget=budget,
                                  state_library=library)
        if repairs.realizable:
            raise SystemExit(f'{label}: the task is realizable, not a repair case')
        rows.append({'task': label, 'problem': repairs.problem.split(':', 1)[0],
                     'repaired': bool(repairs.proposals), 'first': repairs.first_proposal_seconds,
                     'proposals': len(repairs.proposals), 'tried': repairs.tried, 'seconds': repairs.seconds,
                     'first_kind': repairs.proposals[0].kind if repairs.proposals else '-'})
        print(f'{label:60s} {rows[-1]["problem"]:22s} proposals {len(repairs.proposals)} '
              f'first {rows[-1]["first"] if rows[-1]["first"] is None else round(rows[-1]["first"], 3)} s',
              flush=True)
    return rows


def table(rows: list[dict]) -> str:
    lines = ['| task | refused with | repaired | first proposal (s) | proposals | tried | first kind |',
             '|---|---|---|---|---|---|---|']
    for row in rows:
        first = '-' if row['first'] is None else f'{row["first"]:.3f}'
        lines.append(f'| {row["task"]} | {row["problem"]} | {"yes" if row["repaired"] else "no"} | {first} | '
                     f'{row["proposals"]} | {row["tried"]} | {row["first_kind"]} |')
    return '\n'.join(lines)


def summary(rows: list[dict]) -> str:
    repaired = [r for r in rows if r['repaired']]
    firsts = [r['first'] for r in repaired]
    return (f'{len(repaired)} of {len(rows)} tasks repaired ({100 * len(repaired) / len(rows):.0f} %); '
            f'first proposal median {statistics.median(firsts):.3f} s, max {max(firsts):.3f} s; '
            f'proposals per repaired task median {statistics.median(r["proposals"] for r in repaired):g}.')


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--markdown', help='also write the results to this file')
    parser.add_argument('--budget', type=float, default=10.0, help='time budget of each search (s)')
    args = parser.parse_args()
    sources = Path(os.environ.get('FLEXBE_SOURCES', ROOT.parent / 'shared' / 'third_party'))
    library = workspace_state_library(os.environ.get('AMENT_PREFIX_PATH') or str(Path(sys.prefix) / 'flexbe'))
    with tempfile.TemporaryDirectory() as directory:
        config_dir = Path(directory)
        write_cnu_systems(config_dir, sources / 'flexbe_synthesis')
        tasks = atlas_variants()
        tasks += [(f'atlas + custom LTL: {label}', TaskRequest('atlas', tuple(i), tuple(g)), custom)
                  for label, i, g, custom in CUSTOM_ATLAS]
        tasks += [(f'custom LTL game: {label}', TaskRequest('atlas', ('stand_prep',), ('look_down',)), custom)
                  for label, custom in SLUGS_STYLE]
        tasks += cnu_variants()
        rows = run(tasks, config_dir, library, args.budget)
    text = table(rows)
    print(text)
    print(summary(rows))
    if args.markdown:
        Path(args.markdown).write_text(
            '# Verified repairs of unrealizable tasks\n\n'
            f'Written by `bench/bench_repair.py` (time budget {args.budget:g} s and at most 5 proposals per '
            'task; every proposal compiled and synthesized, and found realizable, before it counts; '
            'times are wall-clock on the 2-core machine, shared with other work while it ran).\n\n'
            f'**{summary(rows)}**\n\n' + text + '\n')


if __name__ == '__main__':
    main()
