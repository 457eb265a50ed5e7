"""Lines by shape: the lines of a section that share a shape are built together.

A shape is a line with every proposition replaced by a placeholder ("_0 & next(_1) -> !_2",
"| ! _0 | _1' _2'"). Large specifications repeat a few shapes with different propositions; each
shape is parsed once by the grammar (respec.parsing.grammar) and compiled into a function that
builds the formulas of all lines of that shape together, a node column at a time, with the
grammar's very tree as result (docs/parsing.md). Lines whose propositions break the section's
rules, and unusual lines (very long or deeply nested, or whose template folds a proposition
away), are left to the grammar, which explains errors.
"""

from __future__ import annotations

import itertools
import re
import string
from collections import deque
from operator import add
from typing import Any, Callable, Literal, cast

from respec.ltl import FALSE, FIELD_SETTERS, TRUE, And, Const, Formula, Iff, Implies, Next, Not, Or, Var, variables
from respec.parsing.errors import ParseError
from respec.parsing.grammar import parse_in_scope
from respec.parsing.scope import ANY, KEYWORDS, Scope, Source

# How many lines are read between two calls of a parse's ``check`` (to interrupt it).
LINES_BETWEEN_CHECKS = 1024

_PROPOSITION = re.compile(
    r"(?<![A-Za-z0-9_.@])(?!(?:TRUE|FALSE|next)(?![A-Za-z0-9_.@]))[A-Za-z_][A-Za-z0-9_.@]*")
_WORD = re.compile(r"([A-Za-z_][A-Za-z0-9_.@]*)")
_PLACEHOLDER = '\x00'
_NEXT_MARK = '\x01'
# Outlines (see _shapes_by_translation): each character of a word becomes one of these.
_DIGIT_MARK, _DOT_MARK = '\x02', '\x03'
_MARKS = (_PLACEHOLDER, _NEXT_MARK, _DIGIT_MARK, _DOT_MARK)
_NAME_START = string.ascii_letters + '_'
_OUTLINE = str.maketrans({**dict.fromkeys(_NAME_START, _PLACEHOLDER), **dict.fromkeys(string.digits, _DIGIT_MARK),
                          '.': _DOT_MARK, '@': _DOT_MARK})
_WORDS_ONLY = str.maketrans({chr(code): ' ' for code in range(128)
                             if chr(code) not in _NAME_START + string.digits + '.@'})
_OUTLINE_WORD = re.compile(f'[{_PLACEHOLDER}{_DIGIT_MARK}{_DOT_MARK}]+')
# A number, or a word starting with . or @.
_OUTLINE_NON_NAME = re.compile(f'(?<![{_PLACEHOLDER}{_DIGIT_MARK}{_DOT_MARK}])[{_DIGIT_MARK}{_DOT_MARK}]')
_MAX_SHAPE_PLACEHOLDERS = 64
_MAX_SHAPE_NESTING = 32
# build(columns, n, leaves): the formulas of n lines of a shape (see _compile_shape).
_Build = Callable[[list[list[str]], int, 'LeafNodes'], list[Formula]]
# (build, read_now, read_next), or False for a shape the grammar handles.
_CompiledShape = tuple[_Build, tuple[int, ...], tuple[int, ...]] | Literal[False]
# (names, starts, lines_of_shape): see _shapes_by_translation.
_Shapes = tuple[list[str], list[int], dict[str, list[int]]]
_SHAPES: dict[str, dict[str, _CompiledShape]] = {}  # syntax -> shape -> compiled (or False)
_MAX_SHAPES = 1 << 14
_LINES_WORTH_COMPILING = 8     # lines sharing a shape before it is compiled
_LINES_WORTH_GROUPING = 1000   # sections this large may be left whole to the line readers


