"""Parsers for slugs' two specification formats and for LTLSpecification messages.

* ``.structuredslugs``: infix formulas (``parse_formula(text, 'infix')``).
* ``.slugsin``: prefix formulas (``parse_formula(text, 'prefix')``), including slugs'
  memory buffers ``$ n f0 ... fn-1`` and recalls ``? i``.

Every parser returns ``respec.ltl`` trees built with its constructors, so the result of
parsing printed text is the tree that was printed (``parse_formula(to_infix(f)) == f``).

Operator precedence follows slugs' structured grammar (tools/StructuredSlugsParser/grammar.wi),
tightest first: ``!`` and ``next``, then ``&``, ``|``, ``^``, ``->``, ``<->``. As in that
grammar every binary operator is LEFT associative, so ``a -> b -> c`` means ``(a -> b) -> c``
(the same file means the same thing to slugs and to us; our printer always parenthesizes).

Structured slugs' integer variables (``level: 3...107`` in [INPUT] / [OUTPUT]) are bit-blasted
as slugs' compiler does: bits ``level@0.3.107``, ``level@1``, ... hold ``value - low``, each
comparison (``= != < <= > >=`` over sums with ``+``) is expanded over the values involved, and
range limits are added to the owner's init and transition sections.

Section scopes follow slugs (src/synthesisContextBasics.cpp): [ENV_INIT] may mention only
current input variables, [SYS_INIT] only current variables, [ENV_TRANS] no next-step output.

Every error is a ``ParseError`` naming the file (or message section), line, column and the
offending token, e.g. ``spec.structuredslugs:7:12: unknown variable 'foo' near 'foo'``.
"""

from __future__ import annotations

import gc
import itertools
import re
from contextlib import contextmanager
from dataclasses import dataclass, field
from functools import lru_cache
from operator import itemgetter
from typing import NamedTuple

from respec.errors import CodedError
from respec.ltl import (
    FALSE, TRUE, And, Const, Formula, Iff, Implies, Next, Not, Or, Var, conj, disj, iff, implies,
    neg, next_, var,
)
from respec.spec import FORMULA_SECTIONS, PROPOSITION_SECTIONS, SLUGS_HEADERS, GR1Specification

__all__ = [
    'ParseError', 'UnknownVariableError', 'parse_formula', 'parse_structuredslugs',
    'parse_slugsin', 'spec_from_text_sections', 'IntegerVariable', 'xor',
]

_SECTION_OF_HEADER = {header: section for section, header in SLUGS_HEADERS.items()}
_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_.@]*")
_NUMBER = re.compile(r"[0-9]+")
_INTEGER_DECLARATION = re.compile(r"^([A-Za-z_][A-Za-z0-9_]*)\s*:\s*(-?[0-9]+)\s*\.\.\.\s*(-?[0-9]+)$")
_KEYWORDS = {'TRUE', 'FALSE', 'next'}


class ParseError(CodedError):
    """A syntax or naming error at ``filename:line:column``; ``item`` is the offending token."""

    code = 'INVALID_FORMULA'

    def __init__(self, problem: str, token: str, filename: str = '<string>', line: int = 1,
                 column: int = 1):
        self.problem = problem
        self.filename = filename
        self.line = line
        self.column = column
        self.token = token
        super().__init__(f'{filename}:{line}:{column}: {problem} near {token!r}', item=token)


class UnknownVariableError(ParseError):
    """A formula mentions a proposition that no [INPUT] / [OUTPUT] section declares."""

    code = 'UNKNOWN_PROPOSITION'


class _Token(NamedTuple):
    kind: str       # 'name', 'primed', 'number', 'op', 'TRUE', 'FALSE', 'next', 'end'
    text: str
    line: int
    column: int


@dataclass(frozen=True)
class _Source:
    """Where a formula's text comes from: for error positions."""

    filename: str = '<string>'
    line: int = 1
    column: int = 1

    def error(self, problem: str, token: str, line: int, column: int, kind=ParseError):
        # Positions inside the text are relative to its first character.
        absolute_column = column + self.column - 1 if line == 1 else column
        return kind(problem, token, self.filename, self.line + line - 1, absolute_column)


@dataclass(frozen=True)
class _Scope:
    """Which propositions a formula may use, and which of them in the next step."""

    names: frozenset[str] | None        # None: any name (parse_formula without declarations)
    current: frozenset[str] | None
    next_step: frozenset[str] | None
    section: str = ''
    integers: dict = field(default_factory=dict)   # name -> IntegerVariable (structured slugs)

    @property
    def both_steps(self) -> frozenset[str]:
        """The propositions allowed in the current and in the next step."""
        return self.current & self.next_step


