"""bench/bench_gr1_families.py end to end on the smallest instance of one family: the table
has our cold and resident times, the checks ran, and the resident answer is the command's."""

from __future__ import annotations

import json
import shutil
import sys
from pathlib import Path

import pytest

REPOSITORY = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPOSITORY / 'bench'))

import bench_gr1_families  # noqa: E402

pytestmark = pytest.mark.slow


def test_the_families_bench_times_ours_cold_and_resident(tmp_path, monkeypatch):
    monkeypatch.setattr(bench_gr1_families, 'RESULTS', tmp_path)
    slugs = shutil.which('slugs')  # compared only when a real slugs is on PATH
    arguments = ['--families', 'factory', '--max-sizes', '2', '--timeout', '60']
    assert bench_gr1_families.main(arguments + (['--slugs', slugs] if slugs else [])) == 0
    rows = json.loads((tmp_path / 'gr1_families.json').read_text())
    assert [row['size'] for row in rows] == ['3x3 s1 e1', '4x3 s1 e1']
    assert [row['ours_verdict'] for row in rows] == [False, True]
    for row in rows:
        assert 0 < row['resident'] < row['ours']
    assert 'symbolic ok' in rows[1]['checks'] and 'explicit ok' in rows[1]['checks']
    assert 'counter-strategy ok' in rows[0]['checks']  # issue 38: checked independently
    table = (tmp_path / 'gr1_families.md').read_text()
    assert '| ours | ours resident | slugs |' in table
    assert 'UTC, code at' in rows[0]['measured']
    assert f"- {rows[0]['measured']}: factory" in table  # which rows come from which run
    assert (tmp_path / 'gr1_families_factory.png').stat().st_size > 0


def test_a_resident_request_costs_less_than_a_fresh_process(tmp_path):
    slugsin = tmp_path / 'tiny.slugsin'
    slugsin.write_text('[INPUT]\nx\n\n[OUTPUT]\ny\n\n[SYS_TRANS]\n^ x\' y\'\n')
    cold = bench_gr1_families.run_timed(bench_gr1_families.GR1SYNTH + [str(slugsin)], 60)
    assert bench_gr1_families.verdict(cold) is True
    assert bench_gr1_families.resident_cpu(slugsin, cold['cpu']) < cold['cpu']
