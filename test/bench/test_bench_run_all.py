"""bench/run_all.py (``make bench``): every benchmark in turn, slugs passed to those that take it."""

from __future__ import annotations

import sys
from pathlib import Path

REPOSITORY = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPOSITORY / 'bench'))

import run_all  # noqa: E402


def test_every_benchmark_is_listed_and_slugs_goes_to_those_comparing_against_it():
    names = [script.name for script in run_all.benchmarks()]
    assert names == sorted(path.name for path in (REPOSITORY / 'bench').glob('bench_*.py'))
    assert {'bench_gr1_families.py', 'bench_reliability.py', 'bench_tiny_specs.py'} <= set(names)
    families = run_all.command(REPOSITORY / 'bench' / 'bench_gr1_families.py', '/opt/slugs')
    reliability = run_all.command(REPOSITORY / 'bench' / 'bench_reliability.py', '/opt/slugs')
    assert families[-2:] == ['--slugs', '/opt/slugs'] and '--slugs' not in reliability


def test_only_and_skip_choose_what_runs(capsys):
    assert run_all.main(['--only', 'no_such_benchmark']) == 0
    assert '0 of 0 benchmarks ran' in capsys.readouterr().out
    assert run_all.main(['--only', 'ltl_specification', '--skip', 'ltl_specification']) == 0