_ANY = _Scope(None, None, None)


# --- infix (structured slugs) -------------------------------------------------------------

# Each spelling of an operator -> its canonical form.
_INFIX_OPERATORS = {
    '<-->': '<->', '<->': '<->', '-->': '->', '->': '->', '&&': '&', '||': '|',
    '/\\': '&', '\\/': '|', '&': '&', '|': '|', '^': '^', '!=': '!=', '!': '!',
    '~': '!', '(': '(', ')': ')',
    # Integer comparisons and addition (structured slugs' integer variables).
    '<=': '<=', '>=': '>=', '<': '<', '>': '>', '=': '=', '+': '+',
}
# One scanner for all tokens (longest operator spellings first); much faster than a
# character loop on large files.
_INFIX_TOKEN = re.compile(
    r"(?P<space>[^\S\n]+)|(?P<newline>\n)|(?P<comment>#[^\n]*)|(?P<number>[0-9]+)"
    r"|(?P<name>[A-Za-z_][A-Za-z0-9_.@]*)(?P<prime>')?"
    r"|(?P<op>" + '|'.join(re.escape(spelling) for spelling in
                           sorted(_INFIX_OPERATORS, key=len, reverse=True)) + r")"
    r"|(?P<bad>.)")
_COMPARATORS = {
    '=': lambda a, b: a == b, '!=': lambda a, b: a != b, '<': lambda a, b: a < b,
    '<=': lambda a, b: a <= b, '>': lambda a, b: a > b, '>=': lambda a, b: a >= b,
}
_MAX_EXPANSION = 1 << 16   # valuations enumerated to expand one integer comparison
# Binary operators by binding strength, loosest first (all left associative).
_BINARY_LEVEL = {'<->': 0, '->': 1, '^': 2, '|': 3, '&': 4}


def _infix_tokens(text: str, source: _Source) -> list[_Token]:
    tokens, line, line_start = [], 1, 0
    append = tokens.append
    for match in _INFIX_TOKEN.finditer(text):
        kind = match.lastgroup
        if kind == 'space' or kind == 'comment':
            continue
        if kind == 'newline':
            line, line_start = line + 1, match.end()
            continue
        column = match.start() - line_start + 1
        if kind == 'prime':  # a name followed by a prime: the last group that matched
            append(_Token('primed', match.group('name'), line, column))
        elif kind == 'name':
            word = match.group()
            append(_Token(word, word, line, column) if word in _KEYWORDS
                   else _Token('name', word, line, column))
        elif kind == 'op':
            append(_Token('op', _INFIX_OPERATORS[match.group()], line, column))
        elif kind == 'number':
            append(_Token('number', match.group(), line, column))
        else:
            raise source.error('unexpected character', match.group(), line, column)
    append(_Token('end', '', line, len(text) - line_start + 1))
    return tokens


