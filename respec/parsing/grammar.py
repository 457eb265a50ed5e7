"""The reference readers of formulas: slugs' infix (structured slugs) and prefix (slugsin) grammars.

* infix: ``parse_formula(text, 'infix')``, as in ``.structuredslugs`` files;
* prefix: ``parse_formula(text, 'prefix')``, as in ``.slugsin`` files, including slugs' memory
  buffers ``$ n f0 ... fn-1`` and recalls ``? i``.

They return ``respec.ltl`` trees built with its constructors, so the result of parsing printed
text is the tree that was printed (``parse_formula(to_infix(f)) == f``). They keep every token's
position, check each proposition against its section's scope, and explain every error; the
faster readers (respec.parsing.quick, respec.parsing.shapes) leave them any line they do not
expect.

Operator precedence follows slugs' structured grammar (tools/StructuredSlugsParser/grammar.wi),
tightest first: ``!`` and ``next``, then ``&``, ``|``, ``^``, ``->``, ``<->``. As in that
grammar every binary operator is LEFT associative, so ``a -> b -> c`` means ``(a -> b) -> c``
(the same file means the same thing to slugs and to us; our printer always parenthesizes).
"""

from __future__ import annotations

import re
from enum import IntEnum
from functools import lru_cache
from typing import NamedTuple

from respec.errors import quoted
from respec.ltl import FALSE, TRUE, Formula, Var, conj, disj, iff, implies, neg, next_, var
from respec.nesting import MAX_FORMULA_NESTING, too_deep
from respec.parsing.errors import ParseError
from respec.parsing.integers import COMPARATORS, compare
from respec.parsing.scope import ANY, KEYWORDS, NAME, Scope, Source, error_kind, scope_problem


class _Token(NamedTuple):
    kind: str       # 'name', 'primed', 'number', 'op', 'TRUE', 'FALSE', 'next', 'end'
    text: str
    line: int
    column: int


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


class Binding(IntEnum):
    """How tightly a binary operator binds, loosest first (all are left associative)."""

    IFF = 0
    IMPLIES = 1
    XOR = 2
    OR = 3
    AND = 4


BINDING = {'<->': Binding.IFF, '->': Binding.IMPLIES, '^': Binding.XOR, '|': Binding.OR, '&': Binding.AND}


