"""Ours vs slugs on the public GR(1) families (issue 24): CPU time per family and size, with
the differential checks, one table (results/gr1_families.md) and one PNG per family.

    nice -n 10 python bench/bench_gr1_families.py --slugs /path/to/slugs [--timeout 120]
    python bench/bench_gr1_families.py --families cinderella,amba --max-sizes 4

For each family (bench/gr1_families.py) and size, smallest first: the structuredslugs text is
converted once to slugsin (our parser) and both tools run on that same file, each in a fresh
process, realizability only (slugs' default), CPU seconds (user + system of the child,
start-up included). A tool that times out is not run on the family's larger sizes.
Differential checks on every instance both finish: the verdicts agree; and, when realizable,
our strategy passes bench/strategy_check.py, an independent checker: as relations (the
symbolic check, bounded by ``--check-timeout``), and as the explicit strategy
(``gr1synth --explicitStrategy --jsonOutput``, bounded by ``--strategy-timeout``) where its
extraction finishes in time.

Tiny specifications are bound by start-up (a Python process with CUDD loaded: about 0.1 s), so
the instances ours solves within ``RESIDENT_BELOW`` seconds are also sent to a resident
``gr1synth --serve`` process (the mode for tools that call it many times): the "resident"
column is its CPU time per request, once the process has answered the same request once.
"""

from __future__ import annotations

import argparse
import json
import os
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / 'bench' / 'results'
sys.path[:0] = [str(ROOT), str(ROOT / 'bench')]

import gr1_families

GR1SYNTH = [sys.executable, '-m', 'ltl_synthesizer']
# Instances ours solves within this many CPU seconds are also timed in the resident mode.
RESIDENT_BELOW = 2.0
# CPU seconds of repeated requests per instance (the kernel counts CPU time in 10 ms ticks).
RESIDENT_BUDGET = 1.0
# Counter-strategies up to this many bytes of JSON are loaded and checked (larger ones hold
# millions of system answers: the check would need gigabytes).
COUNTERSTRATEGY_CHECKED_BYTES = 4 * 2**20


def this_run() -> str:
    """When and on which commit the rows of this run are measured: the report keeps rows of
    earlier runs (families not run this time), and says which rows come from which run."""
    commit = subprocess.run(['git', 'rev-parse', '--short', 'HEAD'], cwd=ROOT, capture_output=True,
                            text=True).stdout.strip() or 'unknown commit'
    return f"{time.strftime('%Y-%m-%d %H:%M', time.gmtime())} UTC, code at {commit}"


def run_timed(command: list[str], timeout: float, stdout=subprocess.DEVNULL) -> dict:
    """Run ``command``; its CPU seconds (user + system, children included), exit status and
    stderr; ``timeout`` True when killed at the time limit."""
    with tempfile.TemporaryFile() as errors:
        start = time.monotonic()
        process = subprocess.Popen(command, stdout=stdout, stderr=errors, cwd=ROOT,
                                   start_new_session=True)
        timed_out = False
        while True:
            pid, status, usage = os.wait4(process.pid, os.WNOHANG)
            if pid:
                break
            if time.monotonic() - start > timeout:
                os.killpg(process.pid, signal.SIGKILL)
                pid, status, usage = os.wait4(process.pid, 0)
                timed_out = True
                break
            time.sleep(0.02)
        process.returncode = os.waitstatus_to_exitcode(status)
        errors.seek(0)
        text = errors.read().decode(errors='replace')
    return {'cpu': usage.ru_utime + usage.ru_stime, 'timeout': timed_out,
            'status': process.returncode, 'stderr': text, 'rss_mb': usage.ru_maxrss / 1024}