class _InfixParser:
    """Recursive descent over slugs' precedence levels; one method per level."""

    def __init__(self, text: str, scope: _Scope, source: _Source):
        self.source = source
        self.scope = scope
        self.tokens = _infix_tokens(text, source)
        self.position = 0

    def parse(self) -> Formula:
        if self.peek().kind == 'end':
            raise self.error('empty formula', self.peek())
        formula = self.binary(0, in_next=False)
        if self.peek().kind != 'end':
            raise self.error('unexpected token after the formula', self.peek())
        return formula

    def peek(self) -> _Token:
        return self.tokens[self.position]

    def take(self) -> _Token:
        token = self.tokens[self.position]
        self.position += 1
        return token

    def error(self, problem: str, token: _Token, kind=ParseError) -> ParseError:
        text = token.text + ("'" if token.kind == 'primed' else '') if token.kind != 'end' else '<end>'
        return self.source.error(problem, text, token.line, token.column, kind)

    def binary(self, level: int, in_next: bool) -> Formula:
        """Operators binding at least as strongly as ``level`` (precedence climbing)."""
        left = self.unary(in_next)
        tokens = self.tokens
        while True:
            token = tokens[self.position]
            operator_level = _BINARY_LEVEL.get(token.text) if token.kind == 'op' else None
            if operator_level is None or operator_level < level:
                return left
            self.position += 1
            right = self.binary(operator_level + 1, in_next)  # left associative
            if token.text in ('&', '|'):
                # A run of the same associative operator becomes one node at once: combining
                # pairwise would copy the growing operand list at every step.
                operands = [left, right]
                while tokens[self.position].kind == 'op' and tokens[self.position].text == token.text:
                    self.position += 1
                    operands.append(self.binary(operator_level + 1, in_next))
                left = conj(operands) if token.text == '&' else disj(operands)
            else:
                left = _combine(token.text, left, right)

    def unary(self, in_next: bool) -> Formula:
        token = self.peek()
        if token.kind == 'op' and token.text == '!':
            self.take()
            return neg(self.unary(in_next))
        if token.kind == 'next':
            self.take()
            if in_next:
                raise self.error('nested next is not GR(1)', token)
            return next_(self.unary(in_next=True))
        return self.atom(in_next)

    def atom(self, in_next: bool) -> Formula:
        token = self.take()
        if self.scope.integers and (token.kind == 'number' or (
                token.kind in ('name', 'primed') and token.text in self.scope.integers)):
            self.position -= 1
            return self.comparison(in_next)
        if self.scope.integers and token.kind == 'op' and token.text == '(':
            # '(' opens either a Boolean formula or an integer sum; try the sum first.
            start = self.position - 1
            self.position = start
            try:
                return self.comparison(in_next)
            except ParseError:
                self.position = start + 1
        if token.kind in ('TRUE', 'FALSE'):
            return TRUE if token.kind == 'TRUE' else FALSE
        if token.kind == 'name':
            return self.variable(token, next_step=in_next)
        if token.kind == 'primed':
            if in_next:
                raise self.error('primed variable inside next() is a nested next', token)
            return next_(self.variable(token, next_step=True))
        if token.kind == 'op' and token.text == '(':
            inner = self.binary(0, in_next)
            closing = self.take()
            if not (closing.kind == 'op' and closing.text == ')'):
                raise self.error("expected ')'", closing)
            return inner
        if token.kind == 'end':
            raise self.error('formula ends too early', token)
        raise self.error('expected a variable, TRUE, FALSE, ! or (', token)

    def comparison(self, in_next: bool) -> Formula:
        """``sum comparator sum`` over integer variables, expanded to their bits."""
        left = self.sum(in_next)
        operator = self.take()
        if not (operator.kind == 'op' and operator.text in _COMPARATORS):
            raise self.error('expected a comparison operator (= != < <= > >=)', operator)
        right = self.sum(in_next)
        try:
            return compare(left, operator.text, right)
        except ValueError as error:
            raise self.error(str(error), operator) from None

    def sum(self, in_next: bool) -> list:
        terms = self.summand(in_next)
        while self.peek().kind == 'op' and self.peek().text == '+':
            self.take()
            terms = terms + self.summand(in_next)
        return terms

    def summand(self, in_next: bool) -> list:
        token = self.take()
        if token.kind == 'number':
            return [int(token.text)]
        if token.kind in ('name', 'primed') and token.text in self.scope.integers:
            if token.kind == 'primed' and in_next:
                raise self.error('primed variable inside next() is a nested next', token)
            next_step = in_next or token.kind == 'primed'
            integer = self.scope.integers[token.text]
            if integer.bits:
                problem = _scope_problem(self.scope, integer.bits[0], next_step)
                if problem:
                    raise self.error(problem.replace(repr(integer.bits[0]), repr(integer.name)), token)
            return [(integer, next_step)]
        if token.kind == 'op' and token.text == '(':
            terms = self.sum(in_next)
            closing = self.take()
            if not (closing.kind == 'op' and closing.text == ')'):
                raise self.error("expected ')'", closing)
            return terms
        raise self.error('expected an integer variable or a number', token)

    def variable(self, token: _Token, next_step: bool) -> Var:
        problem = _scope_problem(self.scope, token.text, next_step)
        if problem:
            kind = UnknownVariableError if problem.startswith('unknown') else ParseError
            raise self.error(problem, token, kind)
        return _var(token.text)


def _shared(wrapper, inner):
    """name -> ``wrapper(inner(name))``, one shared node per name: large specifications mention
    each proposition many times."""
    return lru_cache(maxsize=1 << 16)(lambda name: wrapper(inner(name)))


_var = lru_cache(maxsize=1 << 16)(var)
_not_var = _shared(Not, _var)
_next_var = _shared(Next, _var)
_next_not_var = _shared(Next, _not_var)
_not_next_var = _shared(Not, _next_var)


def _combine(operator: str, left: Formula, right: Formula) -> Formula:
    if operator == '&':
        return conj([left, right])
    if operator == '|':
        return disj([left, right])
    if operator == '->':
        return implies(left, right)
    if operator == '<->':
        return iff(left, right)
    return xor(left, right)


def xor(left: Formula, right: Formula) -> Formula:
    """Exclusive or, which respec.ltl spells as a negated biimplication."""
    return neg(iff(left, right))


