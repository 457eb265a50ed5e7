"""Tiny specifications (issue 38 item 5): the cost of a fresh ``gr1synth`` process (target:
at most 0.15 s of CPU) beside slugs', and the wall time of one request to a resident
``gr1synth --serve`` process (target: under 10 ms), for a verdict, an explicit strategy and a
counter-strategy, and of one synthesis in the server's own synthesis processes (what the
``ltl_synthesis`` node asks its child: the strategy when realizable, the explanation when not).

    nice -n 10 python bench/bench_tiny_specs.py [--slugs /path/to/slugs]

Fresh processes: the median CPU seconds (user + system) of ``--repeats`` runs, alternating the
two tools (bench_startup.py has the interpreter's floors and more specifications). Resident: the median wall time of ``--repeats`` requests after a first one (which
loads the modules), and the mean CPU time of the answering process over ``--cpu-batch``
requests (the kernel counts CPU time in 10 ms ticks: a batch makes that fine enough; on a
shared machine the wall time also holds the time other work took the cores). Table:
results/tiny_specs.md.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / 'bench' / 'results'
sys.path[:0] = [str(ROOT), str(ROOT / 'bench')]

import gr1_families
from bench_gr1_families import GR1SYNTH, run_timed

SPECS = {
    'one input, one output (realizable)':
        "[INPUT]\nx\n\n[OUTPUT]\ny\n\n[SYS_TRANS]\ny' <-> x'\n\n[SYS_LIVENESS]\ny | !x\n",
    'one input, one output (unrealizable)':
        "[INPUT]\nx\n\n[OUTPUT]\ny\n\n[SYS_TRANS]\ny' <-> x\n\n[SYS_LIVENESS]\ny & x\n",
    'GenBuf, 2 senders (realizable)': gr1_families.genbuf(2, True),
    'GenBuf, 2 senders (unrealizable)': gr1_families.genbuf(2, False),
    'gridworld 5x3 k=2 (unrealizable)': gr1_families.gridworld(5, 3, 2, False),
}

# The resident requests: what gr1synth is asked, by verdict.
REQUESTS = {True: ['--explicitStrategy', '--jsonOutput'], False: ['--counterStrategy', '--jsonOutput']}


def process_cpu(pid: int) -> float:
    """CPU seconds (user + system) process ``pid`` has used so far, all its threads included."""
    with open(f'/proc/{pid}/stat') as stat:
        fields = stat.read().rsplit(')', 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf('SC_CLK_TCK')


def resident_wall(requests: list[list[str]], repeats: int, cpu_batch: int) -> tuple[list[float], float]:
    """Median wall seconds per request, for each request, of one resident process; and the
    mean CPU seconds per request that process spent on a batch of ``cpu_batch`` of the last."""
    process = subprocess.Popen(GR1SYNTH + ['--serve'], stdin=subprocess.PIPE,
                               stdout=subprocess.PIPE, text=True, cwd=ROOT)

    def ask(arguments) -> float:
        start = time.perf_counter()
        process.stdin.write(json.dumps(arguments) + '\n')
        process.stdin.flush()
        answer = json.loads(process.stdout.readline())
        elapsed = time.perf_counter() - start
        if answer['status'] != 0:
            raise RuntimeError(f'{arguments}: {answer["stderr"]}')
        return elapsed

    def cpu_per_request(arguments) -> float:
        before = process_cpu(process.pid)
        for _ in range(cpu_batch):
            ask(arguments)
        return (process_cpu(process.pid) - before) / cpu_batch

    try:
        for arguments in requests:
            ask(arguments)  # loads what this kind of request needs
        walls = [statistics.median(ask(arguments) for _ in range(repeats)) for arguments in requests]
        return walls, cpu_per_request(requests[-1])
    finally:
        process.stdin.close()
        process.wait()


def synthesis_children() -> list[int]:
    """The synthesis processes this process started."""
    found = []
    for entry in filter(str.isdigit, os.listdir('/proc')):
        try:
            with open(f'/proc/{entry}/stat') as stat:
                parent = int(stat.read().rsplit(')', 1)[1].split()[1])
            with open(f'/proc/{entry}/cmdline', 'rb') as cmdline:
                command = cmdline.read()
        except (FileNotFoundError, ProcessLookupError):
            continue
        if parent == os.getpid() and b'respec.child_processes.runner' in command:
            found.append(int(entry))
    return found


def server_child_wall(spec, repeats: int, cpu_batch: int) -> tuple[float, float]:
    """Median wall seconds of one synthesis in the server's synthesis processes, as the
    ``ltl_synthesis`` node asks it (its default strategy budget), the child already warm; and
    the mean CPU seconds per synthesis of the child and this caller over ``cpu_batch`` of them."""
    from ltl_synthesizer.interrupt import Limits
    from ltl_synthesizer.isolated import SynthesisProcesses
    from respec.child_processes.runner import SERVER_CHILD_NICENESS
    from ltl_synthesizer.service import DEFAULT_MAX_STRATEGY_EDGES
    processes = SynthesisProcesses(niceness=SERVER_CHILD_NICENESS)
    processes.prepare(1)

    def synthesize() -> float:
        start = time.perf_counter()
        processes.synthesize(spec, True, Limits(), max_strategy_edges=DEFAULT_MAX_STRATEGY_EDGES)
        return time.perf_counter() - start

    try:
        synthesize()
        wall = statistics.median(synthesize() for _ in range(repeats))
        child, = synthesis_children()  # one child serves them all
        before = process_cpu(child) + process_cpu(os.getpid())
        for _ in range(cpu_batch):
            synthesize()
        return wall, (process_cpu(child) + process_cpu(os.getpid()) - before) / cpu_batch
    finally:
        processes.close()


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--slugs', help='slugs executable (compared when given)')
    parser.add_argument('--repeats', type=int, default=7)
    parser.add_argument('--cpu-batch', type=int, default=40,
                        help='requests per CPU measurement of the resident process and the server child')
    parser.add_argument('--markdown', default=str(RESULTS / 'tiny_specs.md'), help='where to write the table')
    args = parser.parse_args(argv)
    from respec.parsing import parse_structuredslugs
    lines = ['# Tiny specifications: a fresh process and the resident mode', '',
             'Fresh: median CPU seconds (user + system) of a fresh process over '
             f'{args.repeats} runs, verdict only, ours and slugs alternating. Resident: median wall '
             f'milliseconds per request (of {args.repeats}) to one `gr1synth --serve` process, for '
             'the verdict and for the strategy (`--explicitStrategy --jsonOutput` when realizable, '
             '`--counterStrategy --jsonOutput` when not), each request answered once before. Server child: '
             'median wall milliseconds of one synthesis in the synthesis node\'s child processes '
             '(`SynthesisProcesses.synthesize`, the node\'s strategy budget), the child warm. '
             f'CPU: mean CPU milliseconds per request over {args.cpu_batch} of them (the resident '
             'process; the child and its caller). The machine (2 cores) was shared with other work '
             'while this ran: the wall times hold the time other work took the cores.', '',
             'Generated by `nice -n 10 python bench/bench_tiny_specs.py --slugs SLUGS`.', '',
             '| specification | verdict | ours fresh | slugs fresh | resident verdict | '
             'resident strategy | resident strategy CPU | server child | server child CPU |',
             '|---|---|---|---|---|---|---|---|---|']
    with tempfile.TemporaryDirectory() as directory:
        for label, text in SPECS.items():
            slugsin = Path(directory) / 'tiny.slugsin'
            slugsin.write_text(parse_structuredslugs(text, filename='t.structuredslugs').to_slugsin())
            first = run_timed(GR1SYNTH + [str(slugsin)], 60)
            realizable = 'is realizable' in first['stderr']
            ours_runs, slugs_runs = [], []
            for _ in range(args.repeats):  # alternating, so both see the same load
                ours_runs.append(run_timed(GR1SYNTH + [str(slugsin)], 60)['cpu'])
                if args.slugs:
                    slugs_runs.append(run_timed([args.slugs, str(slugsin)], 60)['cpu'])
            ours = statistics.median(ours_runs)
            slugs = statistics.median(slugs_runs) if slugs_runs else None
            output = str(Path(directory) / 'strategy.json')
            (verdict_wall, strategy_wall), strategy_cpu = resident_wall(
                [[str(slugsin)], REQUESTS[realizable] + [str(slugsin), output]], args.repeats, args.cpu_batch)
            child_wall, child_cpu = server_child_wall(parse_structuredslugs(text, filename='t.structuredslugs'),
                                                      args.repeats, args.cpu_batch)
            row = (f"| {label} | {'realizable' if realizable else 'unrealizable'} | {ours:.3f} s | "
                   f"{f'{slugs:.3f} s' if slugs is not None else '-'} | {verdict_wall * 1000:.1f} ms | "
                   f'{strategy_wall * 1000:.1f} ms | {strategy_cpu * 1000:.1f} ms | '
                   f'{child_wall * 1000:.1f} ms | {child_cpu * 1000:.1f} ms |')
            print(row, flush=True)
            lines.append(row)
    Path(args.markdown).parent.mkdir(parents=True, exist_ok=True)
    Path(args.markdown).write_text('\n'.join(lines) + '\n')
    return 0


if __name__ == '__main__':
    sys.exit(main())