def _infix_tokens(text: str, source: Source) -> list[_Token]:
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
            append(_Token(word, word, line, column) if word in KEYWORDS
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
    """Recursive descent over slugs' precedence levels: precedence climbing for the binary
    operators, one method for each other level."""

    def __init__(self, text: str, scope: Scope, source: Source):
        self.source = source
        self.scope = scope
        self.tokens = _infix_tokens(text, source)
        self.position = 0
        self.depth = 0

    def parse(self) -> Formula:
        if self.peek().kind == 'end':
            raise self.error('empty formula', self.peek())
        formula = self.binary(Binding.IFF, in_next=False)
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

    def binary(self, binding: int, in_next: bool) -> Formula:
        """Operators binding at least as tightly as ``binding`` (precedence climbing)."""
        left = self.unary(in_next)
        tokens = self.tokens
        while True:
            token = tokens[self.position]
            operator_binding = BINDING.get(token.text) if token.kind == 'op' else None
            if operator_binding is None or operator_binding < binding:
                return left
            self.position += 1
            right = self.binary(operator_binding + 1, in_next)  # left associative
            if token.text in ('&', '|'):
                # A run of the same associative operator becomes one node at once: combining
                # pairwise would copy the growing operand list at every step.
                operands = [left, right]
                while tokens[self.position].kind == 'op' and tokens[self.position].text == token.text:
                    self.position += 1
                    operands.append(self.binary(operator_binding + 1, in_next))
                left = conj(operands) if token.text == '&' else disj(operands)
            else:
                left = combine(token.text, left, right)

    def deeper(self, token: _Token) -> None:
        """One nesting level more (a '(', '!' or next); refused beyond MAX_FORMULA_NESTING."""
        self.depth += 1
        if self.depth > MAX_FORMULA_NESTING:
            raise self.error(too_deep(), token)

    def unary(self, in_next: bool) -> Formula:
        token = self.peek()
        if token.kind == 'op' and token.text == '!':
            self.take()
            self.deeper(token)
            formula = neg(self.unary(in_next))
            self.depth -= 1
            return formula
        if token.kind == 'next':
            self.take()
            if in_next:
                raise self.error('nested next is not GR(1)', token)
            self.deeper(token)
            formula = next_(self.unary(in_next=True))
            self.depth -= 1
            return formula
        return self.atom(in_next)

    def atom(self, in_next: bool) -> Formula:
        token = self.take()
        if self.scope.integers and (token.kind == 'number' or (
                token.kind in ('name', 'primed') and token.text in self.scope.integers)):
            self.position -= 1
            return self.comparison(in_next)
        if self.scope.integers and token.kind == 'op' and token.text == '(':
            # '(' opens either a Boolean formula or an integer sum; try the sum first.
            start, depth = self.position - 1, self.depth
            self.position = start
            try:
                return self.comparison(in_next)
            except ParseError:
                self.position, self.depth = start + 1, depth
        if token.kind in ('TRUE', 'FALSE'):
            return TRUE if token.kind == 'TRUE' else FALSE
        if token.kind == 'name':
            return self.variable(token, next_step=in_next)
        if token.kind == 'primed':
            if in_next:
                raise self.error('primed variable inside next() is a nested next', token)
            return next_(self.variable(token, next_step=True))
        if token.kind == 'op' and token.text == '(':
            self.deeper(token)
            inner = self.binary(Binding.IFF, in_next)
            self.depth -= 1
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
        if not (operator.kind == 'op' and operator.text in COMPARATORS):
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
                problem = scope_problem(self.scope, integer.bits[0], next_step)
                if problem:
                    raise self.error(problem.replace(quoted(integer.bits[0]), quoted(integer.name)), token)
            return [(integer, next_step)]
        if token.kind == 'op' and token.text == '(':
            self.deeper(token)
            terms = self.sum(in_next)
            self.depth -= 1
            closing = self.take()
            if not (closing.kind == 'op' and closing.text == ')'):
                raise self.error("expected ')'", closing)
            return terms
        raise self.error('expected an integer variable or a number', token)

    def variable(self, token: _Token, next_step: bool) -> Var:
        problem = scope_problem(self.scope, token.text, next_step)
        if problem:
            raise self.error(problem, token, error_kind(problem))
        return _var(token.text)


# One node per proposition: large specifications mention each proposition many times.
_var = lru_cache(maxsize=1 << 16)(var)


def combine(operator: str, left: Formula, right: Formula) -> Formula:
    """A binary operator (its canonical spelling) applied to two operands."""
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


# --- prefix (slugsin) ---------------------------------------------------------------------

_PREFIX_TOKEN = re.compile(r'\S+')


class _PrefixParser:
    """slugsin prefix notation: ``! f``, ``& f g``, ``| f g``, ``^ f g``, ``1``, ``0``, ``x``, ``x'``,
    memory buffers ``$ n f0 ... fn-1`` (value: the last element) and recalls ``? i``."""

    def __init__(self, text: str, scope: Scope, source: Source):
        self.source = source
        self.scope = scope
        self.tokens = []
        for line_number, line in enumerate(text.split('\n'), start=1):
            line = line.split('#', 1)[0]
            self.tokens += [(m.group(), line_number, m.start() + 1) for m in _PREFIX_TOKEN.finditer(line)]
        self.position = 0
        self.depth = 0
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
        self.depth += 1  # operators nest; a leaf below the deepest one is no level of its own
        if self.depth > MAX_FORMULA_NESTING and token[0] in ('!', '^', '&', '|', '$'):
            raise self.error(too_deep(), token)
        try:
            return self.operation(token, memory)
        finally:
            self.depth -= 1

    def operation(self, token, memory: list[Formula] | None) -> Formula:
        """The formula that starts with ``token``."""
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
        if not NAME.fullmatch(name) or name in KEYWORDS:
            raise self.error('expected an operator (! & | ^ $ ?), 0, 1 or a variable', token)
        problem = scope_problem(self.scope, name, primed)
        if problem:
            raise self.error(problem, token, error_kind(problem))
        return next_(_var(name)) if primed else _var(name)


# --- reading one formula -------------------------------------------------------------------

def parse_formula(text: str, syntax: str = 'infix') -> Formula:
    """Parse one formula: ``syntax`` is 'infix' (structured slugs) or 'prefix' (slugsin).

    Any variable name is accepted; specification parsers check names against declarations.
    """
    if not isinstance(text, str):
        raise ParseError('formula must be a string', quoted(text))
    return parse_in_scope(text, syntax, ANY, Source())


def parse_in_scope(text: str, syntax: str, scope: Scope, source: Source) -> Formula:
    if syntax == 'infix':
        return _InfixParser(text, scope, source).parse()
    if syntax == 'prefix':
        return _PrefixParser(text, scope, source).parse()
    raise ValueError(f"unknown formula syntax {syntax!r} (expected 'infix' or 'prefix')")


