"""Run our synthesizer on slugs' own example specifications and compare with slugs' results.

slugs' files are not ours to ship, so this takes the path of the ``examples`` directory of a
slugs checkout (https://github.com/VerifiableRobotics/slugs):

    python bench/slugs_examples.py /path/to/slugs/examples [--all] [--oracle] [--slugs EXE]

For each example it synthesizes in-process under slugs' default (standard) semantics and
under ``--sysInitRoboticsSemantics`` and prints expected vs ours with timings. ``--all`` also
runs every other .slugsin / .structuredslugs file found (no expectation known); ``--oracle``
adds the explicit-state test oracle's verdict for examples with at most 12 propositions;
``--slugs EXE`` adds the verdicts of a slugs executable run on the same files (through
ltl_synthesizer.external, as the original stack ran it), with its times.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

REPOSITORY = Path(__file__).resolve().parent.parent
sys.path[:0] = [str(REPOSITORY), str(REPOSITORY / 'test')]

from ltl_synthesizer import is_realizable
from respec.parsing import ParseError, parse_slugsin, parse_structuredslugs

# Realizability per slugs: (default semantics, --sysInitRoboticsSemantics).
EXPECTED = {
    'baby_network.slugsin': (False, False),
    'example_outermost_fixed_point_unrealizability.slugsin': (False, False),
    'unrealizable1.slugsin': (False, False),
    'firefighting.slugsin': (True, True),
    'networks.slugsin': (True, True),
    'simple_safety_example.slugsin': (True, True),
    'semantics_diference.slugsin': (True, False),
    'optimisticRecoveryTest.slugsin': (True, False),
}
ORACLE_LIMIT = 12


def load(path: Path):
    parse = parse_slugsin if path.suffix == '.slugsin' else parse_structuredslugs
    return parse(path.read_text(), str(path.name))


def verdict(realizable) -> str:
    return '-' if realizable is None else ('R' if realizable else 'U')


def run_slugs(executable: str, path: Path, spec) -> tuple[list, list]:
    """slugs' verdicts and times under both semantics, on the file as we print it."""
    import tempfile

    from ltl_synthesizer.external import run_external_synthesizer

    verdicts, seconds = [], []
    with tempfile.TemporaryDirectory() as directory:
        slugsin = Path(directory) / (path.stem + '.slugsin')
        slugsin.write_text(spec.to_slugsin())
        for robotics_semantics in (False, True):
            start = time.perf_counter()
            realizable, _, _ = run_external_synthesizer(
                executable, slugsin, Path(directory) / 'strategy.json',
                robotics_semantics=robotics_semantics, timeout=600)
            verdicts.append(realizable)
            seconds.append(time.perf_counter() - start)
    return verdicts, seconds


def run(path: Path, expected, use_oracle: bool, slugs: str | None = None) -> tuple[str, bool]:
    """One table row, and whether it matches the expectation."""
    try:
        spec = load(path)
    except ParseError as error:
        return f'{path.name:58} not parsed: {error}', expected is None
    size = len(spec.env_props) + len(spec.sys_props)
    ours, seconds = [], []
    for robotics_semantics in (False, True):
        start = time.perf_counter()
        ours.append(is_realizable(spec, robotics_semantics))
        seconds.append(time.perf_counter() - start)
    oracle = ''
    if use_oracle:
        if size <= ORACLE_LIMIT:
            from gr1_oracle import Oracle
            checker = Oracle(spec)
            oracle = ' '.join(verdict(checker.realizable(r)) for r in (False, True))
        else:
            oracle = 'n/a'
    reference = ''
    if slugs:
        verdicts, slugs_seconds = run_slugs(slugs, path, spec)
        reference = (f' {verdict(verdicts[0])} {verdict(verdicts[1])}'
                     f' {slugs_seconds[0]:8.3f} {slugs_seconds[1]:8.3f}')
        if expected is None:
            expected = tuple(verdicts)
        elif tuple(verdicts) != tuple(expected):
            reference += ' (slugs differs from the expectation)'
    wanted = expected or (None, None)
    cells = [f'{verdict(wanted[k])}/{verdict(ours[k])}' for k in (0, 1)]
    agrees = expected is None or tuple(ours) == tuple(expected)
    row = (f'{path.name:58} {size:4} {cells[0]:>9} {cells[1]:>9} {seconds[0]:8.3f} {seconds[1]:8.3f}'
           + (f' {oracle:>7}' if use_oracle else '') + reference + ('' if agrees else '   MISMATCH'))
    return row, agrees


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('examples', type=Path, help="a slugs checkout's examples directory")
    parser.add_argument('--all', action='store_true', help='also run the other example files')
    parser.add_argument('--oracle', action='store_true', help='add the explicit-state oracle verdicts')
    parser.add_argument('--slugs', metavar='EXE', help='also run this slugs executable on every example')
    arguments = parser.parse_args(argv)
    if not arguments.examples.is_dir():
        parser.error(f'{arguments.examples} is not a directory')

    paths = [arguments.examples / name for name in EXPECTED]
    if arguments.all:
        others = sorted(p for p in arguments.examples.rglob('*')
                        if p.suffix in ('.slugsin', '.structuredslugs') and p.name not in EXPECTED)
        paths += others
    print('R = realizable, U = unrealizable; cells are expected/ours (expected: slugs documentation,'
          ' or the slugs executable when given); times in seconds')
    print(f'{"example":58} {"vars":>4} {"standard":>9} {"robotics":>9} {"t_std":>8} {"t_rob":>8}'
          + (f' {"oracle":>7}' if arguments.oracle else '')
          + (f' {"slugs":>5} {"t_slugs":>8} {"t_slugs_r":>8}' if arguments.slugs else ''))
    mismatches = 0
    for path in paths:
        if not path.exists():
            print(f'{path.name:58} missing')
            mismatches += 1
            continue
        row, agrees = run(path, EXPECTED.get(path.name), arguments.oracle, arguments.slugs)
        print(row, flush=True)
        mismatches += not agrees
    print(f'{mismatches} mismatch(es)')
    return 1 if mismatches else 0


if __name__ == '__main__':
    sys.exit(main())