@dataclass(frozen=True)
class IntegerVariable:
    """A structured-slugs integer ``name: low...high``, stored as slugs stores it: the bits of
    ``value - low``, least significant first, named ``name@0.low.high``, ``name@1``, ..."""

    name: str
    low: int
    high: int

    @property
    def bits(self) -> list[str]:
        count = 0
        while 2 ** count <= self.high - self.low:
            count += 1
        return [f'{self.name}@0.{self.low}.{self.high}' if k == 0 else f'{self.name}@{k}' for k in range(count)]

    def equals(self, value: int, next_step: bool) -> Formula:
        """The bits spelling ``value`` (which must lie in the range)."""
        offset = value - self.low
        literals = [var(bit) if offset >> k & 1 else neg(var(bit)) for k, bit in enumerate(self.bits)]
        return conj(next_(literal) if next_step else literal for literal in literals)

    def in_range(self, next_step: bool) -> Formula:
        """slugs' "variable limits" constraint; TRUE when every bit pattern is a value."""
        if 2 ** len(self.bits) == self.high - self.low + 1:
            return TRUE
        return compare([(self, next_step)], '<=', [self.high])


def compare(left: list, operator: str, right: list) -> Formula:
    """Expand ``sum(left) <operator> sum(right)`` to a disjunction over the valuations of the
    integer variables involved (terms: ints, or (IntegerVariable, next_step) pairs)."""
    unknowns = sorted({term for term in left + right if not isinstance(term, int)},
                      key=lambda term: (term[0].name, term[1]))
    ranges = [range(variable.low, variable.high + 1) for variable, _ in unknowns]
    size = 1
    for values in ranges:
        size *= len(values)
    if size > _MAX_EXPANSION:
        raise ValueError(f'integer comparison over {size} valuations is too large to expand')
    holds = _COMPARATORS[operator]
    cases = []
    for values in itertools.product(*ranges):
        value_of = dict(zip(unknowns, values))

        def total(terms):
            return sum(term if isinstance(term, int) else value_of[term] for term in terms)

        if holds(total(left), total(right)):
            cases.append(conj(variable.equals(value, next_step)
                              for (variable, next_step), value in value_of.items()))
    return disj(cases)


def _scope_problem(scope: _Scope, name: str, next_step: bool) -> str:
    if scope.names is None:
        return ''
    where = f' in {scope.section}' if scope.section else ''
    if name not in scope.names:
        return f'unknown variable {name!r}{where}'
    allowed = scope.next_step if next_step else scope.current
    if name not in allowed:
        step = 'next-step' if next_step else 'current'
        return f'{step} variable {name!r} is not allowed{where}'
    return ''


# --- prefix (slugsin) ---------------------------------------------------------------------

_PREFIX_TOKEN = re.compile(r'\S+')


class _PrefixParser:
    """slugsin prefix notation: ``! f``, ``& f g``, ``| f g``, ``^ f g``, ``1``, ``0``, ``x``, ``x'``,
    memory buffers ``$ n f0 ... fn-1`` (value: the last element) and recalls ``? i``."""

    def __init__(self, text: str, scope: _Scope, source: _Source):
        self.source = source
        self.scope = scope
        self.tokens = []
        for line_number, line in enumerate(text.split('\n'), start=1):
            line = line.split('#', 1)[0]
            self.tokens += [(m.group(), line_number, m.start() + 1) for m in _PREFIX_TOKEN.finditer(line)]
        self.position = 0
        self.end = (text.count('\n') + 1, len(text.rsplit('\n', 1)[-1]) + 1)

    def parse(self) -> Formula:
        if not self.tokens:
            raise self.source.error('empty formula', '<end>', *self.end)
        formula = self.formula(memory=None)
        if self.position < len(self.tokens):
            raise self.error('stray token after the formula', self.tokens[self.position])
        return formula

    def error(self, problem, token, kind=ParseError) -> ParseError:
        return self.source.error(problem, token[0], token[1], token[2], kind)

    def take(self):
        if self.position == len(self.tokens):
            raise self.source.error('formula ends too early', '<end>', *self.end)
        token = self.tokens[self.position]
        self.position += 1
        return token

    def number(self, after) -> int:
        token = self.take()
        if not token[0].isdigit():
            raise self.error(f"expected a number after {after[0]!r}", token)
        return int(token[0])

    def formula(self, memory: list[Formula] | None) -> Formula:
        token = self.take()
        text = token[0]
        if text == '!':
            return neg(self.formula(memory))
        if text == '^':
            left = self.formula(memory)
            return xor(left, self.formula(memory))
        if text in ('&', '|'):
            # "| a | b | c d": the right operands that repeat the operator are gathered into
            # one node (pairwise, each level would copy the flattened list below it).
            operands = [self.formula(memory)]
            while self.position < len(self.tokens) and self.tokens[self.position][0] == text:
                self.position += 1
                operands.append(self.formula(memory))
            operands.append(self.formula(memory))
            return conj(operands) if text == '&' else disj(operands)
        if text in ('1', '0'):
            return TRUE if text == '1' else FALSE
        if text == '$':
            size = self.number(token)
            if size == 0:
                raise self.error('a memory buffer needs at least one element', token)
            buffer: list[Formula] = []
            for _ in range(size):
                buffer.append(self.formula(buffer))
            return buffer[-1]
        if text == '?':
            index_token = self.tokens[self.position] if self.position < len(self.tokens) else token
            index = self.number(token)
            if memory is None or index >= len(memory):
                raise self.error(f'recall of memory element {index} that is not defined yet', index_token)
            return memory[index]
        primed = text.endswith("'")
        name = text[:-1] if primed else text
        if not _NAME.fullmatch(name) or name in _KEYWORDS:
            raise self.error('expected an operator (! & | ^ $ ?), 0, 1 or a variable', token)
        problem = _scope_problem(self.scope, name, primed)
        if problem:
            kind = UnknownVariableError if problem.startswith('unknown') else ParseError
            raise self.error(problem, token, kind)
        return next_(_var(name)) if primed else _var(name)


