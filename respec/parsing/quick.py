"""Quick readers of specification file lines: infix and slugsin formulas over plain strings.

They build the very tree the reference readers (respec.parsing.grammar) build, with the same
constructors, without keeping each token's position; on anything they do not expect they give
up (None), so that the reference reader reads that line and explains any error
(docs/parsing.md).
"""

from __future__ import annotations

import re
import string
from typing import Any

from respec.ltl import FALSE, TRUE, Formula, Var, conj, disj, neg, next_, var
from respec.nesting import MAX_FORMULA_NESTING
from respec.parsing.operators import BINDING, Binding, combine
from respec.parsing.scope import Scope


# --- infix: a shunting-yard loop ----------------------------------------------------------
#
# It gives up on non-ASCII text, integers, numbers, a bad character, a misplaced operator, a
# proposition the section does not allow, a nested next.

_READABLE_LINE = re.compile(r"[A-Za-z0-9_.@' \t&|^!~()<>/\\-]*")
# Operators spelled with several characters become one mark each (longest spellings first, as
# the infix reader's scanner reads them), which then stands apart like the one-character ones.
_MARK_OF_OPERATOR = {'<->': '\x10', '->': '\x11', '&': '\x12', '|': '\x13'}
_SPELLINGS = tuple((spelling, _MARK_OF_OPERATOR[operator]) for spelling, operator in (
    ('<-->', '<->'), ('<->', '<->'), ('-->', '->'), ('->', '->'),
    ('&&', '&'), ('/\\', '&'), ('||', '|'), ('\\/', '|')))
_PADDED = ('(', ')', '!', '~', '&', '|', '^', *_MARK_OF_OPERATOR.values())
_NAME_START = frozenset(string.ascii_letters + '_')
# A token's kind: a binary operator's Binding; below the bindings, the marks the operator stack
# holds besides them ('(' and the unary operators); above them, the other tokens.
_OPEN, _NOT, _NEXT = -1, -2, -3
_CLOSE, _TRUE, _FALSE = range(len(Binding), len(Binding) + 3)
_KIND = {
    **{operator: BINDING[operator] for operator in ('&', '|', '^')},
    **{mark: BINDING[operator] for operator, mark in _MARK_OF_OPERATOR.items()},
    '(': _OPEN, '!': _NOT, '~': _NOT, 'next': _NEXT, ')': _CLOSE, 'TRUE': _TRUE, 'FALSE': _FALSE,
}
_OPERATOR_OF_BINDING: dict[int, str] = {binding: operator for operator, binding in BINDING.items()}
# Runs of the operators binding this tightly or more (| and &) make one node, as in the grammar.
_FOLDED = Binding.OR