def parse_section_by_shapes(lines: list[str], syntax: str, scope: Scope, leaves: LeafNodes,
                            check: Callable[[], object] | None = None) -> list[Formula | None]:
    """The formula of each line, or None where the grammar must handle the line.

    The shapes and propositions of all lines are found at once (a few passes of str.translate
    over the joined text, not a scan per line), and the lines of each shape are built together.
    A shape not compiled yet is compiled only when enough lines share it (compiling costs
    more than parsing a few lines); a large section whose lines are mostly unlike each other is
    left whole to the line readers (respec.parsing.quick, then the grammar).
    """
    joined = '\n'.join(lines)
    if not lines or any(mark in joined for mark in _MARKS):
        return [None] * len(lines)
    # 'next(' is marked first, so that every word left is a proposition or a keyword.
    marked = joined.replace('next(', _NEXT_MARK + '(')
    names, starts, lines_of_shape = _shapes_by_translation(marked) or _shapes_by_expression(marked)
    # Lines are checked against the section's rules, for each step only if some proposition
    # of the section may not appear in it.
    check_now = scope.names is not None and not scope.current.issuperset(names)
    check_next = scope.names is not None and not scope.next_step.issuperset(names)
    compiled_shapes = _SHAPES.setdefault(syntax, {})
    formulas: list[Formula | None] = [None] * len(lines)
    for shape, indices in lines_of_shape.items():
        compiled = compiled_shapes.get(shape)
        if compiled is None:
            if len(indices) < _LINES_WORTH_COMPILING:
                continue
            compiled = _compiled_shape(compiled_shapes, shape, syntax, starts[indices[0] + 1] - starts[indices[0]])
        if compiled is False:
            continue
        build, read_now, read_next = compiled
        count = len(read_now) + len(read_next)
        read_now, read_next = read_now if check_now else (), read_next if check_next else ()
        for first in range(0, len(indices), LINES_BETWEEN_CHECKS):
            if check is not None:
                check()
            chosen = indices[first:first + LINES_BETWEEN_CHECKS]
            columns = _columns(names, [starts[index] for index in chosen], count)
            if (read_now or read_next) and not _within(scope, columns, read_now, read_next):
                # Some line breaks the rules: the grammar names the problem.
                keep = [row for row in range(len(chosen))
                        if _within(scope, [[column[row]] for column in columns], read_now, read_next)]
                chosen = [chosen[row] for row in keep]
                columns = [[column[row] for row in keep] for column in columns]
            for index, formula in zip(chosen, build(columns, len(chosen), leaves)):
                formulas[index] = formula
    return formulas


def _shapes_by_translation(marked: str) -> _Shapes | None:
    """(names, starts, lines_of_shape): every proposition in order, where each line's
    propositions start in it, and the lines of each shape. Found with str.translate (faster
    than a regular expression); None when the text needs the expression
    (non-ASCII text, numbers, TRUE / FALSE or a spaced 'next (')."""
    if not marked.isascii():
        return None
    names = marked.translate(_WORDS_ONLY).split()
    if KEYWORDS.intersection(names):
        return None
    # In a line's outline each word is a run of marks as long as the word; lines are grouped
    # by outline, then outlines by shape (one placeholder per word).
    outline_of_line = marked.translate(_OUTLINE).split('\n')
    lines_of_outline = _positions(outline_of_line)
    if _mostly_unlike(lines_of_outline, len(outline_of_line)):
        return [], [], {}
    word_counts: dict[str, int] = {}
    lines_of_shape: dict[str, list[int]] = {}
    for outline, indices in lines_of_outline.items():
        if _OUTLINE_NON_NAME.search(outline):
            return None
        shape = _OUTLINE_WORD.sub(_PLACEHOLDER, outline)
        word_counts[outline] = shape.count(_PLACEHOLDER)
        lines_of_shape.setdefault(shape, []).extend(indices)
    return names, list(itertools.accumulate(map(word_counts.__getitem__, outline_of_line), initial=0)), lines_of_shape


def _shapes_by_expression(marked: str) -> _Shapes:
    """What _shapes_by_translation finds, for any text."""
    parts = _WORD.split(marked)
    names = parts[1::2]
    if KEYWORDS.intersection(names):  # the slower expression that skips keywords
        names = _PROPOSITION.findall(marked)
        shapes = _PROPOSITION.sub(_PLACEHOLDER, marked)
    else:
        shapes = _PLACEHOLDER.join(parts[0::2])
    shape_of_line = shapes.split('\n')
    lines_of_shape = _positions(shape_of_line)
    if _mostly_unlike(lines_of_shape, len(shape_of_line)):
        return [], [], {}
    starts = list(itertools.accumulate(map(str.count, shape_of_line, itertools.repeat(_PLACEHOLDER)), initial=0))
    return names, starts, lines_of_shape


