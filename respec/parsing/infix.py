"""The reference reader of infix formulas (structured slugs, ``.structuredslugs`` files).

Recursive descent over slugs' precedence levels (respec.parsing.operators), keeping every
token's position for its messages; integer comparisons are expanded by respec.parsing.integers.
"""

from __future__ import annotations

import re
from typing import NamedTuple

from respec.vocabulary.errors import quoted
from respec.ltl import FALSE, TRUE, Formula, Var, conj, disj, neg, next_
from respec.nesting import MAX_FORMULA_NESTING, too_deep
from respec.parsing.errors import ParseError
from respec.parsing.integers import COMPARATORS, Term, compare
from respec.parsing.operators import BINDING, Binding, combine, shared_var
from respec.parsing.scope import KEYWORDS, Scope, Source, error_kind, scope_problem


class _Token(NamedTuple):
    kind: str       # 'name', 'primed', 'number', 'op', 'TRUE', 'FALSE', 'next', 'end'
    text: str
    line: int
    column: int


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


def _infix_tokens(text: str, source: Source) -> list[_Token]:
    tokens: list[_Token] = []
    line, line_start = 1, 0
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


class InfixParser:
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

    def error(self, problem: str, token: _Token, kind: type[ParseError] = ParseError) -> ParseError:
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

    def sum(self, in_next: bool) -> list[Term]:
        terms = self.summand(in_next)
        while self.peek().kind == 'op' and self.peek().text == '+':
            self.take()
            terms = terms + self.summand(in_next)
        return terms

    def summand(self, in_next: bool) -> list[Term]:
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
        return shared_var(token.text)
