"""Capability robots of realistic size and the per-cell gridworld (issue 44): our whole pipeline,
our synthesizer alone and slugs, side by side in one run, with the fitted growth exponents.

    python bench/bench_capability_scale.py --slugs /tmp/slugs/src/slugs [--timeout 60]
        [--slugs-timeout 300] [--shapes chain,retry] [--sizes 10,20,40] [--grids 7x5,19x16]
        [--warm-up-to 80] [--markdown FILE]

For every capability robot (bench/capability_robots.py: N capabilities bound to FlexBE's
OperatorDecisionState, a request with no initial conditions, the goal, outcomes finished,failed)
and size N, each in a fresh process, wall seconds:

- "pipeline": what export-behavior / the synthesis node does for the request, in one process:
  compile the task, synthesize (robotics semantics, explicit strategy), the well-separation
  check (on the solved game, as the node's synthesis child does it), the automaton, the FlexBE
  machine (stage seconds in the notes);
- "gr1synth": ``python -m ltl_synthesizer --sysInitRoboticsSemantics`` on the compiled slugsin
  (realizability only, as slugs' default);
- "gr1synth + strategy": the same with ``--explicitStrategy --jsonOutput`` (the synthesis the
  pipeline needs: the verdict and the explicit strategy, written out);
- "slugs": slugs with the same flag on the same file (realizability only);
- "ratio": pipeline / (gr1synth + strategy), the pipeline's cost over the synthesis it needs;
  "CPU ratio" the same in CPU seconds (user + system of each process), which other jobs on the
  machine do not stretch as they stretch wall seconds;
- "warm": the same request answered again in one process (imports done, as in a long-running
  server; robots up to ``--warm-up-to``, default 80): the pipeline three times in one child,
  gr1synth + strategy three times by its resident mode (``gr1synth --serve``'s answer); wall
  seconds of the faster of the second and third answers, timed in the process, and their ratio;
- "check": ``strategy_check.check_strategy`` (an independent check that shares no code with
  the synthesizer) on the pipeline's explicit strategy, in its own process after the run.

The per-cell gridworld rows (capability_robots.per_cell_gridworld) have no pipeline (no robot):
gr1synth and slugs only. Verdicts are compared on every row both tools finish. A tool that
runs into the time cap is not run on the shape's larger sizes. The growth exponent is the
least-squares slope of log(seconds) over log(N) on the rows with N >= 20 that finished.
Timings are wall seconds on a shared 2-core machine: noisy.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import resource
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT), str(ROOT / 'bench')]

import capability_robots
from pipeline_child import pipeline_child, warm_synthesis_script

RESULTS = ROOT / 'bench' / 'results' / 'capability_scale.md'
SIZES = [10, 20, 40, 80, 160]
GRIDS = [(7, 5), (13, 10), (19, 16), (21, 18)]
PIPELINE_CHILD = str(ROOT / 'bench' / 'pipeline_child.py')


def run_wall(command: list[str], timeout: float) -> dict:
    """Run ``command`` in its own session; wall and CPU seconds, exit status, stdout, timeout."""
    used_before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.monotonic()
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, cwd=ROOT,
                               start_new_session=True, text=True)
    try:
        out, err = process.communicate(timeout=timeout)
        timed_out = False
    except subprocess.TimeoutExpired:
        os.killpg(process.pid, signal.SIGKILL)
        out, err = process.communicate()
        timed_out = True
    seconds = time.monotonic() - start
    used = resource.getrusage(resource.RUSAGE_CHILDREN)  # the process is reaped: its CPU is counted
    cpu = used.ru_utime - used_before.ru_utime + used.ru_stime - used_before.ru_stime
    return {'seconds': seconds, 'cpu': cpu, 'timeout': timed_out, 'code': process.returncode,
            'out': out, 'err': err, 'limit': timeout}


def verdict_of(text: str) -> bool | None:
    if 'RESULT: Specification is realizable.' in text:
        return True
    if 'RESULT: Specification is unrealizable.' in text:
        return False
    return None




def warm_runs(directory: Path, shape: str, size: int, slugsin: Path, timeout: float) -> dict:
    """A request's seconds in a process that has answered it once already (its imports done, as
    in a long-running server), the faster of two such answers: the pipeline (``pipeline_child.py``
    three times in one process), and gr1synth + strategy in its resident mode (``gr1synth
    --serve``'s answers to a request repeated three times)."""
    runs = {}
    pipeline = run_wall([sys.executable, PIPELINE_CHILD, str(directory), shape, str(size),
                         str(slugsin) + '.warm', '3'], timeout)
    synthesis = run_wall([sys.executable, '-c', warm_synthesis_script('perf_counter'), '--sysInitRoboticsSemantics', '--explicitStrategy',
                          '--jsonOutput', str(slugsin), os.devnull], timeout)
    for name, run in (('pipeline', pipeline), ('gr1synth + strategy', synthesis)):
        if not run['timeout'] and run['code'] == 0:
            runs[name] = json.loads(run['out'].strip().splitlines()[-1])['warm_seconds']
    for leftover in (Path(str(slugsin) + '.warm'), Path(str(slugsin) + '.warm.strategy.json')):
        leftover.unlink(missing_ok=True)
    return runs


def fitted_exponent(points: list[tuple[int, float]]) -> float | None:
    """Least-squares slope of log(seconds) over log(N), on N >= 20."""
    points = [(n, s) for n, s in points if n >= 20 and s > 0]
    if len(points) < 2:
        return None
    xs = [math.log(n) for n, _ in points]
    ys = [math.log(s) for _, s in points]
    mean_x, mean_y = sum(xs) / len(xs), sum(ys) / len(ys)
    denominator = sum((x - mean_x) ** 2 for x in xs)
    return sum((x - mean_x) * (y - mean_y) for x, y in zip(xs, ys)) / denominator if denominator else None


def cell(result: dict | None, timeout: float) -> str:
    if result is None:
        return 'skipped'
    if result['timeout']:
        return f"> {result.get('limit', timeout):g}"
    if result.get('failed'):
        return f"failed ({result['failed']})"
    return f"{result['seconds']:.2f}"


def measure_capabilities(args, directory: Path, rows: list, series: dict) -> None:
    python = sys.executable
    for shape in args.shapes:
        given_up = set()
        for size in args.sizes:
            robot = capability_robots.SHAPES[shape](size)
            robot.write(directory)
            slugsin = directory / f'{robot.name}.slugsin'
            row = {'family': shape, 'size': size, 'label': f'{shape} N={size}'}
            results = {}
            if 'pipeline' not in given_up:
                run = run_wall([python, PIPELINE_CHILD, str(directory), shape, str(size),
                                str(slugsin)], args.timeout)
                if not run['timeout'] and run['code'] == 0:
                    report = json.loads(run['out'].strip().splitlines()[-1])
                    run.update(report)
                    row['verdict'] = report['realizable']
                    row['props'] = f"{report['env']} / {report['sys']}"
                    row['stages'] = report['stages']
                elif not run['timeout']:
                    run['failed'] = (run['err'].strip().splitlines() or ['?'])[-1][:80]
                results['pipeline'] = run
            if not slugsin.exists():  # the pipeline did not get as far as compiling: compile here
                subprocess.run([python, '-c', _COMPILE_ONLY, str(directory), shape, str(size), str(slugsin)],
                               cwd=ROOT, check=True)
            results.update(solved_by_both(slugsin, args, given_up))
            pipeline = results.get('pipeline')
            if pipeline and not pipeline['timeout'] and not pipeline.get('failed') and size <= args.warm_up_to:
                row['warm'] = warm_runs(directory, shape, size, slugsin, args.timeout)
            strategy = Path(str(slugsin) + '.strategy.json')
            if strategy.exists() and 'check' not in given_up and size <= args.check_up_to:
                results['check'] = checked(slugsin, strategy, args.timeout)
            strategy.unlink(missing_ok=True)
            _finish_row(row, results, given_up, series)
            rows.append(row)
            print(_row_line(row, args.timeout), flush=True)


_COMPILE_ONLY = '''
import sys
sys.path[:0] = ['.', 'bench']
from pathlib import Path
import capability_robots
directory, shape, size, out = sys.argv[1], sys.argv[2], int(sys.argv[3]), sys.argv[4]
open(out, 'w').write(capability_robots.compiled_spec(shape, size, Path(directory)).to_slugsin())
'''


_CHECK = '''
import json, sys
sys.path[:0] = ['.', 'bench']
from respec.parsing import parse_slugsin
from strategy_check import check_strategy
spec = parse_slugsin(open(sys.argv[1]).read())
print(json.dumps(check_strategy(spec, json.loads(open(sys.argv[2]).read()))))
'''


def checked(slugsin: Path, strategy: Path, timeout: float) -> dict:
    """The independent check of the pipeline's explicit strategy: its problems (none: passed)."""
    run = run_wall([sys.executable, '-c', _CHECK, str(slugsin), str(strategy)], timeout)
    if not run['timeout']:
        if run['code'] == 0:
            run['problems'] = json.loads(run['out'].strip().splitlines()[-1])
        else:
            run['failed'] = (run['err'].strip().splitlines() or ['?'])[-1][:80]
    return run


def solved_by_both(slugsin: Path, args, given_up: set, with_strategy: bool = True) -> dict:
    """gr1synth's (with the explicit strategy too, if ``with_strategy``) and slugs' runs on
    ``slugsin`` (those not given up on), each with its verdict or, when it gave none, its last
    line of errors."""
    results = {}
    if not with_strategy:
        given_up = given_up | {'gr1synth + strategy'}
    for tool, command in (('gr1synth', [sys.executable, '-m', 'ltl_synthesizer', '--sysInitRoboticsSemantics',
                                        str(slugsin)]),
                          ('gr1synth + strategy', [sys.executable, '-m', 'ltl_synthesizer',
                                                   '--sysInitRoboticsSemantics', '--explicitStrategy',
                                                   '--jsonOutput', str(slugsin), os.devnull]),
                          ('slugs', [args.slugs, '--sysInitRoboticsSemantics', str(slugsin)])):
        if tool in given_up:
            continue
        run = run_wall(command, args.slugs_timeout if tool == 'slugs' else args.timeout)
        if not run['timeout']:
            run['verdict'] = verdict_of(run['out'] + run['err'])
            if run['verdict'] is None:
                run['failed'] = (run['err'].strip().splitlines() or ['no verdict'])[-1][:80]
        results[tool] = run
    return results


def measure_gridworlds(args, directory: Path, rows: list, series: dict) -> None:
    for realizable in (True, False):
        family = 'gridworld' if realizable else 'gridworld_unrealizable'
        given_up = set()
        for width, height in args.grids:
            text = capability_robots.per_cell_gridworld(width, height, 8, realizable)
            slugsin = directory / f'{family}_{width}x{height}.slugsin'
            slugsin.write_text(text)
            row = {'family': family, 'size': width * height, 'label': f'{family} {width}x{height}',
                   'props': f'{math.ceil(math.log2(width * height))} + {math.ceil(math.log2(width * height))} bits',
                   'kb': len(text) // 1024}
            results = solved_by_both(slugsin, args, given_up, with_strategy=False)
            _finish_row(row, results, given_up, series)
            rows.append(row)
            print(_row_line(row, args.timeout), flush=True)


def _finish_row(row: dict, results: dict, given_up: set, series: dict) -> None:
    row['results'] = results
    verdicts = {tool: r.get('verdict', r.get('realizable')) for tool, r in results.items()
                if tool != 'check' and not r['timeout'] and not r.get('failed')}
    verdicts = {tool: v for tool, v in verdicts.items() if v is not None}
    row['agree'] = len(set(verdicts.values())) <= 1
    if 'verdict' not in row and verdicts:
        row['verdict'] = next(iter(verdicts.values()))
    for tool, run in results.items():
        if run['timeout']:
            given_up.add(tool)
        elif not run.get('failed'):
            series.setdefault((row['family'], tool), []).append((row['size'], run['seconds']))


def _row_line(row: dict, timeout: float) -> str:
    results = row['results']
    verdict = {True: 'realizable', False: 'unrealizable'}.get(row.get('verdict'), '?')
    if not row['agree']:
        verdict += ' (VERDICTS DIFFER)'
    stages = ', '.join(f'{k} {v:.2f}' for k, v in row.get('stages', {}).items())
    ratio = cpu_ratio = ''
    pipeline, synthesis = results.get('pipeline'), results.get('gr1synth + strategy')
    if pipeline and synthesis and not pipeline['timeout'] and not synthesis['timeout'] \
            and not pipeline.get('failed') and not synthesis.get('failed'):
        ratio = f"{pipeline['seconds'] / synthesis['seconds']:.2f}"
        cpu_ratio = f"{pipeline['cpu'] / synthesis['cpu']:.2f}"
    warm = row.get('warm', {})
    warm_cell = ' / '.join(f'{warm[tool]:.3f}' if tool in warm else '-' for tool in ('pipeline', 'gr1synth + strategy'))
    warm_ratio = f"{warm['pipeline'] / warm['gr1synth + strategy']:.2f}" \
        if 'pipeline' in warm and warm.get('gr1synth + strategy') else ''
    if not warm:
        warm_cell = ''
    check = results.get('check')
    if check is None:
        check_cell = ''
    elif check['timeout'] or check.get('failed'):
        check_cell = cell(check, timeout)
    else:
        problems = check['problems']
        check_cell = f"passed ({check['seconds']:.1f} s)" if not problems else f'{len(problems)} problems: {problems[0]}'
    return (f"| {row['label']} | {row.get('props', '')} | {verdict} | "
            + ' | '.join(cell(results.get(tool), timeout) for tool in TOOLS)
            + f' | {ratio} | {cpu_ratio} | {warm_cell} | {warm_ratio} | {check_cell} | {stages} |')


TOOLS = ('pipeline', 'gr1synth', 'gr1synth + strategy', 'slugs')


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--pipeline-child', nargs=4, help=argparse.SUPPRESS)
    parser.add_argument('--runs', type=int, default=1, help=argparse.SUPPRESS)  # of --pipeline-child
    parser.add_argument('--warm-up-to', type=int, default=80,
                        help='measure warm runs (a second request in the same process) of robots up to '
                             'this size (default 80)')
    parser.add_argument('--slugs', default='/tmp/slugs/src/slugs')
    parser.add_argument('--timeout', type=float, default=60.0, help='wall seconds per run (default 60)')
    parser.add_argument('--slugs-timeout', type=float, help="slugs' wall seconds per run (default: --timeout)")
    parser.add_argument('--shapes', default=','.join(capability_robots.SHAPES))
    parser.add_argument('--sizes', default=','.join(map(str, SIZES)))
    parser.add_argument('--grids', default=','.join(f'{w}x{h}' for w, h in GRIDS), help="'' for none")
    parser.add_argument('--check-up-to', type=int, default=80,
                        help='check the explicit strategies of robots up to this size (default 80)')
    parser.add_argument('--markdown', help=f'write the table here (e.g. {RESULTS.relative_to(ROOT)})')
    args = parser.parse_args()
    if args.slugs_timeout is None:
        args.slugs_timeout = args.timeout
    if args.pipeline_child:
        config_dir, shape, size, slugsin = args.pipeline_child
        pipeline_child(config_dir, shape, int(size), slugsin, args.runs)
        return
    args.shapes = [s for s in args.shapes.split(',') if s]
    args.sizes = [int(s) for s in args.sizes.split(',') if s]
    args.grids = [tuple(int(v) for v in g.split('x')) for g in args.grids.split(',') if g]
    header = ('| task | env / sys props | verdict | pipeline (s) | gr1synth (s) | gr1synth + strategy (s) '
              '| slugs (s) | ratio | CPU ratio | warm: pipeline / gr1synth + strategy (s) | warm ratio | check '
              '| pipeline stages (s) |\n'
              '|---|---|---|---|---|---|---|---|---|---|---|---|---|')
    print(header, flush=True)
    rows, series = [], {}
    with tempfile.TemporaryDirectory() as directory:
        measure_capabilities(args, Path(directory), rows, series)
        measure_gridworlds(args, Path(directory), rows, series)
    exponents = ['| family | pipeline | gr1synth | gr1synth + strategy | slugs |', '|---|---|---|---|---|']
    for family in dict.fromkeys(row['family'] for row in rows):
        values = []
        for tool in TOOLS:
            slope = fitted_exponent(series.get((family, tool), []))
            values.append('-' if slope is None else f'{slope:.1f}')
        exponents.append(f'| {family} | ' + ' | '.join(values) + ' |')
    print('\nFitted growth exponent (seconds ~ N^k over N >= 20; gridworld: over cells):')
    print('\n'.join(exponents))
    differing = [row['label'] for row in rows if not row['agree']]
    print('verdicts differ on: ' + (', '.join(differing) if differing else 'no row'))
    if args.markdown:
        commit = subprocess.run(['git', 'rev-parse', '--short', 'HEAD'], cwd=ROOT, capture_output=True,
                                text=True).stdout.strip()
        lines = [_row_line(row, args.timeout) for row in rows]
        Path(args.markdown).write_text(
            f'# Capability robots and the per-cell gridworld (issue 44)\n\n'
            f"Written by `bench/bench_capability_scale.py --timeout {args.timeout:g}` on "
            f"{time.strftime('%Y-%m-%d %H:%M', time.gmtime())} UTC, code at {commit}; wall seconds, "
            f'each run a fresh process, on the shared 2-core machine (noisy). slugs built from source.\n\n'
            + header + '\n' + '\n'.join(lines) + '\n\nFitted growth exponent (seconds ~ N^k over N >= 20; '
            'gridworld: over cells):\n\n' + '\n'.join(exponents) + '\n\nVerdicts differ on: '
            + (', '.join(differing) if differing else 'no row') + '.\n')


if __name__ == '__main__':
    main()