# --- public API ---------------------------------------------------------------------------

def parse_formula(text: str, syntax: str = 'infix') -> Formula:
    """Parse one formula: ``syntax`` is 'infix' (structured slugs) or 'prefix' (slugsin).

    Any variable name is accepted; specification parsers check names against declarations.
    """
    if not isinstance(text, str):
        raise ParseError('formula must be a string', repr(text))
    return _parse(text, syntax, _ANY, _Source())


def _parse(text: str, syntax: str, scope: _Scope, source: _Source) -> Formula:
    if syntax == 'infix':
        return _InfixParser(text, scope, source).parse()
    if syntax == 'prefix':
        return _PrefixParser(text, scope, source).parse()
    raise ValueError(f"unknown formula syntax {syntax!r} (expected 'infix' or 'prefix')")


def _scopes(env_props: list[str], sys_props: list[str], integers=None) -> dict[str, _Scope]:
    """slugs' rules for which variables each formula section may read (synthesisContextBasics.cpp)."""
    inputs, outputs = frozenset(env_props), frozenset(env_props) | frozenset(sys_props)
    nothing = frozenset()

    def scope(section, current, next_step):
        return _Scope(outputs, current, next_step, f'[{SLUGS_HEADERS[section]}]', integers or {})

    return {
        'env_init': scope('env_init', inputs, nothing),
        'sys_init': scope('sys_init', outputs, nothing),
        'env_trans': scope('env_trans', outputs, inputs),
        'sys_trans': scope('sys_trans', outputs, outputs),
        'env_liveness': scope('env_liveness', outputs, outputs),
        'sys_liveness': scope('sys_liveness', outputs, outputs),
    }


def parse_structuredslugs(text: str, filename: str = '<string>', check=None) -> GR1Specification:
    """Parse a ``.structuredslugs`` file: one infix conjunct per non-empty line.

    Like slugs' structured compiler, a line that is not infix but is a valid slugsin prefix
    formula is accepted as prefix. ``check``, if given, is called every few hundred lines
    (e.g. a synthesizer's Interrupt, which raises to stop a long parse).
    """
    return _parse_slugs_file(text, filename, 'infix', check)


def parse_slugsin(text: str, filename: str = '<string>', check=None) -> GR1Specification:
    """Parse a ``.slugsin`` file: one prefix conjunct per non-empty line (``check``: as above)."""
    return _parse_slugs_file(text, filename, 'prefix', check)


_LINES_BETWEEN_CHECKS = 256


