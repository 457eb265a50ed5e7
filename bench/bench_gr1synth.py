"""Benchmark of the ``gr1synth`` command as a slugs drop-in (issue 14): start-up, large files.

    python bench/bench_gr1synth.py              # everything (+ slugs' column if on PATH)
    python bench/bench_gr1synth.py --size-mb 2  # smaller generated files

Figures (results/gr1synth.md):
- start-up: wall and CPU seconds of ``gr1synth --help`` (best of 10 fresh processes);
- parsing (CPU seconds and peak RSS of ``respec.parsing`` in a fresh process) of files of
  ``--size-mb`` MB: a compiled task (the chain family of bench_synthesizer.py with as many
  actions as fill the size, as structuredslugs and as slugsin: what a large generated
  specification looks like), and random formulas where no two lines share a shape (the worst
  case: every line is read on its own), in both syntaxes;
- whole runs, verdict only (slugs' default, no ``--explicitStrategy``): ``gr1synth`` and, when a
  ``slugs`` executable is on PATH, slugs on the same slugsin files (CPU seconds, peak RSS).
"""

from __future__ import annotations

import argparse
import json
import os
import random
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / 'bench' / 'results'
sys.path.insert(0, str(ROOT))

GR1SYNTH = Path(sys.executable).parent / 'gr1synth'
TIMEOUT_SECONDS = 150
INPUTS = 1000


def random_formula(rng: random.Random, names: list[str], depth: int, allow_next: bool) -> str:
    """An infix formula over ``names`` of nesting ``depth`` (structured slugs syntax)."""
    if depth == 0:
        name = rng.choice(names)
        if allow_next and rng.random() < 0.3:
            name = f'next({name})'
        return f'!{name}' if rng.random() < 0.3 else name
    operator = rng.choice(['&', '|', '->', '<->', '&', '|'])
    left = random_formula(rng, names, depth - 1 - rng.randrange(2) * (depth > 1), allow_next)
    right = random_formula(rng, names, depth - 1, allow_next)
    return f'({left} {operator} {right})'


def generated_spec(size_bytes: int, seed: int = 1) -> str:
    """A structuredslugs text of about ``size_bytes``: env safety over inputs, one system safety
    line per output of the form ``condition -> (y' <-> formula)`` (so each line is satisfiable
    whatever the others say), one liveness goal each."""
    rng = random.Random(seed)
    inputs = [f'sensor{i}' for i in range(INPUTS)]
    lines_env, lines_sys, outputs = [], [], []
    size = 0
    while size < size_bytes:
        index = len(outputs)
        output = f'act{index}'
        outputs.append(output)
        condition = random_formula(rng, inputs, rng.randrange(2, 5), allow_next=True)
        value = random_formula(rng, inputs + outputs[:-1], rng.randrange(1, 4), allow_next=False)
        lines_sys.append(f"{condition} -> (next({output}) <-> {value})")
        if index % 4 == 0:
            lines_env.append(random_formula(rng, inputs, rng.randrange(1, 3), allow_next=False)
                             + f' | next({rng.choice(inputs)})')
        size += len(lines_sys[-1]) + (len(lines_env[-1]) if index % 4 == 0 else 0) + 2
    return '\n'.join(['[INPUT]', *inputs, '', '[OUTPUT]', *outputs, '', '[ENV_TRANS]', *lines_env, '',
                      '[SYS_TRANS]', *lines_sys, '', '[ENV_LIVENESS]', inputs[0], '',
                      '[SYS_LIVENESS]', outputs[0], ''])


# Runs a command and prints its own rusage last. The benchmark launches commands through this
# small interpreter because a child's peak RSS counts the memory of the process that spawned
# it (Linux keeps the larger of the old and new images at exec), and the benchmark holds
# megabytes of generated specifications.
_RUSAGE_WRAPPER = """
import json, os, sys
pid = os.fork()
if pid == 0:
    os.execvp(sys.argv[1], sys.argv[1:])
_, status, usage = os.wait4(pid, 0)
sys.stdout.flush()
print('@@rusage', json.dumps([os.waitstatus_to_exitcode(status), usage.ru_utime + usage.ru_stime,
                              usage.ru_maxrss]), flush=True)
"""


def run_measured(command: list[str], timeout: float = TIMEOUT_SECONDS) -> dict:
    """Run ``command`` in a fresh process: its own CPU seconds and peak RSS, wall seconds, exit
    code and output; ``{'timeout': True}`` if it runs longer than ``timeout``."""
    started = time.perf_counter()
    process = subprocess.Popen([sys.executable, '-S', '-c', _RUSAGE_WRAPPER, *map(str, command)],
                               stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                               start_new_session=True)
    try:
        text, _ = process.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        os.killpg(process.pid, signal.SIGKILL)  # the wrapper and the command it runs
        process.communicate()
        return {'timeout': True}
    output, _, usage = text.rpartition('@@rusage ')
    exit_code, cpu_seconds, peak_rss_kb = json.loads(usage.splitlines()[0])
    return {'cpu_seconds': cpu_seconds, 'peak_rss_mb': peak_rss_kb / 1024,
            'wall_seconds': time.perf_counter() - started, 'exit_code': exit_code, 'output': output}


def startup(repeats: int = 10) -> dict:
    walls = []
    for _ in range(repeats):
        started = time.perf_counter()
        subprocess.run([str(GR1SYNTH), '--help'], capture_output=True, check=True)
        walls.append(time.perf_counter() - started)
    cpus = [run_measured([GR1SYNTH, '--help'])['cpu_seconds'] for _ in range(repeats)]
    return {'wall_seconds': min(walls), 'cpu_seconds': min(cpus)}


