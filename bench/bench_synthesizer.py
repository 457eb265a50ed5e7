"""Benchmark of ltl_synthesizer: paper-size ATLAS tasks and the chain scaling family.

    python bench/bench_synthesizer.py                 # paper tasks + chain N=4..256, stopping
                                                      # at the first N over 5 minutes (+ plot)
    python bench/bench_synthesizer.py --max-n 12      # shorter
    python bench/bench_synthesizer.py --compare       # option comparison (reordering, partitioning,
                                                      # sifting and reachability on small games)

Chain family: ATLAS's 5 control modes plus actions act0..act{N-1}, act_i needing control mode
[stand, manipulate][i % 2] and act_{i-1}; outcomes completed/failed; SM outcomes
finished/failed; start in stand_prep; goal act{N-1}. Specifications come from
ltl_specification.compile_task with a generated <system>.yaml (which keeps only the pertinent
control modes: stand_prep, stand, manipulate). Each measurement runs in a fresh
subprocess so peak RSS (ru_maxrss) belongs to that run alone; times are wall-clock in-process
(synthesis + strategy extraction) and for the whole process (start-up included, as slugs').
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from respec.robot import robot_system

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / 'bench' / 'results'
sys.path.insert(0, str(ROOT))

ATLAS_MODES = {'stand_prep': ['stand'], 'stand': ['manipulate', 'step', 'walk'],
               'manipulate': ['stand'], 'step': ['stand'], 'walk': ['stand']}
# slugs wall times (incl. start-up) on a 2-core Debian machine, from the project brief.
SLUGS_SECONDS = {8: 6.7, 12: 13.0, 16: 26.0, 24: 84.0, 32: 279.0}
PAPER_TASKS = [
    ('look_down', ['stand_prep'], ['look_down']),
    ('look_down, pickup_object', ['stand_prep'], ['look_down', 'pickup_object']),
    ('pickup_object', ['stand_prep'], ['pickup_object']),
    ('grasp_object', ['stand'], ['grasp_object']),
    ('pregrasp, grasp_object', ['stand_prep'], ['pregrasp', 'grasp_object']),
    ('approach_object', ['stand_prep'], ['approach_object']),
    ('footstep_execution', ['stand_prep'], ['footstep_execution']),
]


def chain_config(n: int, directory: Path) -> str:
    """Write <system>.yaml for the chain family of size n; return the system name."""
    import yaml
    actions = {}
    for i in range(n):
        mode = ['stand', 'manipulate'][i % 2]
        actions[f'act{i}'] = [mode] if i == 0 else [f'act{i - 1}', mode]
    system = f'chain{n}'
    config = {'system': system, 'abstraction': {
        'outcomes': ['completed', 'failed'], 'initial_mode': 'stand_prep',
        'control_modes': ATLAS_MODES, 'actions': actions}}
    (directory / f'{system}.yaml').write_text(yaml.safe_dump(config, sort_keys=False))
    return system


def chain_spec(n: int):
    from ltl_specification import compile_task
    with tempfile.TemporaryDirectory() as directory:
        system = chain_config(n, Path(directory))
        return compile_task(robot_system(system, directory), ['stand_prep'], [f'act{n - 1}'])


def paper_spec(initial, goals):
    from ltl_specification import compile_task
    return compile_task(robot_system('atlas', ROOT / 'config'), initial, goals)


def run_one(kind: str, argument: str, options: dict) -> dict:
    """Measure one synthesis in this process (called in a child process)."""
    from ltl_synthesizer import Options, synthesize
    if kind == 'chain':
        spec = chain_spec(int(argument))
    else:
        initial, goals = json.loads(argument)
        spec = paper_spec(initial, goals)
    compiled, compiled_cpu = time.perf_counter(), time.process_time()
    result = synthesize(spec, options=Options(**options))
    done, done_cpu = time.perf_counter(), time.process_time()
    return {'realizable': result.realizable, 'seconds': done - compiled,
            'cpu_seconds': done_cpu - compiled_cpu,
            'process_seconds': _seconds_since_spawn(),
            'nodes': len(result.strategy['nodes']) if result.strategy else 0,
            'variables': result.stats['variables'], 'peak_bdd_nodes': result.stats['peak_bdd_nodes'],
            'peak_rss_mb': resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}


def _seconds_since_spawn() -> float:
    """Wall time since the parent started this process (interpreter start-up included)."""
    return time.time() - float(os.environ['BENCH_SPAWNED_AT'])


def measure(kind: str, argument: str, options: dict | None = None, timeout: float = 300) -> dict:
    env = dict(os.environ, BENCH_SPAWNED_AT=repr(time.time()))
    command = [sys.executable, __file__, '--child', kind, argument, json.dumps(options or {})]
    try:
        done = subprocess.run(command, capture_output=True, text=True, timeout=timeout, env=env,
                              cwd=ROOT)
    except subprocess.TimeoutExpired:
        return {'timeout': True}
    if done.returncode != 0:
        raise RuntimeError(done.stderr)
    return json.loads(done.stdout.strip().splitlines()[-1])


def bench_paper(repeats: int = 5) -> list[dict]:
    rows = []
    for label, initial, goals in PAPER_TASKS:
        runs = [measure('paper', json.dumps([initial, goals])) for _ in range(repeats)]
        best = min(runs, key=lambda r: r['seconds'])
        rows.append({'task': f'from {", ".join(initial)}: {label}', **best})
        print(f"{rows[-1]['task']:55s} vars={best['variables']:3d} nodes={best['nodes']:4d} "
              f"in-process={best['seconds'] * 1000:7.1f} ms  process={best['process_seconds']:.2f} s "
              f"realizable={best['realizable']}", flush=True)
    return rows


def bench_chain(sizes, options=None, timeout=300) -> list[dict]:
    rows = []
    for n in sizes:
        row = {'n': n, **measure('chain', str(n), options, timeout)}
        rows.append(row)
        if row.get('timeout'):
            print(f'N={n:3d}  timeout (> {timeout} s)', flush=True)
            break
        print(f"N={n:3d} vars={row['variables']:4d} nodes={row['nodes']:6d} "
              f"time={row['seconds']:8.2f} s  process={row['process_seconds']:8.2f} s  "
              f"peak RSS={row['peak_rss_mb']:7.1f} MB  slugs={SLUGS_SECONDS.get(n, '-')}", flush=True)
    return rows


def write_report(paper_rows, chain_rows) -> None:
    RESULTS.mkdir(parents=True, exist_ok=True)
    lines = ['# ltl_synthesizer benchmark', '',
             f'Machine: {os.cpu_count()} cores, Python {sys.version.split()[0]}.', '',
             '## Paper-size ATLAS tasks (best of 5; synthesis + strategy extraction, in-process)', '',
             '| task | variables | strategy nodes | in-process (ms) | whole process (s) |',
             '|---|---|---|---|---|']
    for row in paper_rows:
        lines.append(f"| {row['task']} | {row['variables']} | {row['nodes']} | "
                     f"{row['seconds'] * 1000:.1f} | {row['process_seconds']:.2f} |")
    lines += ['', '## Chain family (goal act{N-1}; time includes strategy extraction)', '',
              '| N | variables | strategy nodes | time (s) | process (s) | peak RSS (MB) | slugs (s) |',
              '|---|---|---|---|---|---|---|']
    for row in chain_rows:
        if row.get('timeout'):
            lines.append(f"| {row['n']} | | | > 300 | | | {SLUGS_SECONDS.get(row['n'], '')} |")
            continue
        lines.append(f"| {row['n']} | {row['variables']} | {row['nodes']} | {row['seconds']:.2f} | "
                     f"{row['process_seconds']:.2f} | {row['peak_rss_mb']:.0f} | "
                     f"{SLUGS_SECONDS.get(row['n'], '')} |")
    (RESULTS / 'synthesizer_scaling.md').write_text('\n'.join(lines) + '\n')
    (RESULTS / 'synthesizer_scaling.json').write_text(json.dumps(
        {'paper': paper_rows, 'chain': chain_rows}, indent=1, sort_keys=True) + '\n')
    plot(chain_rows)
    print('\n'.join(lines))


def plot(chain_rows) -> None:
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    done = [r for r in chain_rows if not r.get('timeout')]
    figure, (left, right) = plt.subplots(1, 2, figsize=(10, 4))
    left.plot([r['n'] for r in done], [r['process_seconds'] for r in done], 'o-', label='gr1synth (ours)')
    left.plot(list(SLUGS_SECONDS), list(SLUGS_SECONDS.values()), 's--', label='slugs (reported)')
    left.set_xlabel('N (actions in the chain)')
    left.set_ylabel('wall time incl. start-up (s)')
    left.set_yscale('log')
    left.legend()
    left.grid(True, alpha=0.3)
    right.plot([r['n'] for r in done], [r['peak_rss_mb'] for r in done], 'o-')
    right.set_xlabel('N (actions in the chain)')
    right.set_ylabel('peak RSS (MB)')
    right.grid(True, alpha=0.3)
    figure.suptitle('GR(1) synthesis + explicit strategy, ATLAS chain family')
    figure.tight_layout()
    figure.savefig(RESULTS / 'synthesizer_scaling.png', dpi=120)


COMPARISONS = {
    'default (affinity order, clusters 1000, no reordering)': {},
    'declared variable order': {'variable_order': 'declared'},
    'no clustering (one BDD per conjunct)': {'cluster_limit': 0},
    'monolithic transition relations': {'cluster_limit': 10**9},
    'dynamic reordering on': {'reordering': True},
}


def compare(sizes) -> None:
    """Each engine option against the default on the chain family; table to results/."""
    lines = ['# ltl_synthesizer: engine options compared on the chain family', '',
             'Synthesis + strategy extraction, in-process seconds (each run in a fresh process; '
             '"> 120" = timed out).', '',
             '| option | ' + ' | '.join(f'N={n}' for n in sizes) + ' |',
             '|---|' + '---|' * len(sizes)]
    for label, options in COMPARISONS.items():
        print(f'--- {label}', flush=True)
        rows = bench_chain(sizes, options, timeout=120)
        cells = [('> 120' if row.get('timeout') else f"{row['seconds']:.2f}") for row in rows]
        cells += [''] * (len(sizes) - len(cells))
        lines.append(f'| {label} | ' + ' | '.join(cells) + ' |')
    RESULTS.mkdir(parents=True, exist_ok=True)
    (RESULTS / 'synthesizer_options.md').write_text('\n'.join(lines) + '\n')
    print('\n'.join(lines))


SMALL_GAME_SWITCHES = {
    'automatic (default)': {},
    'sifting + reachability on': {'sift_once': True, 'reachable_only': True},
    'sifting + reachability off': {'sift_once': False, 'reachable_only': False},
}
MULTI_GOAL_TASKS = ['look_down', 'approach_object', 'pregrasp', 'grasp_object', 'pickup_object']


def compare_small_games(repeats: int = 3) -> None:
    """The sifting pass and the reachability search, forced on or off, around the size where
    the automatic choice switches them on (ltl_synthesizer.symbolic.SMALL_GAME_PROPOSITIONS)."""
    cases = [(label, 'paper', json.dumps([initial, goals])) for label, initial, goals in PAPER_TASKS]
    cases += [(f'{n} goals from stand_prep', 'paper', json.dumps([['stand_prep'], MULTI_GOAL_TASKS[:n]]))
              for n in (3, 4, 5)]
    cases += [(f'chain N={n}', 'chain', str(n)) for n in (8, 12)]
    lines = ['# ltl_synthesizer: sifting and reachability on small games', '',
             f'Synthesis + strategy extraction, in-process ms, best of {repeats} fresh processes.', '',
             '| task | variables | ' + ' | '.join(SMALL_GAME_SWITCHES) + ' |',
             '|---|---|' + '---|' * len(SMALL_GAME_SWITCHES)]
    for label, kind, argument in cases:
        cells, variables = [], 0
        for options in SMALL_GAME_SWITCHES.values():
            runs = [measure(kind, argument, options) for _ in range(repeats)]
            variables = runs[0]['variables']
            cells.append(f"{min(r['seconds'] for r in runs) * 1000:.1f}")
        lines.append(f'| {label} | {variables} | ' + ' | '.join(cells) + ' |')
        print(lines[-1], flush=True)
    RESULTS.mkdir(parents=True, exist_ok=True)
    (RESULTS / 'synthesizer_small_games.md').write_text('\n'.join(lines) + '\n')
    print('\n'.join(lines))


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--child', nargs=3, help=argparse.SUPPRESS)
    parser.add_argument('--max-n', type=int, default=256)
    parser.add_argument('--compare', action='store_true')
    args = parser.parse_args(argv)
    if args.child:
        kind, argument, options = args.child
        print(json.dumps(run_one(kind, argument, json.loads(options))))
        return 0
    sizes = [n for n in (4, 8, 12, 16, 20, 24, 28, 32, 40, 48, 56, 64, 80, 96, 128, 160, 192, 256)
             if n <= args.max_n]
    if args.compare:
        compare([n for n in sizes if n <= 16])
        compare_small_games()
        return 0
    paper_rows = bench_paper()
    chain_rows = bench_chain(sizes)
    write_report(paper_rows, chain_rows)
    return 0


if __name__ == '__main__':
    sys.exit(main())