def _parse_slugs_file(text: str, filename: str, syntax: str, check=None) -> GR1Specification:
    lines_by_section: dict[str, list[tuple[int, str, str]]] = {s: [] for s in PROPOSITION_SECTIONS + FORMULA_SECTIONS}
    section = None
    lines = None
    for number, raw in enumerate(text.splitlines(), start=1):
        content = raw.partition('#')[0] if '#' in raw else raw
        stripped = content.strip()
        if not stripped:
            continue
        if stripped[0] == '[':
            header = stripped[1:-1] if stripped.endswith(']') else None
            if header not in _SECTION_OF_HEADER:
                raise ParseError('unknown section header (expected one of '
                                 + ', '.join(f'[{h}]' for h in SLUGS_HEADERS.values()) + ')',
                                 stripped, filename, number, _column(content))
            section = _SECTION_OF_HEADER[header]
            lines = lines_by_section[section]
            continue
        if section is None:
            raise ParseError('text before the first section header', stripped, filename, number,
                             _column(content))
        lines.append((number, content, stripped))

    declared: dict[str, list[str]] = {}
    integers: dict[str, IntegerVariable] = {}
    seen: set[str] = set()
    for section in PROPOSITION_SECTIONS:
        declared[section] = []
        for number, content, name in lines_by_section[section]:
            if (syntax != 'infix' or ':' not in name) and name not in seen \
                    and name not in _KEYWORDS and _NAME.fullmatch(name):
                declared[section].append(name)  # the common case, without an error source
                seen.add(name)
                continue
            source = _Source(filename, number, _column(content))
            integer = _INTEGER_DECLARATION.match(name) if syntax == 'infix' else None
            if integer:
                variable = _integer_variable(integer, seen, source)
                integers[variable.name] = variable
                names = variable.bits
            else:
                _check_proposition_name(name, seen, syntax, source)
                names = [name]
            declared[section].extend(names)
            seen.update(names)

    scopes = _scopes(declared['env_props'], declared['sys_props'], integers)
    formulas = {}
    with _collector_paused():
        for section in FORMULA_SECTIONS:
            scope, entries = scopes[section], lines_by_section[section]
            parsed = _parse_section_by_shapes([line for _, _, line in entries], syntax, scope, check) \
                if not scope.integers else [None] * len(entries)
            for index, formula in enumerate(parsed):
                if formula is None:
                    number, content, line = entries[index]
                    parsed[index] = _parse_line(line, syntax, scope, _Source(filename, number, _column(content)))
            formulas[section] = parsed
    # Like slugs' compiler, keep integers in range: initially and after every step.
    for variable in integers.values():
        owner = 'env' if variable.bits and variable.bits[0] in declared['env_props'] else 'sys'
        for section, next_step in ((f'{owner}_init', False), (f'{owner}_trans', True)):
            limit = variable.in_range(next_step)
            if limit != TRUE:
                formulas[section].append(limit)
    return GR1Specification(**declared, **formulas)


def _integer_variable(declaration: re.Match, seen: set[str], source: _Source) -> IntegerVariable:
    name, low, high = declaration.group(1), int(declaration.group(2)), int(declaration.group(3))
    if low > high:
        raise source.error(f'empty integer range {low}...{high}', name, 1, 1)
    variable = IntegerVariable(name, low, high)
    for taken in [name] + variable.bits:
        if taken in seen or taken in _KEYWORDS:
            raise source.error('proposition declared twice', taken, 1, 1)
    return variable


def _column(content: str) -> int:
    """The column of a line's first non-blank character."""
    return len(content) - len(content.lstrip()) + 1


def _parse_line(line: str, syntax: str, scope: _Scope, source: _Source) -> Formula:
    try:
        return _parse(line, syntax, scope, source)
    except ParseError as infix_error:
        if syntax != 'infix' or isinstance(infix_error, UnknownVariableError):
            raise
        try:
            return _parse(line, 'prefix', scope, source)
        except ParseError:
            raise infix_error from None


# --- lines by shape ---------------------------------------------------------------------------
#
# Large specifications repeat a few line shapes with different propositions ("a & next(b) ->
# !c", "| ! a | b' c'" ...). A shape is the line with every proposition replaced by a placeholder; it is parsed
# once, by the parser above, and compiled into a function that builds the formula of any line
# of that shape. The result is the very tree the parser would build (a proposition never
# changes how operators group or fold). Lines whose propositions break the section's rules,
# and unusual lines (very long or deeply nested), go through the parser, which explains errors.

_PROPOSITION = re.compile(
    r"(?<![A-Za-z0-9_.@])(?!(?:TRUE|FALSE|next)(?![A-Za-z0-9_.@]))[A-Za-z_][A-Za-z0-9_.@]*")
_WORD = re.compile(r"([A-Za-z_][A-Za-z0-9_.@]*)")
_PLACEHOLDER = '\x00'
_NEXT_MARK = '\x01'
_MAX_SHAPE_PLACEHOLDERS = 64
_MAX_SHAPE_NESTING = 32
_SHAPES: dict[str, dict[str, object]] = {}  # syntax -> shape -> compiled (or False)
_SHAPES_SEEN_ONCE: set[tuple[str, str]] = set()
_MAX_SHAPES = 1 << 14