def _process_cpu(pid: int) -> float:
    """CPU seconds (user + system) a running process has used, from /proc."""
    fields = Path(f'/proc/{pid}/stat').read_text().rsplit(')', 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf('SC_CLK_TCK')


def resident_cpu(slugsin: Path, cold_cpu: float) -> float:
    """CPU seconds per request of a resident ``gr1synth --serve`` process on ``slugsin``: the
    process answers it once (its modules load), then as many times as fit in RESIDENT_BUDGET
    (at most 20); nothing carries over from one request to the next."""
    repetitions = max(1, min(20, int(RESIDENT_BUDGET / max(cold_cpu - 0.1, 0.01))))
    process = subprocess.Popen(GR1SYNTH + ['--serve'], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                               text=True, cwd=ROOT)

    def ask() -> dict:
        process.stdin.write(json.dumps([str(slugsin)]) + '\n')
        process.stdin.flush()
        return json.loads(process.stdout.readline())

    try:
        first = ask()
        start = _process_cpu(process.pid)
        for _ in range(repetitions):
            if ask() != first:
                raise RuntimeError(f'the resident answer to {slugsin.name} changed')
        return (_process_cpu(process.pid) - start) / repetitions
    finally:
        process.stdin.close()
        process.wait()


def verdict(result: dict):
    if result['timeout'] or result['status'] != 0:
        return None
    if 'Specification is realizable' in result['stderr']:
        return True
    if 'Specification is unrealizable' in result['stderr']:
        return False
    return None


def symbolic_strategy_check(slugsin: Path, timeout: float) -> str:
    """Our strategy as relations, checked independently (bench/strategy_check.py): a short
    outcome text."""
    with tempfile.TemporaryFile() as output:
        run = run_timed([sys.executable, str(ROOT / 'bench' / 'strategy_check.py'), str(slugsin)],
                        timeout, stdout=output)
        output.seek(0)
        said = output.read().decode(errors='replace').strip()
    if run['timeout']:
        return f'symbolic check > {timeout:.0f} s'
    if run['status'] == 0:
        return f'symbolic ok ({run["cpu"]:.1f} s)'
    return f'symbolic check FAILED: {said or run["stderr"].strip()[-200:]}'


def strategy_check(spec, slugsin: Path, timeout: float) -> str:
    """Extract our explicit strategy and check it independently; a short outcome text."""
    from strategy_check import check_strategy
    output = slugsin.with_suffix('.json')
    run = run_timed(GR1SYNTH + ['--explicitStrategy', '--jsonOutput', str(slugsin), str(output)],
                    timeout)
    if run['timeout']:
        return f'explicit not extracted (> {timeout:.0f} s)'
    if run['status'] != 0:
        return f'explicit extraction failed: {run["stderr"].strip()[-200:]}'
    strategy = json.loads(output.read_text())
    output.unlink()
    problems = check_strategy(spec, strategy)
    size = len(strategy['nodes'])
    return f'explicit ok ({size} nodes)' if not problems else \
        f'explicit check FAILED ({size} nodes): {problems[0]}'


def counterstrategy_check(spec, slugsin: Path, slugs: str | None, timeout: float) -> str:
    """Our counter-strategy (``--counterStrategy --jsonOutput``), checked independently
    (bench/strategy_check.check_counterstrategy), with its size and CPU time beside slugs'
    (``--counterStrategy``: slugs writes it as text only), alternating the two tools."""
    from strategy_check import check_counterstrategy
    output = slugsin.with_suffix('.counter.json')
    run = run_timed(GR1SYNTH + ['--counterStrategy', '--jsonOutput', str(slugsin), str(output)],
                    timeout)
    if run['timeout'] or run['status'] != 0:
        said = f'> {timeout:.0f} s' if run['timeout'] else run['stderr'].strip()[-200:]
        return f'counter-strategy not extracted ({said})'
    size = output.stat().st_size
    if size > COUNTERSTRATEGY_CHECKED_BYTES:  # every node lists every system answer
        output.unlink()
        return f'counter-strategy of {size / 2**20:.0f} MB not checked ({run["cpu"]:.2f} s)'
    strategy = json.loads(output.read_text())
    output.unlink()
    problems = check_counterstrategy(spec, strategy)
    text = (f'counter-strategy {"ok" if not problems else "check FAILED: " + problems[0]} '
            f'({len(strategy["nodes"])} nodes, {run["cpu"]:.2f} s')
    if slugs is not None:
        with tempfile.TemporaryFile() as written:
            theirs = run_timed([slugs, '--counterStrategy', str(slugsin)], timeout, stdout=written)
            written.seek(0)
            states = sum(line.startswith(b'State ') for line in written)
        text += f'; slugs {states} nodes, {theirs["cpu"]:.2f} s' if not theirs['timeout'] else \
            f'; slugs > {timeout:.0f} s'
    return text + ')'


def bench_family(name: str, sizes, slugs: str | None, timeout: float, strategy_timeout: float,
                 check_timeout: float, directory: Path, measured: str = '') -> list[dict]:
    from respec.parsing import parse_structuredslugs
    rows = []
    ours_alive, slugs_alive = True, slugs is not None
    for label, generator, arguments in sizes:
        if not (ours_alive or slugs_alive):
            break
        text = generator(*arguments)
        spec = parse_structuredslugs(text, filename=f'{name}.structuredslugs')
        slugsin = directory / f'{name}_{"_".join(map(str, arguments))}.slugsin'
        slugsin.write_text(spec.to_slugsin())
        row = {'family': name, 'size': label, 'limit': timeout,
               'variables': len(spec.env_props) + len(spec.sys_props), 'measured': measured}
        if ours_alive:
            ours = run_timed(GR1SYNTH + [str(slugsin)], timeout)
            row['ours'] = None if ours['timeout'] else ours['cpu']
            row['ours_verdict'] = verdict(ours)
            ours_alive = not ours['timeout']
            if row['ours'] is not None and row['ours'] < RESIDENT_BELOW:
                row['resident'] = resident_cpu(slugsin, row['ours'])
        if slugs_alive:
            theirs = run_timed([slugs, str(slugsin)], timeout)
            row['slugs'] = None if theirs['timeout'] else theirs['cpu']
            row['slugs_verdict'] = verdict(theirs)
            slugs_alive = not theirs['timeout']
        checks = []
        if row.get('ours_verdict') is not None and row.get('slugs_verdict') is not None:
            checks.append('verdicts agree' if row['ours_verdict'] == row['slugs_verdict']
                          else 'VERDICTS DISAGREE')
        if row.get('ours_verdict'):
            checks.append('strategy: ' + symbolic_strategy_check(slugsin, check_timeout) + ', '
                          + strategy_check(spec, slugsin, strategy_timeout))
        elif row.get('ours_verdict') is False:
            checks.append(counterstrategy_check(spec, slugsin, slugs if slugs_alive else None,
                                                strategy_timeout))
        row['checks'] = '; '.join(checks)
        slugsin.unlink()
        rows.append(row)
        print(f"{name:16s} {label:18s} vars={row['variables']:3d} ours={_cell(row, 'ours'):>8s} "
              f"resident={_resident_cell(row):>6s} slugs={_cell(row, 'slugs'):>8s} {_verdict_text(row)}  {row['checks']}", flush=True)
    return rows


def _cell(row: dict, tool: str) -> str:
    if tool not in row:
        return '-'
    return f"> {row.get('limit', 0):.0f} s" if row[tool] is None else f'{row[tool]:.2f}'


def _resident_cell(row: dict) -> str:
    return f"{row['resident']:.3f}" if row.get('resident') is not None else '-'


def _verdict_text(row: dict) -> str:
    value = row.get('ours_verdict', row.get('slugs_verdict'))
    return {True: 'realizable', False: 'unrealizable', None: '?'}[value]


def write_report(rows: list[dict], timeout: float) -> None:
    lines = ['# Ours (gr1synth) vs slugs on the public GR(1) families', '',
             'CPU seconds (user + system, start-up included) of a fresh process, realizability '
             f'only, on the same slugsin file; "> N s": killed at the time limit, "-" = not run '
             '(the tool timed out on a smaller size). Ratio = ours / slugs. Checks: verdicts '
             'agree; our strategy passes bench/strategy_check.py (independent of the '
             'synthesizer\'s fixpoints): "symbolic": as relations, on all of its positions '
             '(initial positions covered, every environment move answered, no move leaving '
             'them, and an Emerson-Lei search for a fair path that misses a goal; CPU s of '
             'synthesis and check); "explicit": the extracted strategy graph, where extraction finishes in '
             'time; for unrealizable instances, our counter-strategy (`--counterStrategy --jsonOutput`) '
             'passes the independent check (every system answer is followed, every cycle meets '
             'every assumption and misses some goal), with its node count and CPU s beside '
             'slugs\' (`--counterStrategy`), where extraction finishes in time. "Resident": CPU s per request of a resident `gr1synth --serve` process '
             f'(instances ours solves within {RESIDENT_BELOW:.0f} s), start-up excluded.', '',
             'Generated by `nice -n 10 python bench/bench_gr1_families.py --slugs SLUGS`; the '
             'rows of families not run again are kept from earlier runs. Rows by run:', '',
             *_runs(rows), '',
             '| family | size | variables | verdict | ours | ours resident | slugs | ratio | checks |',
             '|---|---|---|---|---|---|---|---|---|']
    for row in rows:
        ratio = '-'
        if row.get('ours') is not None and row.get('slugs'):
            ratio = f"{row['ours'] / row['slugs']:.2f}"
        elif row.get('ours') is not None and 'slugs' in row:
            ratio = 'slugs timed out'
        lines.append(f"| {row['family']} | {row['size']} | {row['variables']} | {_verdict_text(row)} "
                     f"| {_cell(row, 'ours')} | {_resident_cell(row)} | {_cell(row, 'slugs')} | {ratio} "
                     f"| {row['checks']} |")
    RESULTS.mkdir(parents=True, exist_ok=True)
    (RESULTS / 'gr1_families.md').write_text('\n'.join(lines) + '\n')
    (RESULTS / 'gr1_families.json').write_text(json.dumps(rows, indent=1) + '\n')


def _runs(rows: list[dict]) -> list[str]:
    """One line per run: when it was measured and the families whose rows come from it."""
    families_by_run: dict[str, list[str]] = {}
    for row in rows:
        families = families_by_run.setdefault(row.get('measured') or 'an earlier run', [])
        if row['family'] not in families:
            families.append(row['family'])
    return [f'- {run}: {", ".join(families)}' for run, families in families_by_run.items()]


def plot(rows: list[dict], timeout: float) -> None:
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    for family in dict.fromkeys(row['family'] for row in rows):
        family_rows = [row for row in rows if row['family'] == family]
        labels = [row['size'] for row in family_rows]
        figure, axes = plt.subplots(figsize=(8, 4.5))
        names = {'ours': 'gr1synth (ours)', 'resident': 'gr1synth --serve, per request', 'slugs': 'slugs'}
        for tool, marker in (('ours', 'o'), ('resident', '^'), ('slugs', 's')):
            points = [(index, row[tool]) for index, row in enumerate(family_rows)
                      if row.get(tool) is not None]
            if points:
                axes.plot(*zip(*points), marker=marker, label=names[tool],
                          linestyle=':' if tool == 'resident' else '-')
            timeouts = [(index, row.get('limit', timeout)) for index, row in enumerate(family_rows)
                        if tool in row and row[tool] is None]
            if timeouts:
                axes.plot(*zip(*timeouts), marker='x', linestyle='none',
                          color='red' if tool == 'slugs' else 'black', label=f'{tool} timeout')
        axes.set_yscale('log')
        axes.set_xticks(range(len(labels)))
        axes.set_xticklabels(labels, rotation=30, ha='right', fontsize=8)
        axes.set_ylabel('CPU seconds')
        axes.set_title(f'{family}: ours vs slugs (realizability)')
        axes.legend()
        figure.tight_layout()
        figure.savefig(RESULTS / f'gr1_families_{family}.png', dpi=90)
        plt.close(figure)


def _in_family_order(rows: list[dict]) -> list[dict]:
    order = list(gr1_families.FAMILIES)
    return sorted(rows, key=lambda row: order.index(row['family']))  # stable within a family


def add_comparison_arguments(parser: argparse.ArgumentParser) -> None:
    """The options every bench against slugs takes: the slugs executable and a run's time limit."""
    parser.add_argument('--slugs', help='slugs executable (compared when given)')
    parser.add_argument('--timeout', type=float, default=120, help='seconds per run')


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    add_comparison_arguments(parser)
    parser.add_argument('--strategy-timeout', type=float, default=10,
                        help='seconds for extracting the explicit strategy')
    parser.add_argument('--check-timeout', type=float, default=120,
                        help='seconds for the symbolic strategy check')
    parser.add_argument('--families', default=','.join(gr1_families.FAMILIES))
    parser.add_argument('--max-sizes', type=int, default=None)
    args = parser.parse_args(argv)
    families = args.families.split(',')
    # Rows of the families not run this time are kept from the previous report.
    previous = RESULTS / 'gr1_families.json'
    kept = [row for row in json.loads(previous.read_text()) if row['family'] not in families] \
        if previous.exists() else []
    rows = []
    measured = this_run()
    with tempfile.TemporaryDirectory() as directory:
        for name in families:
            sizes = gr1_families.FAMILIES[name][:args.max_sizes]
            rows += bench_family(name, sizes, args.slugs, args.timeout, args.strategy_timeout,
                                 args.check_timeout, Path(directory), measured)
            write_report(_in_family_order(kept + rows), args.timeout)
    plot(_in_family_order(kept + rows), args.timeout)
    return 0


if __name__ == '__main__':
    sys.exit(main())
