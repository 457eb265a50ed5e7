"""The reference reader of prefix formulas (slugsin, ``.slugsin`` files), including slugs'
memory buffers ``$ n f0 ... fn-1`` and recalls ``? i``; it keeps every token's position for its
messages.
"""

from __future__ import annotations

import re

from respec.ltl import FALSE, TRUE, Formula, conj, disj, neg, next_
from respec.nesting import MAX_FORMULA_NESTING, too_deep
from respec.parsing.errors import ParseError
from respec.parsing.operators import shared_var, xor
from respec.parsing.scope import KEYWORDS, NAME, Scope, Source, error_kind, scope_problem


_PREFIX_TOKEN = re.compile(r'\S+')
_Token = tuple[str, int, int]  # text, line, column


class PrefixParser:
    """slugsin prefix notation: ``! f``, ``& f g``, ``| f g``, ``^ f g``, ``1``, ``0``, ``x``, ``x'``,
    memory buffers ``$ n f0 ... fn-1`` (value: the last element) and recalls ``? i``."""

    def __init__(self, text: str, scope: Scope, source: Source):
        self.source = source
        self.scope = scope
        self.tokens: list[_Token] = []
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

    def error(self, problem: str, token: _Token, kind: type[ParseError] = ParseError) -> ParseError:
        return self.source.error(problem, token[0], token[1], token[2], kind)

    def take(self) -> _Token:
        if self.position == len(self.tokens):
            raise self.source.error('formula ends too early', '<end>', *self.end)
        token = self.tokens[self.position]
        self.position += 1
        return token

    def number(self, after: _Token) -> int:
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

    def operation(self, token: _Token, memory: list[Formula] | None) -> Formula:
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
        return next_(shared_var(name)) if primed else shared_var(name)