def quick_infix(line: str, scope: Scope, variables: dict[str, Var] | None = None) -> Formula | None:
    """The formula of one infix line of a specification file (the grammar's tree, read by a
    shunting-yard loop over plain strings), or None for the grammar to read (see above).
    ``variables``: the file's proposition nodes by name (shared, and added to)."""
    variables = {} if variables is None else variables
    if not line.isascii() or scope.integers or _READABLE_LINE.fullmatch(line) is None:
        return None
    if line.count('(') + line.count('!') + line.count('~') + line.count('next') > MAX_FORMULA_NESTING:
        return None  # perhaps nested too deeply: the grammar counts the levels
    for spelling, mark in _SPELLINGS:
        if spelling in line:
            line = line.replace(spelling, mark)
    if '-' in line or '<' in line or '>' in line or '/' in line or '\\' in line:
        return None  # a comparison, or a broken operator
    for operator in _PADDED:
        if operator in line:
            line = line.replace(operator, f' {operator} ')
    known, now, following = scope.names, scope.current, scope.next_step
    operands: list[Formula] = []
    operators: list[int] = []  # Bindings and the marks below them
    counts: list[int] = []  # the operands of each binary operator on the stack
    operand: Formula
    push, push_operator = operands.append, operators.append
    kinds = _KIND
    in_next = False
    expect_operand = True
    for token in line.split():
        kind = kinds.get(token)
        if expect_operand:
            if kind is None:  # a proposition
                if token[0] not in _NAME_START:
                    return None  # a number, or a word starting with '.', '@' or a prime
                if "'" in token:
                    name = token[:-1]
                    if in_next or "'" in name or (known is not None and name not in following):
                        return None
                    operand = variables.get(name) or variables.setdefault(name, var(name))
                    operand = next_(operand)
                elif known is None or token in (following if in_next else now):
                    operand = variables.get(token) or variables.setdefault(token, var(token))
                else:
                    return None
            elif kind < 0:  # '(', '!' or next
                if kind == _NEXT:
                    if in_next:
                        return None
                    in_next = True
                push_operator(kind)
                continue
            elif kind == _TRUE:
                operand = TRUE
            elif kind == _FALSE:
                operand = FALSE
            else:
                return None  # a binary operator or ')' where an operand belongs
            expect_operand = False
        elif kind is None or kind < 0 or kind > _CLOSE:
            return None  # an operand or a unary operator after an operand
        elif kind == _CLOSE:
            while operators and operators[-1] >= 0:
                _reduce(operands, operators, counts)
            if not operators or operators.pop() != _OPEN:
                return None
            operand = operands.pop()
        else:  # a binary operator; kind is its Binding
            while operators and operators[-1] > kind:
                _reduce(operands, operators, counts)
            if operators and operators[-1] == kind:
                if kind >= _FOLDED:  # a run of & or |: one node for the whole run
                    counts[-1] += 1
                    expect_operand = True
                    continue
                _reduce(operands, operators, counts)  # left associative
            push_operator(kind)
            counts.append(2)
            expect_operand = True
            continue
        # An operand is complete: the unary operators just before it apply.
        while operators and operators[-1] < _OPEN:
            if operators.pop() == _NOT:
                operand = neg(operand)
            else:
                operand = next_(operand)
                in_next = False
        push(operand)
    if expect_operand:
        return None
    while operators:
        if operators[-1] < 0:
            return None  # an unclosed '('
        _reduce(operands, operators, counts)
    return operands[0]


def _reduce(operands: list[Formula], operators: list[int], counts: list[int]) -> None:
    """Replace the operands of the operator on top of the stack by its formula."""
    operator, count = _OPERATOR_OF_BINDING[operators.pop()], counts.pop()
    arguments = operands[-count:]
    del operands[-count:]
    if operator == '&':
        operands.append(conj(arguments))
    elif operator == '|':
        operands.append(disj(arguments))
    else:
        operands.append(combine(operator, *arguments))


# --- slugsin: right to left -------------------------------------------------------------

# A run of & or | read right to left: [operator, operands last first].
_Run = list[Any]
_PREFIX_KIND = {token: token for token in ('!', '&', '|', '^', '1', '0')}


def quick_prefix(line: str, scope: Scope, variables: dict[str, Var]) -> Formula | None:
    """The formula of one slugsin line of a specification file, read right to left over plain
    strings (the grammar's tree), or None for the grammar to read: undeclared or misplaced
    propositions, malformed lines. ``variables``: the file's proposition nodes by name
    (shared, and added to). Lines with memory buffers (a recall names an element to its left)
    and very long lines are read left to right."""
    now, following = scope.current, scope.next_step
    if scope.names is None:
        return None
    if '$' in line or '?' in line or (
            len(line) > 2 * MAX_FORMULA_NESTING and line.count(' ') > MAX_FORMULA_NESTING):
        # Memory buffers, or a line long enough to be nested too deeply: read left to right,
        # which resolves recalls and counts the nesting levels as the grammar does.
        return _quick_prefix_left_to_right(line, now, following, variables)
    # Formulas and runs; told apart by their class, which is faster than isinstance (and
    # which mypy does not narrow by).
    operands: list[Any] = []
    push, pop = operands.append, operands.pop
    for token in reversed(line.split()):
        kind = _PREFIX_KIND.get(token)
        if kind is None:  # a proposition: declared ones are well-formed names
            if token[-1] == "'":
                name = token[:-1]
                if name not in following:
                    return None
                push(next_(variables.get(name) or variables.setdefault(name, var(name))))
            elif token in now:
                push(variables.get(token) or variables.setdefault(token, var(token)))
            else:
                return None
        elif kind == '1' or kind == '0':
            push(TRUE if kind == '1' else FALSE)
        elif kind == '!':
            if not operands:
                return None
            operand = pop()
            push(neg(operand if operand.__class__ is not list else _finished(operand)))
        elif len(operands) < 2:
            return None
        else:
            left, right = pop(), pop()
            if left.__class__ is list:
                left = _finished(left)
            if right.__class__ is list:
                if right[0] == kind:
                    right.append(left)  # "& a & b c": one node for the run, as in the grammar
                    push(right)
                    continue
                right = _finished(right)
            push([kind, right, left] if kind == '&' or kind == '|' else combine(kind, left, right))
    return _finished(operands[0]) if len(operands) == 1 else None


