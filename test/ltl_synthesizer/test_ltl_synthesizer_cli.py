"""The gr1synth command line, run as a subprocess the way tools that wrap slugs run it."""

import json
import os
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

REPOSITORY = Path(__file__).resolve().parents[2]

REALIZABLE = """[INPUT]
x

[OUTPUT]
y

[ENV_INIT]
!x

[SYS_INIT]
!y

[SYS_TRANS]
next(y) <-> next(x)

[ENV_LIVENESS]
x

[SYS_LIVENESS]
y
"""

UNREALIZABLE = """[INPUT]
x

[OUTPUT]
y

[SYS_LIVENESS]
x
"""


def gr1synth(*arguments):
    return subprocess.run([sys.executable, '-m', 'ltl_synthesizer', *map(str, arguments)],
                          capture_output=True, text=True, cwd=REPOSITORY, timeout=120)


def write(tmp_path, name, text):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_realizable_writes_the_json_strategy_like_slugs(tmp_path):
    source = write(tmp_path, 'copy.structuredslugs', REALIZABLE)
    output = tmp_path / 'copy.json'
    done = gr1synth('--explicitStrategy', '--jsonOutput', '--sysInitRoboticsSemantics', source, output)
    assert done.returncode == 0
    assert done.stderr.splitlines()[0] == 'RESULT: Specification is realizable.'
    strategy = json.loads(output.read_text())
    assert strategy['variables'] == ['x', 'y']
    assert strategy['nodes']['0'] == {'rank': 0, 'state': [0, 0], 'trans': [0, 1]}


def test_slugsin_input_and_strategy_on_stdout(tmp_path):
    source = write(tmp_path, 'copy.structuredslugs', REALIZABLE)
    converted = tmp_path / 'copy.slugsin'
    assert gr1synth('--convert', source, converted).returncode == 0
    assert "! ^ y' x'" in converted.read_text()
    done = gr1synth('--explicitStrategy', '--jsonOutput', converted)
    assert done.returncode == 0 and 'RESULT: Specification is realizable.' in done.stderr
    assert json.loads(done.stdout)['nodes']['1']['state'] == [1, 1]
    text = gr1synth('--explicitStrategy', converted)
    assert 'State 0 with rank 0 -> <x:0, y:0>\n\tWith successors : 0, 1' in text.stdout


def test_unrealizable_exits_zero_and_explains_only_when_asked(tmp_path):
    source = write(tmp_path, 'block.structuredslugs', UNREALIZABLE)
    done = gr1synth('--explicitStrategy', '--jsonOutput', '--explain', source, tmp_path / 'out.json')
    assert done.returncode == 0
    assert done.stderr.splitlines()[0] == 'RESULT: Specification is unrealizable.'
    assert "system liveness #0 'x'" in done.stderr
    assert not (tmp_path / 'out.json').exists()
    # As slugs: without --explain, just the verdict.
    done = gr1synth('--explicitStrategy', '--jsonOutput', source, tmp_path / 'out.json')
    assert done.returncode == 0 and done.stderr == 'RESULT: Specification is unrealizable.\n'


def test_without_explicit_strategy_only_the_verdict(tmp_path):
    source = write(tmp_path, 'copy.structuredslugs', REALIZABLE)
    done = gr1synth(source)
    assert done.returncode == 0 and done.stdout == ''
    assert done.stderr == 'RESULT: Specification is realizable.\n'
    # As slugs (issue 24): an output file name without --explicitStrategy is refused.
    done = gr1synth(source, tmp_path / 'out.json')
    assert done.returncode == 1 and 'RESULT' not in done.stderr
    assert '--explicitStrategy' in done.stderr
    assert not (tmp_path / 'out.json').exists()


def test_counterstrategy_output(tmp_path):
    source = write(tmp_path, 'block.structuredslugs', UNREALIZABLE)
    done = gr1synth('--counterStrategy', '--jsonOutput', source)
    counter = json.loads(done.stdout)
    assert counter['nodes']['0']['rank'] == [0, 0]