def _mostly_unlike(groups: dict[str, list[int]], lines: int) -> bool:
    """Whether a large section's lines fall into more groups than half their number."""
    return lines >= _LINES_WORTH_GROUPING and 2 * len(groups) > lines


def _positions(items: list[str]) -> dict[str, list[int]]:
    """Each distinct item -> the indices where it occurs."""
    positions: dict[str, list[int]] = {}
    for index, item in enumerate(items):
        found = positions.get(item)
        if found is None:
            positions[item] = [index]
        else:
            found.append(index)
    return positions


def _columns(names: list[str], line_starts: list[int], count: int) -> list[list[str]]:
    """Column i: the i-th proposition of each line (its propositions start at ``line_starts``)."""
    return [list(map(names.__getitem__, map(add, line_starts, itertools.repeat(offset)))) for offset in range(count)]


def _within(scope: Scope, columns: list[list[str]], read_now: tuple[int, ...], read_next: tuple[int, ...]) -> bool:
    """Whether lines read only what the section allows (``read_now``, ``read_next``: the
    columns read in the current and in the next step)."""
    return (scope.current.issuperset(itertools.chain.from_iterable(columns[i] for i in read_now))
            and scope.next_step.issuperset(itertools.chain.from_iterable(columns[i] for i in read_next)))


def _compiled_shape(compiled_shapes: dict[str, _CompiledShape], shape: str, syntax: str, count: int) -> _CompiledShape:
    """A shape's compiled form (see _compile_shape), kept; False for unusual lines (very long
    or deeply nested), which the grammar handles."""
    if count > _MAX_SHAPE_PLACEHOLDERS or shape.count('(') > _MAX_SHAPE_NESTING:
        return False
    if len(compiled_shapes) >= _MAX_SHAPES:
        compiled_shapes.clear()
    compiled = compiled_shapes[shape] = _compile_shape(shape, syntax, count)
    return compiled


def _compile_shape(shape: str, syntax: str, count: int) -> _CompiledShape:
    """(build, read_now, read_next), or False when the shape is not a formula (the grammar then
    reports the line's error). ``build(columns, n)`` makes the formulas of n lines of the shape,
    where ``columns[i]`` holds each line's i-th proposition; ``read_now`` / ``read_next`` are the
    columns read in the current / in the next step."""
    if syntax == 'prefix' and '$' in shape:
        return False  # memory buffers share subformulas, which a template would copy out
    pieces = shape.replace(_NEXT_MARK, 'next').split(_PLACEHOLDER)
    text = ''.join(piece + (f'_{index}' if index < count else '') for index, piece in enumerate(pieces))
    try:
        template = parse_in_scope(text, syntax, ANY, Source())
    except ParseError:
        return False
    if variables(template) != {f'_{index}' for index in range(count)}:
        return False  # folded away (e.g. '& 0 a'): the grammar still checks the proposition
    in_next = [False] * count
    namespace: dict[str, Any] = dict(_BUILDER_NAMES)
    exec(_builder_source(template, in_next), namespace)  # noqa: S102 -- our own generated code
    return (namespace['build'], tuple(i for i in range(count) if not in_next[i]),
            tuple(i for i in range(count) if in_next[i]))


_EMPTY: deque[object] = deque(maxlen=0)
_consume = _EMPTY.extend  # runs an iterator to its end


class LeafNodes:
    """The leaf nodes of one file's compiled lines: one node per proposition for each of a,
    !a, next(a), next(!a) and !next(a), made a column at a time."""

    def __init__(self) -> None:
        self._made: dict[str, dict[str, Formula]] = {factory: {} for factory in _LEAF_PARTS}
        # name -> its Var node (the 'Var' factory makes Vars)
        self.variables: dict[str, Var] = cast('dict[str, Var]', self._made['Var'])

    def __call__(self, factory: str, names: list[str]) -> list[Formula]:
        """The ``factory`` leaf ('Var', 'NotVar', ...) of each of ``names``."""
        made = self._made[factory]
        try:
            return list(map(made.__getitem__, names))
        except KeyError:  # some are new
            pass
        missing = list(set(names).difference(made))
        kind, inner = _LEAF_PARTS[factory]
        nodes: list[Formula] = list(map(object.__new__, itertools.repeat(kind, len(missing))))
        if inner is None:
            _consume(map(FIELD_SETTERS[Var]['name'], nodes, missing))
        else:
            _consume(map(FIELD_SETTERS[kind]['arg'], nodes, self(inner, missing)))
        made.update(zip(missing, nodes))
        return list(map(made.__getitem__, names))