def _finished(operand: Formula | _Run) -> Formula:
    """A formula, from a formula or a run: [operator, operands last first] (quick_prefix)."""
    if operand.__class__ is not list:
        return operand  # type: ignore[return-value]  # a formula: mypy narrows by isinstance, not __class__
    return conj(operand[:0:-1]) if operand[0] == '&' else disj(operand[:0:-1])


# Left to right, a token's kind: the operands an operator takes, or a mark for the others.
_BUFFER, _RECALL, _ONE, _ZERO = 0, -1, -2, -3
_LEFT_TO_RIGHT_KIND = {'!': 1, '&': 2, '|': 2, '^': 2, '$': _BUFFER, '?': _RECALL, '1': _ONE, '0': _ZERO}


def _quick_prefix_left_to_right(line: str, now: frozenset[str], following: frozenset[str], variables: dict[str, Var]) -> Formula | None:
    """A slugsin line, with memory buffers ``$ n f0 ... fn-1`` and recalls ``? i``, read left
    to right with a stack of open operators, each ``[operator, operands wanted, operands]``.
    A recall reads the innermost open buffer, as the grammar's ``memory``; the operators
    open at once are the grammar's nesting levels; a run ``& a & b c`` is one node, as the
    grammar gathers it. Anything unexpected is left to the grammar (None)."""
    tokens = iter(line.split())
    open_operators: list[list[Any]] = []  # each [operator, operands wanted, operands]
    push, pop = open_operators.append, open_operators.pop
    kinds = _LEFT_TO_RIGHT_KIND
    for token in tokens:
        kind = kinds.get(token)
        if kind is None:  # a proposition
            if token[-1] == "'":
                name = token[:-1]
                if name not in following:
                    return None
                value = next_(variables.get(name) or variables.setdefault(name, var(name)))
            elif token in now:
                value = variables.get(token) or variables.setdefault(token, var(token))
            else:
                return None
        elif kind > 0 or kind == _BUFFER:  # an operator
            if kind == _BUFFER:
                kind = _count(next(tokens, ''))
                if not kind:
                    return None
            elif open_operators:
                top = open_operators[-1]
                if top[0] == token and kind == 2 and token != '^' and len(top[2]) == top[1] - 1:
                    top[1] += 1  # one more operand of the same run
                    continue
            if len(open_operators) >= MAX_FORMULA_NESTING:
                return None  # the grammar reports the nesting
            push([token, kind, []])
            continue
        elif kind == _RECALL:
            index = _count(next(tokens, ''))
            memory = next((operator[2] for operator in reversed(open_operators)
                           if operator[0] == '$'), None)
            if index is None or memory is None or index >= len(memory):
                return None
            value = memory[index]
        else:
            value = TRUE if kind == _ONE else FALSE
        # The value completes operators: each finished one is a value for the one below it.
        while open_operators:
            operator, wanted, operands = open_operators[-1]
            operands.append(value)
            if len(operands) < wanted:
                break
            pop()
            value = _applied(operator, operands)
        else:
            return value if next(tokens, None) is None else None
    return None


def _count(token: str) -> int | None:
    """The number a buffer or recall takes, or None."""
    return int(token) if token.isascii() and token.isdigit() else None


def _applied(operator: str, operands: list[Formula]) -> Formula:
    if operator == '$':
        return operands[-1]  # a buffer's value is its last element
    if operator == '!':
        return neg(operands[0])
    if operator == '&':
        return conj(operands)
    if operator == '|':
        return disj(operands)
    return combine(operator, operands[0], operands[1])