def parse_child(path: str) -> dict:
    """Parse one file in this process (the child side of ``parse``)."""
    from respec.parsing import parse_slugsin, parse_structuredslugs
    text = Path(path).read_text()
    parse_file = parse_slugsin if path.endswith('.slugsin') else parse_structuredslugs
    started = time.process_time()
    spec = parse_file(text, Path(path).name)
    cpu = time.process_time() - started
    return {'cpu_seconds': cpu, 'lines': sum(len(getattr(spec, section)) for section in (
        'env_init', 'sys_init', 'env_trans', 'sys_trans', 'env_liveness', 'sys_liveness'))}


def parse(path: Path) -> dict:
    run = run_measured([sys.executable, __file__, '--parse-child', str(path)])
    if run.get('timeout') or run['exit_code'] != 0:
        raise RuntimeError(f'parsing {path.name} failed: {run}')
    return {**json.loads(run['output'].strip().splitlines()[-1]), 'peak_rss_mb': run['peak_rss_mb']}


def whole_run(command: list[str]) -> dict:
    run = run_measured(command)
    if not run.get('timeout'):
        run['verdict'] = _verdict(run.pop('output'))
    return run


def _verdict(output: str) -> str:
    text = output.upper()
    if 'UNREALIZABLE' in text:
        return 'unrealizable'
    return 'realizable' if 'REALIZABLE' in text else ''


def _cell(run: dict) -> str:
    if run.get('timeout'):
        return f'> {TIMEOUT_SECONDS} s'
    return f"{run['cpu_seconds']:.2f} s / {run['peak_rss_mb']:.0f} MB, {run['verdict'] or 'exit %d' % run['exit_code']}"


def chain_task_text(size_bytes: int) -> str:
    """The chain family's compiled task with enough actions to fill about ``size_bytes``."""
    from bench_synthesizer import chain_spec
    actions = max(4, size_bytes // 510)  # ~510 bytes of structuredslugs per action
    return chain_spec(actions).to_structuredslugs()


WHOLE_RUNS = [
    ('from stand_prep: pregrasp, grasp_object (ATLAS)', 'paper', (['stand_prep'], ['pregrasp', 'grasp_object'])),
    ('4 goals from stand_prep, ordered (ATLAS)', 'paper',
     (['stand_prep'], ['look_down', 'approach_object', 'pregrasp', 'grasp_object'])),
    ('chain family N=16', 'chain', 16),
]


def whole_run_specs() -> list[tuple[str, str]]:
    from bench_synthesizer import chain_spec, paper_spec
    return [(label, (chain_spec(argument) if kind == 'chain' else paper_spec(*argument)).to_slugsin())
            for label, kind, argument in WHOLE_RUNS]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--parse-child', help=argparse.SUPPRESS)
    parser.add_argument('--size-mb', type=float, default=10.0)
    args = parser.parse_args(argv)
    if args.parse_child:
        print(json.dumps(parse_child(args.parse_child)))
        return 0
    sys.path.insert(0, str(ROOT / 'bench'))
    from respec.parsing import parse_structuredslugs
    slugs = shutil.which('slugs')
    lines = ['# gr1synth as a slugs drop-in', '',
             f'Machine: {os.cpu_count()} cores, Python {sys.version.split()[0]}.', '']
    start = startup()
    lines += [f"`gr1synth --help`: {start['wall_seconds'] * 1000:.0f} ms wall, "
              f"{start['cpu_seconds'] * 1000:.0f} ms CPU (best of 10 fresh processes).", '',
              '| file | size | formulas | parse CPU (s) | peak RSS (MB) |', '|---|---|---|---|---|']
    print(lines[4], flush=True)
    size = int(args.size_mb * 2**20)
    with tempfile.TemporaryDirectory() as directory:
        files = {}
        task = chain_task_text(size)
        files['compiled task (chain family), structuredslugs'] = ('task.structuredslugs', task)
        files['compiled task (chain family), slugsin'] = (
            'task.slugsin', parse_structuredslugs(task).to_slugsin())
        random_text = generated_spec(size)
        files['random formulas, no shape repeated, structuredslugs'] = ('random.structuredslugs', random_text)
        files['random formulas, no shape repeated, slugsin'] = (
            'random.slugsin', parse_structuredslugs(random_text).to_slugsin())
        for label, (name, text) in files.items():
            path = Path(directory) / name
            path.write_text(text)
            parsed = parse(path)
            lines.append(f"| {label} | {path.stat().st_size / 2**20:.1f} MB | {parsed['lines']} | "
                         f"{parsed['cpu_seconds']:.2f} | {parsed['peak_rss_mb']:.0f} |")
            print(lines[-1], flush=True)
        lines += ['', 'Whole runs, verdict only, CPU seconds / peak RSS (fresh process each):', '',
                  '| specification | gr1synth | ' + ('slugs |' if slugs else ''),
                  '|---|---|' + ('---|' if slugs else '')]
        for label, text in whole_run_specs():
            path = Path(directory) / 'whole.slugsin'
            path.write_text(text)
            cells = [_cell(whole_run([str(GR1SYNTH), str(path)]))]
            if slugs:
                cells.append(_cell(whole_run([slugs, str(path)])))
            lines.append(f'| {label} | ' + ' | '.join(cells) + ' |')
            print(lines[-1], flush=True)
    RESULTS.mkdir(parents=True, exist_ok=True)
    (RESULTS / 'gr1synth.md').write_text('\n'.join(lines) + '\n')
    print('\n'.join(lines))
    return 0


if __name__ == '__main__':
    sys.exit(main())
