"""Explicit strategies at scale (issue 24): ``gr1synth --explicitStrategy --jsonOutput`` streams
the JSON while it extracts the strategy; this prints nodes, edges, nodes/s and peak RSS.

    nice -n 10 python bench/bench_strategy_stream.py [--timeout 120]

Instances: AMBA with 2 masters and the factory and moving-obstacle sizes whose strategies
have thousands of nodes (bench/gr1_families.py), each in a fresh process (CPU seconds, start-up
included; peak RSS of that process). Results: results/strategy_streaming.md.
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT), str(ROOT / 'bench')]

import gr1_families
from bench_gr1_families import GR1SYNTH, RESULTS, run_timed

INSTANCES = [('amba 2 masters', gr1_families.amba, (2,)),
             ('factory 5x3 s1 e0', gr1_families.factory, (5, 3, 1, 0)),
             ('moving obstacle 8x8 g0', gr1_families.moving_obstacle, (8, 0)),
             ('moving obstacle 16x16 g3', gr1_families.moving_obstacle, (16, 3))]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--timeout', type=float, default=120)
    args = parser.parse_args(argv)
    from respec.parsing import parse_structuredslugs
    lines = ['# Explicit strategies, streamed (gr1synth --explicitStrategy --jsonOutput)', '',
             'CPU seconds of the whole process (start-up, parsing, solving, extraction, writing), '
             'peak RSS of the process.', '',
             '| instance | nodes | edges | CPU s | nodes/s | edges/s | JSON MB | peak RSS MB |',
             '|---|---|---|---|---|---|---|---|']
    with tempfile.TemporaryDirectory() as directory:
        for label, generator, arguments in INSTANCES:
            spec = parse_structuredslugs(generator(*arguments))
            source = Path(directory) / 'spec.slugsin'
            source.write_text(spec.to_slugsin())
            output = Path(directory) / 'strategy.json'
            run = run_timed(GR1SYNTH + ['--explicitStrategy', '--jsonOutput', str(source), str(output)],
                            args.timeout)
            if run['timeout'] or run['status'] != 0 or not output.exists():
                lines.append(f'| {label} | timeout (> {args.timeout:.0f} s) or failed | | | | | | |')
                print(lines[-1], flush=True)
                continue
            size = output.stat().st_size
            nodes = json.loads(output.read_text())['nodes']
            edges = sum(len(node['trans']) for node in nodes.values())
            lines.append(f"| {label} | {len(nodes)} | {edges} | {run['cpu']:.2f} | "
                         f"{len(nodes) / run['cpu']:.0f} | {edges / run['cpu']:.0f} | "
                         f"{size / 2**20:.1f} | {run['rss_mb']:.0f} |")
            print(lines[-1], flush=True)
    RESULTS.mkdir(parents=True, exist_ok=True)
    (RESULTS / 'strategy_streaming.md').write_text('\n'.join(lines) + '\n')
    return 0


if __name__ == '__main__':
    sys.exit(main())
