"""Hostile input costs little (issue 25, ROS-free part): YAML alias bombs and deep nesting in
request YAML, formulas nested beyond the one nesting limit, and the one quoting rule of every
message. The full attack sizes are in
bench/bench_reliability.py."""

import resource
import time

import pytest

from respec.vocabulary.errors import QUOTED_CHARACTERS, quoted
from respec.ltl import var
from respec.nesting import MAX_FORMULA_NESTING
from respec.parsing import ParseError, UnknownVariableError, parse_formula, parse_structuredslugs
from synthesis_manager.requests import MAX_YAML_DEPTH, InvalidRequestError, load_request_yaml, parse_synthesis_options

pytestmark = pytest.mark.ros


def alias_bomb(levels: int) -> str:
    """A few hundred bytes that yaml.safe_load expands to 9**levels strings."""
    lines = ['a0: &a0 [lol, lol, lol, lol, lol, lol, lol, lol, lol]']
    lines += [f'a{i}: &a{i} [' + ', '.join([f'*a{i - 1}'] * 9) + ']' for i in range(1, levels)]
    return '\n'.join(lines)


def peak_rss_mib() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def test_a_yaml_alias_bomb_is_refused_before_it_expands():
    bomb = alias_bomb(9)  # 9**9 = 387 million strings if expanded
    assert len(bomb) < 1000
    before, started = peak_rss_mib(), time.process_time()
    with pytest.raises(InvalidRequestError, match='aliases') as raised:
        parse_synthesis_options(bomb)
    assert time.process_time() - started < 1.0
    assert peak_rss_mib() - before < 50
    assert raised.value.code == 'INVALID_REQUEST' and raised.value.item == 'synthesis_options'
    assert len(str(raised.value)) < 200 and 'lol' not in str(raised.value)


def test_a_single_alias_is_refused_too():
    with pytest.raises(InvalidRequestError, match='aliases'):
        parse_synthesis_options('timeout: &t 3\nunordered_goals: *t')


@pytest.mark.parametrize('text', ['[' * 5000 + ']' * 5000, '{a: ' * 3000 + '1' + '}' * 3000,
                                  '\n'.join(' ' * level + 'a:' for level in range(200)) + ' 1'])
def test_deeply_nested_options_are_a_short_invalid_request(text):
    with pytest.raises(InvalidRequestError, match=f'deeper than {MAX_YAML_DEPTH}') as raised:
        parse_synthesis_options(text)
    assert len(str(raised.value)) < 100


def test_yaml_errors_quote_no_input():
    with pytest.raises(InvalidRequestError, match='not valid YAML') as raised:
        parse_synthesis_options('timeout: [' + 'x' * 10_000)
    assert 'x' * 50 not in str(raised.value) and len(str(raised.value)) < 200


@pytest.mark.parametrize('text', ['x' * 10_000 + ': 1', 'timeout: ' + '9' * 5000 + '.5e' + '9' * 3,
                                  'ltl_steps_only: ' + 'y' * 10_000])
def test_refused_option_values_are_quoted_by_their_start(text):
    with pytest.raises(InvalidRequestError) as raised:
        parse_synthesis_options(text)
    assert len(str(raised.value)) < 250


@pytest.mark.parametrize('value', ['a' * 100_000, ['a' * 100_000] * 1000, {'k' * 1000: list(range(10_000))},
                                   [[[[[['deep']]]]]] * 1000, b'b' * 100_000, 10 ** 4000])
def test_quoting_is_short_whatever_the_value(value):
    shown = quoted(value)
    assert len(shown) <= QUOTED_CHARACTERS + 5


def test_short_values_are_quoted_whole():
    assert quoted('look_down') == "'look_down'"
    assert quoted(['a', 'b']) == "['a', 'b']"


# --- deep nesting: one limit for every parser ------------------------------------------------

def in_deep_thread(function, *args):
    from respec.nesting import run_with_deep_stack
    return run_with_deep_stack(function, *args)


@pytest.mark.parametrize('syntax, formula', [
    ('infix', '(' * (MAX_FORMULA_NESTING + 1) + 'x' + ')' * (MAX_FORMULA_NESTING + 1)),
    ('infix', '!' * (MAX_FORMULA_NESTING + 1) + 'x'),
    ('infix', '!(' * (MAX_FORMULA_NESTING // 2 + 1) + 'x' + ')' * (MAX_FORMULA_NESTING // 2 + 1)),
    ('prefix', '! ' * (MAX_FORMULA_NESTING + 1) + 'x'),
    ('prefix', '| x & y ' * (MAX_FORMULA_NESTING // 2 + 1) + 'x'),
])
def test_formulas_nested_beyond_the_limit_are_invalid_formulas(syntax, formula):
    with pytest.raises(ParseError, match=f'nested deeper than {MAX_FORMULA_NESTING}') as raised:
        in_deep_thread(parse_formula, formula, syntax)
    assert raised.value.code == 'INVALID_FORMULA' and len(str(raised.value)) < 200


def test_formulas_nested_up_to_the_limit_are_read_in_files_too():
    deepest = '(' * MAX_FORMULA_NESTING + 'x' + ')' * MAX_FORMULA_NESTING
    spec = in_deep_thread(parse_structuredslugs, f'[OUTPUT]\nx\n\n[SYS_TRANS]\n{deepest}\n')
    assert spec.sys_trans == [var('x')]
    with pytest.raises(ParseError, match='nested deeper'):
        in_deep_thread(parse_structuredslugs, f'[OUTPUT]\nx\n\n[SYS_TRANS]\n!({deepest})\n')


def test_an_unknown_proposition_is_quoted_by_its_start():
    with pytest.raises(UnknownVariableError) as raised:
        parse_structuredslugs('[OUTPUT]\nx\n\n[SYS_TRANS]\n' + 'y' * 60_000 + '\n')
    assert raised.value.code == 'UNKNOWN_PROPOSITION' and len(str(raised.value)) < 250


def test_request_yaml_has_the_bounds_of_robot_files():
    bomb = 'l0: &l0 [x]\n' + ''.join(f'l{i}: &l{i} [{", ".join([f"*l{i - 1}"] * 10)}]\n' for i in range(1, 10))
    with pytest.raises(InvalidRequestError, match=r'synthesis_options: YAML aliases .* \(line 2, column 10\)'):
        load_request_yaml(bomb, 'synthesis_options')
    with pytest.raises(InvalidRequestError, match='synthesis_options: not valid YAML'):
        load_request_yaml('a: [', 'synthesis_options')