# Each leaf factory: the node's class, and the leaf factory of its argument.
_LEAF_PARTS: dict[str, tuple[type[Var] | type[Not] | type[Next], str | None]] = {'Var': (Var, None), 'NotVar': (Not, 'Var'), 'NextVar': (Next, 'Var'),
               'NextNotVar': (Next, 'NotVar'), 'NotNextVar': (Not, 'NextVar')}


# What a compiled shape's code may use: the shared leaf nodes, and for every other node the
# allocation and the field setters, applied a column at a time with map(): no Python code runs
# per line, which matters for the millions of nodes of a large file (docs/parsing.md); the
# nodes are those the dataclass's __init__ makes.
_BUILDER_NAMES = {
    'TRUE': TRUE, 'FALSE': FALSE, 'new': object.__new__, 'repeat': itertools.repeat, 'consume': _consume,
    **{f'{kind.__name__}_{name}': setter
       for kind in (Not, Next, And, Or, Implies, Iff) for name, setter in FIELD_SETTERS[kind].items()},
    **{kind.__name__: kind for kind in (Not, Next, And, Or, Implies, Iff)},
}


def _leaf(formula: Formula) -> tuple[str, Var] | None:
    """(the shared-leaf factory, its variable) if ``formula`` is a leaf the grammar shares."""
    match formula:
        case Var():
            return 'Var', formula
        case Not(arg=Var() as variable):
            return 'NotVar', variable
        case Next(arg=Var() as variable):
            return 'NextVar', variable
        case Next(arg=Not(arg=Var() as variable)):
            return 'NextNotVar', variable
        case Not(arg=Next(arg=Var() as variable)):
            return 'NotNextVar', variable
    return None


def _builder_source(template: Formula, in_next: list[bool]) -> str:
    """Python source of ``build(columns, n, leaves)``: ``template`` for n lines, its placeholder
    ``_i`` replaced by the propositions of ``columns[i]`` (their leaf nodes from ``leaves``, a
    LeafNodes), one node column (a list over the lines) at a time (``in_next[i]`` is set if
    ``_i`` is read in the next step)."""
    statements: list[str] = []

    def column(formula: Formula, under_next: bool) -> str:
        """The name of a list holding ``formula``'s node for each line, after the statements making it."""
        leaf = _leaf(formula)
        if leaf is not None:
            factory, variable = leaf
            index = int(variable.name[1:])
            in_next[index] = under_next or factory.startswith('Next') or factory == 'NotNextVar'
            return new_column(f'leaves({factory!r}, columns[{index}])')
        if isinstance(formula, Const):
            return new_column('[TRUE] * n' if formula.value else '[FALSE] * n')
        kind = type(formula).__name__
        if isinstance(formula, (Not, Next)):
            fields = {'arg': column(formula.arg, under_next or isinstance(formula, Next))}
        elif isinstance(formula, (And, Or)):
            fields = {'args': 'zip(' + ', '.join(column(arg, under_next) for arg in formula.args) + ')'}
        else:
            assert isinstance(formula, (Implies, Iff))  # the other kinds are handled above
            fields = {'left': column(formula.left, under_next), 'right': column(formula.right, under_next)}
        nodes = new_column(f'list(map(new, repeat({kind}, n)))')
        statements.extend(f'consume(map({kind}_{field}, {nodes}, {values}))' for field, values in fields.items())
        return nodes

    def new_column(expression: str) -> str:
        name = f'c{len(statements)}'
        statements.append(f'{name} = {expression}')
        return name

    result = column(template, False)
    return '\n'.join(['def build(columns, n, leaves):', *(f'    {line}' for line in statements),
                      f'    return {result}'])
