"""Benchmark of ltl_synthesizer on multi-goal ATLAS tasks (issue 14): time vs number of goals.

    python bench/bench_goals.py                  # 1..12 goals, ordered and unordered (+ PNG)
    python bench/bench_goals.py --max-goals 6    # shorter
    python bench/bench_goals.py --options        # each solver optimisation switched off in turn

Goals are taken in this order from stand_prep (the first ten are the issue's ordered task):
look_down, approach_object, pregrasp, grasp_object, pickup_object, footstep_execution,
object_template, pregrasp_pose, footstep_plan, target_pose, pregrasp_plan, footstep_goal.
"Ordered" is the paper's strict order (20), "unordered" (17).

Each measurement runs in a fresh process, so its peak RSS (ru_maxrss) is that synthesis's
alone. Times are CPU seconds of the synthesis with explicit strategy extraction
(time.process_time), because the machine's wall clock is shared with other work; slugs' column
(only when a ``slugs`` executable is on PATH) is its CPU time, from the same slugsin file, run as
``slugs --explicitStrategy --jsonOutput --sysInitRoboticsSemantics`` (the original stack's call).
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from respec.robot import robot_system

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / 'bench' / 'results'
sys.path.insert(0, str(ROOT))

GOALS = ['look_down', 'approach_object', 'pregrasp', 'grasp_object', 'pickup_object',
         'footstep_execution', 'object_template', 'pregrasp_pose', 'footstep_plan', 'target_pose',
         'pregrasp_plan', 'footstep_goal']
TIMEOUT_SECONDS = 300  # per synthesis, ours and slugs'
# Each optimisation of the solver, switched off (ltl_synthesizer.Options).
OPTIMISATIONS = {
    'all on (default)': {},
    'Jacobi Y sweeps (chained_sweeps off)': {'chained_sweeps': False},
    'all positions (reachable_only off)': {'reachable_only': False},
    'static variable order (sift_once off)': {'sift_once': False},
}


def task_spec(goals: int, ordered: bool):
    from ltl_specification import compile_task
    return compile_task(robot_system('atlas', ROOT / 'config'), ['stand_prep'], GOALS[:goals], strict_order=ordered)


def run_one(goals: int, ordered: bool, options: dict) -> dict:
    """One synthesis in this process (the child side of ``measure``)."""
    from ltl_synthesizer import Limits, Options, synthesize
    spec = task_spec(goals, ordered)
    started = time.process_time()
    result = synthesize(spec, limits=Limits(memory_limit=None), options=Options(**options))
    cpu = time.process_time() - started
    return {'goals': goals, 'ordered': ordered, 'realizable': result.realizable,
            'cpu_seconds': cpu, 'variables': result.stats['variables'],
            'strategy_nodes': len(result.strategy['nodes']) if result.strategy else 0,
            'peak_rss_mb': resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}


def measure(goals: int, ordered: bool, options: dict | None = None) -> dict:
    command = [sys.executable, __file__, '--child', json.dumps([goals, ordered, options or {}])]
    try:
        done = subprocess.run(command, capture_output=True, text=True, timeout=TIMEOUT_SECONDS, cwd=ROOT)
    except subprocess.TimeoutExpired:
        return {'goals': goals, 'ordered': ordered, 'timeout': True}
    if done.returncode != 0:
        raise RuntimeError(done.stderr)
    return json.loads(done.stdout.strip().splitlines()[-1])


def measure_slugs(goals: int, ordered: bool) -> float | None:
    """slugs' CPU seconds on the same task, or None when slugs is absent or times out."""
    slugs = shutil.which('slugs')
    if slugs is None:
        return None
    with tempfile.TemporaryDirectory() as directory:
        source = Path(directory) / 'task.slugsin'
        source.write_text(task_spec(goals, ordered).to_slugsin())
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        try:
            subprocess.run([slugs, '--explicitStrategy', '--jsonOutput', '--sysInitRoboticsSemantics',
                            str(source), str(Path(directory) / 'out.json')],
                           capture_output=True, timeout=TIMEOUT_SECONDS, check=True)
        except subprocess.TimeoutExpired:
            return float('inf')
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def bench_curve(max_goals: int) -> list[dict]:
    rows = []
    for ordered in (True, False):
        slugs_timed_out = False
        for goals in range(1, max_goals + 1):
            row = measure(goals, ordered)
            # Once slugs needs more than the time limit, larger tasks are not tried on it.
            row['slugs_cpu_seconds'] = float('inf') if slugs_timed_out else measure_slugs(goals, ordered)
            slugs_timed_out = row['slugs_cpu_seconds'] == float('inf')
            rows.append(row)
            print(_row_text(row), flush=True)
    return rows


def _row_text(row: dict) -> str:
    kind = 'ordered' if row['ordered'] else 'unordered'
    if row.get('timeout'):
        return f"{kind:9s} goals={row['goals']:2d}  > {TIMEOUT_SECONDS} s"
    slugs = row.get('slugs_cpu_seconds')
    slugs_text = '' if slugs is None else (f'  slugs > {TIMEOUT_SECONDS} s' if slugs == float('inf')
                                           else f'  slugs={slugs:.2f} s')
    return (f"{kind:9s} goals={row['goals']:2d} vars={row['variables']:3d} "
            f"nodes={row['strategy_nodes']:3d} cpu={row['cpu_seconds']:7.3f} s "
            f"peak RSS={row['peak_rss_mb']:6.1f} MB" + slugs_text)