def _parse_section_by_shapes(lines: list[str], syntax: str, scope: _Scope, check=None) -> list:
    """The formula of each line, or None where the parser must handle the line.

    The shapes and propositions of all lines are found at once (one regular-expression pass
    over the joined text, not two per line). A shape is compiled the second time it is seen:
    compiling costs more than parsing one line, and the lines of a large file are either
    alike or all different.
    """
    joined = '\n'.join(lines)
    if not lines or _PLACEHOLDER in joined or _NEXT_MARK in joined:
        return [None] * len(lines)
    # 'next(' is marked first, so that every word left is a proposition or a keyword;
    # a rare TRUE / FALSE / spaced 'next (' needs the slower expression that skips keywords.
    marked = joined.replace('next(', _NEXT_MARK + '(')
    parts = _WORD.split(marked)
    names = parts[1::2]
    if _KEYWORDS.intersection(names):
        names = _PROPOSITION.findall(marked)
        shapes = _PROPOSITION.sub(_PLACEHOLDER, marked)
    else:
        shapes = _PLACEHOLDER.join(parts[0::2])
    # Each line is checked against the section's rules unless every proposition of the
    # section may appear both in the current and in the next step.
    check_scope = scope.names is not None and not scope.both_steps.issuperset(names)
    compiled_shapes = _SHAPES.setdefault(syntax, {})
    formulas = []
    append = formulas.append
    start = 0
    for shape in shapes.split('\n'):
        count = shape.count(_PLACEHOLDER)
        line_names = names[start:start + count]
        start += count
        if check is not None and len(formulas) % _LINES_BETWEEN_CHECKS == 0:
            check()
        compiled = compiled_shapes.get(shape)
        if compiled is None:
            compiled = _first_sightings(compiled_shapes, shape, syntax, count)
        if compiled is False:
            append(None)
            continue
        build, current_names, next_names = compiled
        if check_scope and not (scope.current.issuperset(current_names(line_names))
                                and scope.next_step.issuperset(next_names(line_names))):
            append(None)  # the parser names the problem
            continue
        append(build(line_names))
    return formulas


def _first_sightings(compiled_shapes: dict, shape: str, syntax: str, count: int):
    """A shape not compiled yet: False the first time (the parser handles that line) and for
    unusual lines (very long or deeply nested), else its compiled form, kept."""
    if count > _MAX_SHAPE_PLACEHOLDERS or shape.count('(') > _MAX_SHAPE_NESTING:
        return False
    key = (syntax, shape)
    if key not in _SHAPES_SEEN_ONCE:
        if len(_SHAPES_SEEN_ONCE) >= _MAX_SHAPES:
            _SHAPES_SEEN_ONCE.clear()
        _SHAPES_SEEN_ONCE.add(key)
        return False
    if len(compiled_shapes) >= _MAX_SHAPES:
        compiled_shapes.clear()
    compiled = compiled_shapes[shape] = _compile_shape(shape, syntax, count)
    return compiled


@contextmanager
def _collector_paused():
    """Python's cyclic garbage collector off while a file's formula trees are built: trees
    have no cycles, and its passes over millions of new nodes cost a third of a large parse."""
    was_enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if was_enabled:
            gc.enable()


def _compile_shape(shape: str, syntax: str, count: int):
    """(build(names) -> Formula, names -> those read in the current step, names -> those read
    in the next step), or False when the shape is not a formula (the parser then reports the
    line's error)."""
    if syntax == 'prefix' and '$' in shape:
        return False  # memory buffers share subformulas, which a template would copy out
    pieces = shape.replace(_NEXT_MARK, 'next').split(_PLACEHOLDER)
    text = ''.join(piece + (f'_{index}' if index < count else '') for index, piece in enumerate(pieces))
    try:
        template = _parse(text, syntax, _ANY, _Source())
    except ParseError:
        return False
    in_next = [False] * count
    namespace = dict(_BUILDER_NAMES)
    exec(_builder_source(template, in_next), namespace)  # noqa: S102 -- our own generated code
    return (namespace['build'], _picker([i for i in range(count) if not in_next[i]]),
            _picker([i for i in range(count) if in_next[i]]))


def _picker(indices: list[int]):
    """names -> the names at ``indices`` (as a tuple)."""
    if not indices:
        return lambda names: ()
    if len(indices) == 1:
        index = indices[0]
        return lambda names: (names[index],)
    return itemgetter(*indices)