@pytest.mark.parametrize('name, text, location', [
    ('bad.structuredslugs', '[INPUT]\nx\n[OUTPUT]\ny\n[SYS_TRANS]\nnext(y) & | x\n', ':6:11:'),
    ('bad.slugsin', '[INPUT]\nx\n[OUTPUT]\ny\n[SYS_TRANS]\n& x\n', ':6:'),
    ('unknown.structuredslugs', '[INPUT]\nx\n[OUTPUT]\ny\n[SYS_LIVENESS]\nz\n', ':6:1:'),
])
def test_malformed_file_names_the_place_and_token(tmp_path, name, text, location):
    source = write(tmp_path, name, text)
    done = gr1synth(source)
    assert done.returncode == 1  # as slugs
    assert done.stderr.startswith('gr1synth: error: ') and str(source) + location in done.stderr
    assert 'RESULT' not in done.stderr


def test_missing_file_and_unknown_extension(tmp_path):
    assert gr1synth(tmp_path / 'nothing.slugsin').returncode == 1
    done = gr1synth(write(tmp_path, 'spec.txt', REALIZABLE))
    assert done.returncode == 1 and 'expected .slugsin or .structuredslugs' in done.stderr


@pytest.mark.parametrize('name, formula', [
    ('deep.structuredslugs', '(' * 10_000 + 'x' + ')' * 10_000),
    ('alternating.structuredslugs', '(x & (y | ' * 5_000 + 'x' + '))' * 5_000),
    ('deep.slugsin', '| x & y ' * 5_000 + 'x'),
])
def test_formulas_nested_10000_deep_are_synthesized(tmp_path, name, formula):
    if name.endswith('.slugsin'):
        text = f'[INPUT]\nx\n\n[OUTPUT]\ny\n\n[SYS_LIVENESS]\n{formula}\n'
    else:
        text = f'[INPUT]\nx\n\n[OUTPUT]\ny\n\n[SYS_TRANS]\n{formula} | TRUE\n'
    done = gr1synth('--explicitStrategy', write(tmp_path, name, text))
    assert done.returncode == 0, done.stderr
    assert done.stderr.startswith('RESULT: Specification is ')


# 100 inputs and 100 outputs that nothing constrains: solving is instant, but there are 2**200
# initial states to enumerate (the reproducer of issue 15: the time limit used to be ignored).
RUNAWAY = ('[INPUT]\n' + '\n'.join(f'x{i}' for i in range(100)) + '\n\n[OUTPUT]\n'
           + '\n'.join(f'y{i}' for i in range(100)) + '\n\n[SYS_LIVENESS]\ny0\n')


@pytest.mark.slow
def test_the_time_limit_stops_a_runaway_strategy_extraction(tmp_path):
    started = time.monotonic()
    done = gr1synth('--explicitStrategy', '--timeout', '2', write(tmp_path, 'runaway.structuredslugs', RUNAWAY))
    assert done.returncode == 3 and 'synthesis timeout' in done.stderr
    assert time.monotonic() - started < 2 + 10  # interpreter start-up on a loaded machine included
    # Without --explicitStrategy there is nothing to enumerate: the verdict comes at once.
    done = gr1synth('--timeout', '60', write(tmp_path, 'runaway.structuredslugs', RUNAWAY))
    assert done.returncode == 0 and 'realizable' in done.stderr


# --- hostile limits and inputs (issue 25) ----------------------------------------------------

@pytest.mark.parametrize('option', ['--timeout', '--memory-limit'])
@pytest.mark.parametrize('value', ['nan', 'inf', '-inf', '-1', 'soon'])
def test_limits_that_are_no_limits_are_refused(tmp_path, option, value):
    done = gr1synth(f'{option}={value}', write(tmp_path, 'spec.structuredslugs', RUNAWAY))
    assert done.returncode == 2 and option in done.stderr and 'finite number >= 0' in done.stderr
    assert 'Traceback' not in done.stderr


def test_the_memory_limit_hit_while_parsing_exits_with_4(tmp_path):
    # 200,000 lines of formulas: parsing alone grows the process well beyond 1 MB.
    text = '[INPUT]\nx\n\n[OUTPUT]\ny\n\n[SYS_TRANS]\n' + '(x | y) & (!x | next(y))\n' * 200_000
    done = gr1synth('--memory-limit', '1', write(tmp_path, 'big.structuredslugs', text))
    assert done.returncode == 4, done.stderr[-2000:]
    assert 'memory' in done.stderr and 'Traceback' not in done.stderr


