"""Start-up cost of gr1synth and of the pipeline (issue 44): CPU seconds (user + system) of fresh
processes, the median of ``--repeats`` runs, optionally beside older code run back to back.

    nice -n 19 python bench/bench_startup.py [--slugs /tmp/slugs/src/slugs] [--old TREE] [--repeats 7]

``--old TREE``: a copy of older code (``git archive COMMIT | tar -x -C TREE``, its bytecode
compiled), run with this venv by ``PYTHONPATH=TREE``; every row then runs the old and the new
code in turn, each run of one beside the same run of the other. Both run as
``python -m ltl_synthesizer`` with ``PYTHONPATH`` set to their tree and a neutral working
directory; "gr1synth" is the console script of this venv (the product, this tree).

Sections, printed as markdown:

- floors: the interpreter without and with the venv's ``.pth`` hooks (the editable install's
  finder, the ROS wheels' bootstrap), and started as from a shell (the bootstrap then starts
  the interpreter a second time to set ``LD_LIBRARY_PATH``), and the import of dd.cudd;
- specifications: the verdict (``--sysInitRoboticsSemantics``) on tiny specifications, small
  per-cell gridworlds and capability robots of 10 and 20 capabilities, ours against slugs;
- pipeline: ``bench/pipeline_child.py`` (the pipeline of the request in one fresh process)
  against ``gr1synth --sysInitRoboticsSemantics --explicitStrategy --jsonOutput`` on the same
  compiled file, and their ratio;
- warm: the same two answered again in one process (a long-running server's cost).

CPU time counts the work of a process wherever it ran, so it is far less sensitive to the load
of a shared machine than wall time; it is not insensitive (caches, frequency).
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT), str(ROOT / 'bench')]

import capability_robots
from bench_tiny_specs import SPECS
from pipeline_child import warm_synthesis_script

PYTHON = sys.executable
GR1SYNTH = str(Path(PYTHON).with_name('gr1synth'))
SHAPES = list(capability_robots.SHAPES)
SIZES = (10, 20)
GRIDS = ((5, 4), (7, 5))
VERDICT = ['--sysInitRoboticsSemantics']
STRATEGY = ['--sysInitRoboticsSemantics', '--explicitStrategy', '--jsonOutput']


def cpu_seconds(command: list[str], tree: str | None = None, env: dict | None = None, cwd: str = '/') -> float:
    """CPU seconds of ``command`` and its children (``tree``: on PYTHONPATH)."""
    env = dict(os.environ if env is None else env)
    if tree:
        env['PYTHONPATH'] = tree
    process = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, env=env, cwd=cwd)
    errors = process.stderr.read()
    _, status, usage = os.wait4(process.pid, 0)
    if status:
        raise RuntimeError(f'{command} failed: {errors[-400:]!r}')
    return usage.ru_utime + usage.ru_stime


def medians(commands: dict[str, tuple], repeats: int) -> dict[str, float]:
    """The median CPU seconds of each command, the commands run in turn ``repeats`` times."""
    seconds: dict[str, list[float]] = {label: [] for label in commands}
    for _ in range(repeats):
        for label, (command, tree, env) in commands.items():
            seconds[label].append(cpu_seconds(command, tree, env))
    return {label: statistics.median(values) for label, values in seconds.items()}


def shell_environment() -> dict:
    """The environment of a shell that has not run the ROS wheels' bootstrap (this process has:
    its children inherit the result and are started once)."""
    return {key: value for key, value in os.environ.items()
            if key not in ('_ROS_WHEELS_BOOTSTRAP_COMPLETE', 'LD_LIBRARY_PATH')}


def floors(args) -> list[str]:
    commands = {
        '`python -S -c pass` (no site: no .pth hooks)': ([PYTHON, '-S', '-c', 'pass'], None, None),
        '`python -c pass` (the venv\'s .pth hooks)': ([PYTHON, '-c', 'pass'], None, None),
        '`python -c pass` from a shell (the ROS wheels\' bootstrap starts it twice)':
            ([PYTHON, '-c', 'pass'], None, shell_environment()),
        '`python -c "import dd.cudd"`': ([PYTHON, '-c', 'import dd.cudd'], None, None),
        '`python -c "import ltl_synthesizer.cudd_import"`':
            ([PYTHON, '-c', 'import ltl_synthesizer.cudd_import'], str(ROOT), None),
    }
    if args.old:
        commands['`python -c "import ltl_synthesizer.cudd_import"`, old'] = (
            [PYTHON, '-c', 'import ltl_synthesizer.cudd_import'], args.old, None)
    found = medians(commands, args.repeats * 3)
    return ['| process | CPU (ms) |', '|---|---|'] + [f'| {label} | {seconds * 1000:.1f} |'
                                                     for label, seconds in found.items()]


def specification_files(directory: Path) -> dict[str, Path]:
    from ltl_specification import compile_task
    from respec.parsing import parse_structuredslugs
    from respec.robot import robot_system
    files = {}
    for label, text in SPECS.items():
        files[label] = directory / f'tiny{len(files)}.slugsin'
        files[label].write_text(parse_structuredslugs(text, filename='t.structuredslugs').to_slugsin())
    for width, height in GRIDS:
        for realizable in (True, False):
            label = f"per-cell gridworld {width}x{height} ({'realizable' if realizable else 'unrealizable'})"
            files[label] = directory / f'grid{len(files)}.slugsin'
            files[label].write_text(capability_robots.per_cell_gridworld(width, height, 8, realizable))
    for shape in SHAPES:
        for size in SIZES:
            robot = capability_robots.SHAPES[shape](size)
            robot.write(directory)
            spec = compile_task(robot_system(robot.name, str(directory)), robot.initial_conditions, robot.goals,
                                sm_outcomes=capability_robots.REQUEST_OUTCOMES,
                                state_library=capability_robots.STATE_LIBRARY)
            files[f'{shape} N={size}'] = directory / f'{robot.name}.slugsin'
            files[f'{shape} N={size}'].write_text(spec.to_slugsin())
    return files


def specifications(args, files: dict[str, Path], labels: list[str]) -> list[str]:
    header = '| specification | gr1synth | python -m ltl_synthesizer |'
    if args.old:
        header += ' old: python -m ltl_synthesizer |'
    if args.slugs:
        header += ' slugs | ours / slugs |'
    lines = [header, '|' + '---|' * header.count(' |')]
    print('\n'.join(lines), flush=True)
    for label in labels:
        path = str(files[label])
        commands = {'gr1synth': ([GR1SYNTH, *VERDICT, path], None, None),
                    'module': ([PYTHON, '-m', 'ltl_synthesizer', *VERDICT, path], str(ROOT), None)}
        if args.old:
            commands['old'] = ([PYTHON, '-m', 'ltl_synthesizer', *VERDICT, path], args.old, None)
        if args.slugs:
            commands['slugs'] = ([args.slugs, *VERDICT, path], None, None)
        found = medians(commands, args.repeats)
        row = f"| {label} | {found['gr1synth'] * 1000:.0f} | {found['module'] * 1000:.0f} |"
        if args.old:
            row += f" {found['old'] * 1000:.0f} |"
        if args.slugs:
            row += f" {found['slugs'] * 1000:.0f} | {found['gr1synth'] / found['slugs']:.2f} |"
        print(row, flush=True)
        lines.append(row)
    return lines


def pipeline(args, files: dict[str, Path], directory: Path) -> list[str]:
    trees = {'new': str(ROOT)} | ({'old': args.old} if args.old else {})
    header = '| task | ' + ' | '.join(f'{name}: pipeline / gr1synth + strategy (ms) | {name} ratio'
                                      for name in trees) + ' |'
    lines = [header, '|' + '---|' * (1 + 2 * len(trees))]
    print('\n'.join(lines), flush=True)
    for shape in SHAPES:
        for size in SIZES:
            label = f'{shape} N={size}'
            commands = {}
            for name, tree in trees.items():
                child = Path(tree) / 'bench' / 'pipeline_child.py'
                commands[f'{name} pipeline'] = (
                    [PYTHON, str(child), str(directory), shape, str(size), str(directory / f'{name}-pipeline.slugsin')],
                    tree, None)
                commands[f'{name} synthesis'] = (
                    [PYTHON, '-m', 'ltl_synthesizer', *STRATEGY, str(files[label]), os.devnull], tree, None)
            found = medians(commands, args.repeats)
            row = f'| {label} | ' + ' | '.join(
                f"{found[f'{name} pipeline'] * 1000:.0f} / {found[f'{name} synthesis'] * 1000:.0f} | "
                f"{found[f'{name} pipeline'] / found[f'{name} synthesis']:.2f}" for name in trees) + ' |'
            print(row, flush=True)
            lines.append(row)
    return lines


_WARM_PIPELINE = '''
import sys, time
sys.path[:0] = [sys.argv[1] + '/bench']
from pipeline_child import pipeline_child
pipeline_child(sys.argv[2], sys.argv[3], int(sys.argv[4]), sys.argv[5], 3, clock=time.process_time)
'''


def warm(args, files: dict[str, Path], directory: Path) -> list[str]:
    """CPU seconds of a request answered again in one process (its imports done, as in a
    long-running server): the faster of the second and third answers, of the pipeline and of
    gr1synth + strategy (the resident mode's answer), and their ratio."""
    lines = ['| task | warm: pipeline / gr1synth + strategy (ms CPU) | warm ratio |', '|---|---|---|']
    print('\n'.join(lines), flush=True)
    for shape in SHAPES:
        for size in SIZES:
            label = f'{shape} N={size}'
            found = {}
            for name, command in (
                    ('pipeline', [PYTHON, '-c', _WARM_PIPELINE, str(ROOT), str(directory), shape, str(size),
                                  str(directory / 'warm.slugsin')]),
                    ('synthesis', [PYTHON, '-c', warm_synthesis_script('process_time'), *STRATEGY, str(files[label]), os.devnull])):
                runs = []
                for _ in range(args.repeats):
                    done = subprocess.run(command, capture_output=True, text=True, check=True, cwd=str(ROOT))
                    runs.append(json.loads(done.stdout.strip().splitlines()[-1])['warm_seconds'])
                found[name] = statistics.median(runs)
            row = (f"| {label} | {found['pipeline'] * 1000:.1f} / {found['synthesis'] * 1000:.1f} | "
                   f"{found['pipeline'] / found['synthesis']:.2f} |")
            print(row, flush=True)
            lines.append(row)
    return lines


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--slugs', help='slugs executable (compared when given)')
    parser.add_argument('--old', help='a tree of older code to run beside this one')
    parser.add_argument('--repeats', type=int, default=7)
    parser.add_argument('--sections', default='floors,specifications,pipeline,warm')
    parser.add_argument('--only', default='', help='specification labels to run (comma-separated prefixes)')
    args = parser.parse_args(argv)
    if args.old and not (Path(args.old) / 'bench' / 'pipeline_child.py').exists():
        parser.error(f'{args.old}/bench/pipeline_child.py is missing: copy this one there (the same '
                     'pipeline, measured without the harness of bench_capability_scale.py)')
    sections = args.sections.split(',')
    with open('/proc/loadavg') as load:
        print(f'load average before: {load.read().split()[:3]}')
    with tempfile.TemporaryDirectory() as folder:
        directory = Path(folder)
        files = specification_files(directory)
        if 'floors' in sections:
            print('\n'.join(floors(args)), flush=True)
        if 'specifications' in sections:
            labels = [label for label in files if not args.only
                      or any(label.startswith(prefix) for prefix in args.only.split(','))]
            specifications(args, files, labels)
        if 'pipeline' in sections:
            pipeline(args, files, directory)
        if 'warm' in sections:
            warm(args, files, directory)
    with open('/proc/loadavg') as load:
        print(f'load average after: {load.read().split()[:3]}')
    return 0


if __name__ == '__main__':
    sys.exit(main())
