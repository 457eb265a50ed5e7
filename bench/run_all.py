"""Every benchmark of bench/ in turn (``make bench``): each prints its figures and writes its
results under bench/results/; this says which one runs, how long each took and which failed.

Some take long (the GR(1) families with slugs, the reliability soak, the fleet of network
namespaces, which needs root): pick with ``--only`` or leave out with ``--skip``.

    .venv/bin/python bench/run_all.py [--only NAME,...] [--skip NAME,...] [--slugs PATH]
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import time
from pathlib import Path

BENCH = Path(__file__).resolve().parent


def benchmarks() -> list[Path]:
    return sorted(BENCH.glob('bench_*.py'))


def command(script: Path, slugs: str | None) -> list[str]:
    """How to run ``script``: slugs is passed to the benchmarks that compare against it."""
    arguments = [sys.executable, str(script)]
    if slugs and "'--slugs'" in script.read_text():
        arguments += ['--slugs', slugs]
    return arguments


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--only', default='', help='comma-separated names (bench_NAME.py) to run')
    parser.add_argument('--skip', default='', help='comma-separated names to leave out')
    parser.add_argument('--slugs', help='a slugs executable, for the benchmarks that compare against it')
    args = parser.parse_args(argv)
    only, skip = set(filter(None, args.only.split(','))), set(filter(None, args.skip.split(',')))
    chosen = [script for script in benchmarks()
              if (not only or script.stem[len('bench_'):] in only) and script.stem[len('bench_'):] not in skip]
    failed = []
    for index, script in enumerate(chosen, 1):
        print(f'[{index}/{len(chosen)}] {script.name}', flush=True)
        started = time.monotonic()
        status = subprocess.call(command(script, args.slugs), cwd=BENCH.parent)
        print(f'[{index}/{len(chosen)}] {script.name}: exit {status} after {time.monotonic() - started:.0f} s',
              flush=True)
        if status:
            failed.append(script.name)
    print(f'{len(chosen) - len(failed)} of {len(chosen)} benchmarks ran'
          + (f'; failed: {", ".join(failed)}' if failed else ''))
    return 1 if failed else 0


if __name__ == '__main__':
    sys.exit(main())