def write_curve(rows: list[dict]) -> None:
    RESULTS.mkdir(parents=True, exist_ok=True)
    with_slugs = any(row.get('slugs_cpu_seconds') is not None for row in rows)
    lines = ['# ltl_synthesizer: ATLAS tasks from stand_prep vs number of goals', '',
             f'Machine: {os.cpu_count()} cores (shared with other work), Python {sys.version.split()[0]}. '
             'CPU seconds (time.process_time) of synthesis + explicit strategy; peak RSS of a fresh '
             'process per row.', '',
             '| goals | order | variables | strategy nodes | CPU (s) | peak RSS (MB) |'
             + (' slugs CPU (s) |' if with_slugs else ''),
             '|---|---|---|---|---|---|' + ('---|' if with_slugs else '')]
    for row in rows:
        kind = 'ordered' if row['ordered'] else 'unordered'
        if row.get('timeout'):
            lines.append(f"| {row['goals']} | {kind} | | | > {TIMEOUT_SECONDS} | |" + (' |' if with_slugs else ''))
            continue
        slugs = row.get('slugs_cpu_seconds')
        slugs_cell = '' if slugs is None else ('> %d' % TIMEOUT_SECONDS if slugs == float('inf') else f'{slugs:.2f}')
        lines.append(f"| {row['goals']} | {kind} | {row['variables']} | {row['strategy_nodes']} | "
                     f"{row['cpu_seconds']:.3f} | {row['peak_rss_mb']:.0f} |"
                     + (f' {slugs_cell} |' if with_slugs else ''))
    (RESULTS / 'synthesizer_goals.md').write_text('\n'.join(lines) + '\n')
    (RESULTS / 'synthesizer_goals.json').write_text(json.dumps(rows, indent=1, sort_keys=True) + '\n')
    plot_curve(rows)
    print('\n'.join(lines))


def plot_curve(rows: list[dict]) -> None:
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    figure, (left, right) = plt.subplots(1, 2, figsize=(10, 4))
    for ordered, style in ((True, 'o-'), (False, 's-')):
        done = [r for r in rows if r['ordered'] == ordered and not r.get('timeout')]
        label = 'ordered' if ordered else 'unordered'
        left.plot([r['goals'] for r in done], [r['cpu_seconds'] for r in done], style, label=f'ours, {label}')
        right.plot([r['goals'] for r in done], [r['peak_rss_mb'] for r in done], style, label=label)
        slugs = [r for r in done if r.get('slugs_cpu_seconds') not in (None, float('inf'))]
        if slugs:
            left.plot([r['goals'] for r in slugs], [r['slugs_cpu_seconds'] for r in slugs], style[0] + '--',
                      label=f'slugs, {label}')
    left.set_xlabel('goals (from stand_prep)')
    left.set_ylabel('CPU seconds, synthesis + strategy')
    left.set_yscale('log')
    left.legend()
    left.grid(True, alpha=0.3)
    right.set_xlabel('goals (from stand_prep)')
    right.set_ylabel('peak RSS (MB)')
    right.legend()
    right.grid(True, alpha=0.3)
    figure.suptitle('GR(1) synthesis of multi-goal ATLAS tasks')
    figure.tight_layout()
    figure.savefig(RESULTS / 'synthesizer_goals.png', dpi=120)


def compare_options(goal_counts=(4, 6, 8, 10)) -> None:
    """Each optimisation switched off in turn, on ordered tasks; table to results/."""
    lines = ['# ltl_synthesizer: solver optimisations switched off one at a time (ordered ATLAS tasks)', '',
             f'CPU seconds of synthesis + strategy (fresh process each; "> {TIMEOUT_SECONDS}" = timed out).', '',
             '| solver | ' + ' | '.join(f'{n} goals' for n in goal_counts) + ' |',
             '|---|' + '---|' * len(goal_counts)]
    for label, options in OPTIMISATIONS.items():
        cells = []
        for goals in goal_counts:
            row = measure(goals, True, options)
            cells.append(f'> {TIMEOUT_SECONDS}' if row.get('timeout') else f"{row['cpu_seconds']:.2f}")
            print(label, goals, cells[-1], flush=True)
            if row.get('timeout'):
                cells += [''] * (len(goal_counts) - len(cells))
                break
        lines.append(f'| {label} | ' + ' | '.join(cells) + ' |')
    RESULTS.mkdir(parents=True, exist_ok=True)
    (RESULTS / 'synthesizer_goal_options.md').write_text('\n'.join(lines) + '\n')
    print('\n'.join(lines))


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--child', help=argparse.SUPPRESS)
    parser.add_argument('--max-goals', type=int, default=len(GOALS))
    parser.add_argument('--options', action='store_true')
    args = parser.parse_args(argv)
    if args.child:
        goals, ordered, options = json.loads(args.child)
        print(json.dumps(run_one(goals, ordered, options)))
        return 0
    if args.options:
        compare_options()
        return 0
    write_curve(bench_curve(args.max_goals))
    return 0


if __name__ == '__main__':
    sys.exit(main())