def peak_rss_of(command) -> tuple[int, str, int]:
    """(exit status, stderr, peak RSS in KiB) of ``command``, started by a small Python (a
    child forked from this process would count this process's size as its own peak)."""
    launcher = ('import resource, subprocess, sys; status = subprocess.run(sys.argv[1:]).returncode; '
                'print(status, resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)')
    done = subprocess.run([sys.executable, '-c', launcher, *command], capture_output=True, text=True,
                          cwd=REPOSITORY, timeout=120)
    status, peak_kib = map(int, done.stdout.split())
    return status, done.stderr, peak_kib


@pytest.mark.parametrize('fifo', [False, True])
def test_an_input_too_large_for_the_memory_limit_is_refused_before_it_is_read(tmp_path, fifo):
    """Issue 34, item 8: --memory-limit 200 peaked at 1,282 MiB reading a 192 MB input. A
    40 MB input at 64 MB: refused by its size (a file) or once 1/8 of the limit is read (a
    pipe), exit 4, the process never near the input's size."""
    line = '| a & b | ! a ' * 20 + 'b\n'
    text = '[INPUT]\na\n\n[OUTPUT]\nb\n\n[SYS_TRANS]\n' + line * (40_000_000 // len(line))
    path = tmp_path / 'big.slugsin'
    if fifo:
        os.mkfifo(path)

        def feed():
            try:
                with open(path, 'w') as stream:
                    stream.write(text)
            except BrokenPipeError:  # gr1synth stopped reading: expected
                pass
        writer = threading.Thread(target=feed, daemon=True)
        writer.start()
    else:
        path.write_text(text)
    started = time.monotonic()
    status, stderr, peak_kib = peak_rss_of([sys.executable, '-m', 'ltl_synthesizer', '--memory-limit', '64',
                                            str(path)])
    assert status == 4 and 'memory limit of 64 MB' in stderr and 'Traceback' not in stderr, stderr[-2000:]
    assert (f'{len(text):,} bytes' in stderr) is not fifo  # a file's size is named
    assert peak_kib < 64 * 1024  # the interpreter and 8 MB of text, never the 40 MB input parsed
    assert time.monotonic() - started < 10


def test_a_fifo_no_one_writes_to_ends_at_the_time_limit(tmp_path):
    fifo = tmp_path / 'input.structuredslugs'
    os.mkfifo(fifo)
    started = time.monotonic()
    done = gr1synth('--timeout', '1', fifo)
    assert done.returncode == 3 and 'timeout' in done.stderr and 'Traceback' not in done.stderr
    assert time.monotonic() - started < 1 + 10  # interpreter start-up on a loaded machine included


def test_formulas_nested_beyond_the_limit_are_malformed(tmp_path):
    from respec.nesting import MAX_FORMULA_NESTING
    depth = MAX_FORMULA_NESTING + 1
    text = '[INPUT]\n\n[OUTPUT]\nx\n\n[SYS_TRANS]\n' + '(' * depth + 'x' + ')' * depth + '\n'
    done = gr1synth(write(tmp_path, 'too_deep.structuredslugs', text))
    assert done.returncode == 1 and f'nested deeper than {MAX_FORMULA_NESTING}' in done.stderr
    assert 'Traceback' not in done.stderr and len(done.stderr) < 300


def test_plain_command_lines_parse_as_argparse_parses_them():
    # Switches then file names are parsed without argparse (making the parser costs more than a
    # tiny synthesis); every command line of up to three words from these parses to the same
    # Namespace (values and order), and anything else is left to argparse.
    import io
    from contextlib import redirect_stderr, redirect_stdout
    from itertools import product
    from ltl_synthesizer.command import SWITCHES, _parser, _plain_arguments
    words = [switch for switch, _ in SWITCHES] + ['--serve', 'in.slugsin', 'out.json', '', '-', '--',
                                                  '--explicit', '-h', '--timeout', '5', '--memory-limit=9']
    plain = 0
    for length in range(4):
        for argv in product(words, repeat=length):
            fast = _plain_arguments(list(argv))
            if fast is None:
                continue
            plain += 1
            with redirect_stderr(io.StringIO()), redirect_stdout(io.StringIO()):
                assert repr(fast) == repr(_parser().parse_args(list(argv))), argv
    assert plain > 1000
    assert _plain_arguments(['--sysInitRoboticsSemantics', '--explicitStrategy', '--jsonOutput', 'a', 'b'])
    assert _plain_arguments(['a', '--explicitStrategy']) is None  # a switch after a file: argparse's
    assert _plain_arguments(['--timeout', '5', 'a']) is None