# What a compiled shape's code may use: the shared leaf nodes, and for every other node the
# allocation and the field setters (about twice as fast as the dataclass's __init__, which
# matters for the millions of nodes of a large file; the nodes are the same).
_BUILDER_NAMES = {
    'Var': _var, 'NotVar': _not_var, 'NextVar': _next_var, 'NextNotVar': _next_not_var,
    'NotNextVar': _not_next_var, 'TRUE': TRUE, 'FALSE': FALSE, 'new': object.__new__,
    **{f'{kind.__name__}_{name}': getattr(kind, name).__set__
       for kind in (Not, Next, And, Or, Implies, Iff) for name in kind.__dataclass_fields__},
    **{kind.__name__: kind for kind in (Not, Next, And, Or, Implies, Iff)},
}


def _builder_source(template: Formula, in_next: list) -> str:
    """Python source of ``build(names)``, which makes ``template`` with each placeholder ``_i``
    replaced by the proposition ``names[i]`` (``in_next[i]`` is set if it is read in the next step)."""
    statements = []

    def node(formula: Formula, under_next: bool) -> str:
        """An expression for ``formula``'s node, after the statements that make its parts."""
        if isinstance(formula, Var):
            index = int(formula.name[1:])
            in_next[index] = under_next
            return f'Var(names[{index}])'
        if isinstance(formula, Const):
            return 'TRUE' if formula.value else 'FALSE'
        if isinstance(formula, (Not, Next)):
            inner = node(formula.arg, under_next or isinstance(formula, Next))
            # Shared leaf nodes, made once (the parser never builds Not(Not) or Next(Next)).
            if inner.startswith(('Var(', 'NotVar(')) or (isinstance(formula, Not) and inner.startswith('NextVar(')):
                return f'{type(formula).__name__}{inner}'
            return made(formula, {'arg': inner})
        if isinstance(formula, (And, Or)):
            return made(formula, {'args': '(' + ''.join(f'{node(arg, under_next)}, ' for arg in formula.args) + ')'})
        return made(formula, {'left': node(formula.left, under_next), 'right': node(formula.right, under_next)})

    def made(formula: Formula, fields: dict) -> str:
        kind, name = type(formula).__name__, f'n{len(statements)}'
        statements.append(f'{name} = new({kind})')
        statements.extend(f'{kind}_{field}({name}, {value})' for field, value in fields.items())
        return name

    result = node(template, False)
    return '\n'.join(['def build(names):', *(f'    {line}' for line in statements), f'    return {result}'])


def _check_proposition_name(name: str, seen: set[str], syntax: str, source: _Source) -> None:
    if ':' in name and syntax == 'infix':
        raise source.error('invalid integer declaration (expected name: low...high)',
                           name.split(':', 1)[0].strip(), 1, 1)
    if not _NAME.fullmatch(name) or name in _KEYWORDS:
        raise source.error('invalid proposition name', name, 1, 1)
    if name in seen:
        raise source.error('proposition declared twice', name, 1, 1)


def spec_from_text_sections(sections: dict[str, list[str]]) -> GR1Specification:
    """Build a specification from the LTLSpecification message shape.

    ``sections`` maps 'env_props' / 'sys_props' to proposition names and the six formula
    sections to lists of infix strings (missing sections are empty). Errors name the
    section and index, e.g. ``sys_trans[2]:1:5: unknown variable 'foo' near 'foo'``.
    """
    if not isinstance(sections, dict):
        raise ParseError('expected a mapping of section names to lists of strings', repr(sections), '<sections>')
    for key in sections:
        if key not in PROPOSITION_SECTIONS + FORMULA_SECTIONS:
            raise ParseError('unknown specification section', str(key), '<sections>')
    for key, entries in sections.items():
        if isinstance(entries, str) or not hasattr(entries, '__iter__'):
            raise ParseError('a section must be a list of strings', repr(entries), key)
        for index, entry in enumerate(entries):
            if not isinstance(entry, str):
                raise ParseError('expected a string', repr(entry), f'{key}[{index}]')

    seen: set[str] = set()
    declared = {}
    for section in PROPOSITION_SECTIONS:
        declared[section] = []
        for index, name in enumerate(sections.get(section, [])):
            _check_proposition_name(name.strip(), seen, 'message', _Source(f'{section}[{index}]'))
            declared[section].append(name.strip())
            seen.add(name.strip())

    scopes = _scopes(declared['env_props'], declared['sys_props'])
    formulas = {
        section: [_parse(text, 'infix', scopes[section], _Source(f'{section}[{index}]'))
                  for index, text in enumerate(sections.get(section, []))]
        for section in FORMULA_SECTIONS}
    return GR1Specification(**declared, **formulas)

