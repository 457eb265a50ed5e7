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
from bisect import bisect_right
import re
import string
from collections import deque
from contextlib import contextmanager
from operator import add

from respec.ltl import (
    FALSE, FIELD_SETTERS, TRUE, And, Const, Formula, Iff, Implies, Next, Not, Or, Var, variables,
)
from respec.spec import FORMULA_SECTIONS, PROPOSITION_SECTIONS, SLUGS_HEADERS, GR1Specification
from respec.parsing.errors import ParseError, UnknownVariableError
from respec.parsing.integers import IntegerVariable
from respec.parsing.grammar import (
    parse_formula, parse_in_scope as _parse, xor,
)
from respec.parsing.quick import quick_infix as _quick_infix, quick_prefix as _quick_prefix
from respec.parsing.scope import (
    ANY as _ANY, KEYWORDS as _KEYWORDS, NAME as _NAME, Scope as _Scope, Source as _Source,
    section_scopes as _scopes,
)

__all__ = [
    'ParseError', 'UnknownVariableError', 'parse_formula', 'parse_structuredslugs',
    'parse_slugsin', 'spec_from_text_sections', 'IntegerVariable', 'xor',
]

_SECTION_OF_HEADER = {header: section for section, header in SLUGS_HEADERS.items()}
_INTEGER_DECLARATION = re.compile(r"^([A-Za-z_][A-Za-z0-9_]*)\s*:\s*(-?[0-9]+)\s*\.\.\.\s*(-?[0-9]+)$")


# --- public API ---------------------------------------------------------------------------

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


_LINES_BETWEEN_CHECKS = 1024


class _SectionText:
    """A section's non-blank lines (comments and surrounding blanks removed), and where each
    one is in the file (worked out only for the lines that need a position: errors)."""

    def __init__(self):
        self.lines: list[str] = []
        self._parts: list[tuple[int, int, list[str], list[int] | None]] = []

    def add(self, first_line: int, contents: list[str]) -> None:
        """The lines after one header; ``first_line``: the file line of ``contents[0]``."""
        stripped = list(map(str.strip, contents))
        while stripped and not stripped[-1]:  # the blank lines before the next header
            stripped.pop()
        kept = [index for index, line in enumerate(stripped) if line] if '' in stripped else None
        self._parts.append((len(self.lines), first_line, contents, kept))
        self.lines.extend(stripped if kept is None else [stripped[index] for index in kept])

    def source(self, index: int, filename: str) -> _Source:
        start, first_line, contents, kept = self._parts[bisect_right(self._parts, (index, 1 << 62)) - 1]
        position = index - start if kept is None else kept[index - start]
        return _Source(filename, first_line + position, _column(contents[position]))


# Line breaks other than '\n' that str.splitlines() also honours.
_OTHER_LINE_BREAKS = '\r\x0b\x0c\x1c\x1d\x1e\x85\u2028\u2029'


def _sections_of(text: str, filename: str) -> dict[str, _SectionText]:
    """Each section's lines: the file is cut at its header lines, not walked line by line."""
    if any(mark in text for mark in _OTHER_LINE_BREAKS):
        text = '\n'.join(text.splitlines())
    sections = {section: _SectionText() for section in PROPOSITION_SECTIONS + FORMULA_SECTIONS}
    section, line, position = None, 1, 0
    for header in itertools.chain(_header_lines(text), [None]):
        chunk = text[position:header[0] if header else len(text)]
        body = chunk.split('\n')
        if not body[-1]:
            body.pop()  # what follows the chunk's last line break
        if '#' in chunk:
            body = [raw.partition('#')[0] for raw in body]
        if section is not None:
            sections[section].add(line, body)
        else:
            for offset, content in enumerate(body):
                if content.strip():
                    raise ParseError('text before the first section header', content.strip(), filename,
                                     line + offset, _column(content))
        if header is None:
            break
        line += chunk.count('\n')
        content = text[header[0]:header[1]].partition('#')[0]
        stripped = content.strip()
        name = stripped[1:-1] if stripped.endswith(']') else None
        if name not in _SECTION_OF_HEADER:
            raise ParseError('unknown section header (expected one of '
                             + ', '.join(f'[{h}]' for h in SLUGS_HEADERS.values()) + ')',
                             stripped, filename, line, _column(content))
        section, line, position = _SECTION_OF_HEADER[name], line + 1, header[1] + 1
    return sections


def _header_lines(text: str):
    """(start, end) of each line whose first non-blank character is '[' (formulas have no '[')."""
    at = text.find('[')
    while at != -1:
        start = text.rfind('\n', 0, at) + 1
        if text[start:at].isspace() or start == at:
            end = text.find('\n', at)
            end = len(text) if end == -1 else end
            yield start, end
            at = text.find('[', end)
        else:
            at = text.find('[', at + 1)


def _parse_slugs_file(text: str, filename: str, syntax: str, check=None) -> GR1Specification:
    sections = _sections_of(text, filename)
    declared: dict[str, list[str]] = {}
    integers: dict[str, IntegerVariable] = {}
    seen: set[str] = set()
    for section in PROPOSITION_SECTIONS:
        declared[section] = []
        for index, name in enumerate(sections[section].lines):
            if (syntax != 'infix' or ':' not in name) and name not in seen \
                    and name not in _KEYWORDS and _NAME.fullmatch(name):
                declared[section].append(name)  # the common case, without an error source
                seen.add(name)
                continue
            source = sections[section].source(index, filename)
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
    leaves = _LeafNodes()
    quick = _quick_infix if syntax == 'infix' else _quick_prefix
    with _collector_paused():
        for section in FORMULA_SECTIONS:
            scope, lines = scopes[section], sections[section].lines
            parsed = _parse_section_by_shapes(lines, syntax, scope, leaves, check) \
                if not scope.integers else [None] * len(lines)
            for index, formula in enumerate(parsed):
                if check is not None and index % _LINES_BETWEEN_CHECKS == 0:
                    check()
                if formula is None:
                    formula = parsed[index] = quick(lines[index], scope, leaves.variables)
                if formula is None:
                    parsed[index] = _parse_line(lines[index], syntax, scope, sections[section].source(index, filename))
            formulas[section] = parsed
    _check_declared_before_use(sections, formulas, integers, filename)
    # Like slugs' compiler, keep integers in range: initially and after every step.
    for variable in integers.values():
        owner = 'env' if variable.bits and variable.bits[0] in declared['env_props'] else 'sys'
        for section, next_step in ((f'{owner}_init', False), (f'{owner}_trans', True)):
            limit = variable.in_range(next_step)
            if limit != TRUE:
                formulas[section].append(limit)
    return GR1Specification(**declared, **formulas)


def _check_declared_before_use(sections, formulas, integers, filename: str) -> None:
    """slugs reads a file top to bottom: a formula may use only variables declared above it.
    Only files with a formula section above a declaration section need the (slower) look."""
    def lines_of(section):  # the file line of each of the section's lines
        return [sections[section].source(index, filename).line
                for index in range(len(sections[section].lines))]
    last_declaration = max((part[1] for section in PROPOSITION_SECTIONS
                            for part in sections[section]._parts), default=0)
    if not any(part[1] < last_declaration for section in FORMULA_SECTIONS
               for part in sections[section]._parts):
        return
    declared_at = {}
    bit_owner = {bit: variable.name for variable in integers.values() for bit in variable.bits}
    for section in PROPOSITION_SECTIONS:
        for name, line in zip(sections[section].lines, lines_of(section)):
            declared_at[name.partition(':')[0].strip()] = line
    for section in FORMULA_SECTIONS:
        for index, (formula, line) in enumerate(zip(formulas[section], lines_of(section))):
            if line > last_declaration:
                continue
            for name in sorted(variables(formula)):
                name = bit_owner.get(name, name)
                if declared_at.get(name, 0) > line:
                    raise sections[section].source(index, filename).error(
                        f"variable '{name}' is used before its section declares it "
                        f'(line {declared_at[name]})', name, 1, 1)


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
# !c", "| ! a | b' c'" ...). A shape is the line with every proposition replaced by a
# placeholder; it is parsed once, by the parser above, and compiled into a function that builds
# the formulas of all lines of that shape together, a node column at a time. The result is the
# very tree the parser would build (a proposition never changes how operators group or fold).
# Lines whose propositions break the section's rules, and unusual lines (very long or deeply
# nested, or whose template folds a proposition away), go through the parser, which explains
# errors.

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
_OUTLINE_WORD = re.compile('[\x00\x02\x03]+')
_OUTLINE_NON_NAME = re.compile('(?<![\x00\x02\x03])[\x02\x03]')  # a number, or a word starting with . or @
_MAX_SHAPE_PLACEHOLDERS = 64
_MAX_SHAPE_NESTING = 32
_SHAPES: dict[str, dict[str, object]] = {}  # syntax -> shape -> compiled (or False)
_MAX_SHAPES = 1 << 14
_LINES_WORTH_COMPILING = 8     # lines sharing a shape before it is compiled
_LINES_WORTH_GROUPING = 1000   # sections this large may be left to the parser whole


def _parse_section_by_shapes(lines: list[str], syntax: str, scope: _Scope, leaves: _LeafNodes,
                             check=None) -> list:
    """The formula of each line, or None where the parser must handle the line.

    The shapes and propositions of all lines are found at once (a few passes of str.translate
    over the joined text, not a scan per line), and the lines of each shape are built together.
    A shape not compiled yet is compiled only when enough lines share it (compiling costs as
    much as parsing a dozen lines); a large section whose lines are mostly unlike each other is
    left to the parser whole.
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
    formulas = [None] * len(lines)
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
        for first in range(0, len(indices), _LINES_BETWEEN_CHECKS):
            if check is not None:
                check()
            chosen = indices[first:first + _LINES_BETWEEN_CHECKS]
            columns = _columns(names, [starts[index] for index in chosen], count)
            if (read_now or read_next) and not _within(scope, columns, read_now, read_next):
                # Some line breaks the rules: the parser names the problem.
                keep = [row for row in range(len(chosen))
                        if _within(scope, [[column[row]] for column in columns], read_now, read_next)]
                chosen = [chosen[row] for row in keep]
                columns = [[column[row] for row in keep] for column in columns]
            for index, formula in zip(chosen, build(columns, len(chosen), leaves)):
                formulas[index] = formula
    return formulas


def _shapes_by_translation(marked: str):
    """(names, starts, lines_of_shape): every proposition in order, where each line's
    propositions start in it, and the lines of each shape. Found with str.translate (a few
    times faster than a regular expression); None when the text needs the expression
    (non-ASCII text, numbers, TRUE / FALSE or a spaced 'next (')."""
    if not marked.isascii():
        return None
    names = marked.translate(_WORDS_ONLY).split()
    if _KEYWORDS.intersection(names):
        return None
    # In a line's outline each word is a run of marks as long as the word; lines are grouped
    # by outline, then outlines by shape (one placeholder per word).
    outline_of_line = marked.translate(_OUTLINE).split('\n')
    lines_of_outline = _positions(outline_of_line)
    if _mostly_unlike(lines_of_outline, len(outline_of_line)):
        return [], [], {}
    word_counts, lines_of_shape = {}, {}
    for outline, indices in lines_of_outline.items():
        if _OUTLINE_NON_NAME.search(outline):
            return None
        shape = _OUTLINE_WORD.sub(_PLACEHOLDER, outline)
        word_counts[outline] = shape.count(_PLACEHOLDER)
        lines_of_shape.setdefault(shape, []).extend(indices)
    return names, list(itertools.accumulate(map(word_counts.__getitem__, outline_of_line), initial=0)), lines_of_shape


def _shapes_by_expression(marked: str):
    """What _shapes_by_translation finds, for any text."""
    parts = _WORD.split(marked)
    names = parts[1::2]
    if _KEYWORDS.intersection(names):  # the slower expression that skips keywords
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


def _mostly_unlike(groups: dict, lines: int) -> bool:
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


def _within(scope: _Scope, columns: list[list[str]], read_now: tuple, read_next: tuple) -> bool:
    """Whether lines read only what the section allows (``read_now``, ``read_next``: the
    columns read in the current and in the next step)."""
    return (scope.current.issuperset(itertools.chain.from_iterable(columns[i] for i in read_now))
            and scope.next_step.issuperset(itertools.chain.from_iterable(columns[i] for i in read_next)))


def _compiled_shape(compiled_shapes: dict, shape: str, syntax: str, count: int):
    """A shape's compiled form (see _compile_shape), kept; False for unusual lines (very long
    or deeply nested), which the parser handles."""
    if count > _MAX_SHAPE_PLACEHOLDERS or shape.count('(') > _MAX_SHAPE_NESTING:
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
    """(build, read_now, read_next), or False when the shape is not a formula (the parser then
    reports the line's error). ``build(columns, n)`` makes the formulas of n lines of the shape,
    where ``columns[i]`` holds each line's i-th proposition; ``read_now`` / ``read_next`` are the
    columns read in the current / in the next step."""
    if syntax == 'prefix' and '$' in shape:
        return False  # memory buffers share subformulas, which a template would copy out
    pieces = shape.replace(_NEXT_MARK, 'next').split(_PLACEHOLDER)
    text = ''.join(piece + (f'_{index}' if index < count else '') for index, piece in enumerate(pieces))
    try:
        template = _parse(text, syntax, _ANY, _Source())
    except ParseError:
        return False
    if variables(template) != {f'_{index}' for index in range(count)}:
        return False  # folded away (e.g. '& 0 a'): the parser still checks the proposition
    in_next = [False] * count
    namespace = dict(_BUILDER_NAMES)
    exec(_builder_source(template, in_next), namespace)  # noqa: S102 -- our own generated code
    return (namespace['build'], tuple(i for i in range(count) if not in_next[i]),
            tuple(i for i in range(count) if in_next[i]))


_consume = deque(maxlen=0).extend  # runs an iterator to its end


class _LeafNodes:
    """The leaf nodes of one file's compiled lines: one node per proposition for each of a,
    !a, next(a), next(!a) and !next(a), made a column at a time."""

    def __init__(self):
        self._made: dict[str, dict[str, Formula]] = {factory: {} for factory in _LEAF_PARTS}
        self.variables: dict[str, Var] = self._made['Var']  # name -> its Var node

    def __call__(self, factory: str, names: list[str]) -> list[Formula]:
        """The ``factory`` leaf ('Var', 'NotVar', ...) of each of ``names``."""
        made = self._made[factory]
        try:
            return list(map(made.__getitem__, names))
        except KeyError:  # some are new
            pass
        missing = list(set(names).difference(made))
        kind, inner = _LEAF_PARTS[factory]
        nodes = list(map(object.__new__, itertools.repeat(kind, len(missing))))
        if inner is None:
            _consume(map(FIELD_SETTERS[Var]['name'], nodes, missing))
        else:
            _consume(map(FIELD_SETTERS[kind]['arg'], nodes, self(inner, missing)))
        made.update(zip(missing, nodes))
        return list(map(made.__getitem__, names))


# Each leaf factory: the node's class, and the leaf factory of its argument.
_LEAF_PARTS = {'Var': (Var, None), 'NotVar': (Not, 'Var'), 'NextVar': (Next, 'Var'),
               'NextNotVar': (Next, 'NotVar'), 'NotNextVar': (Not, 'NextVar')}


# What a compiled shape's code may use: the shared leaf nodes, and for every other node the
# allocation and the field setters, applied a column at a time with map() (no Python code
# runs per line: about five times faster than calling the dataclass's __init__ per node,
# which matters for the millions of nodes of a large file; the nodes are the same).
_BUILDER_NAMES = {
    'TRUE': TRUE, 'FALSE': FALSE, 'new': object.__new__, 'repeat': itertools.repeat, 'consume': _consume,
    **{f'{kind.__name__}_{name}': setter
       for kind in (Not, Next, And, Or, Implies, Iff) for name, setter in FIELD_SETTERS[kind].items()},
    **{kind.__name__: kind for kind in (Not, Next, And, Or, Implies, Iff)},
}


def _leaf(formula: Formula) -> tuple[str, Var] | None:
    """(the shared-leaf factory, its variable) if ``formula`` is a leaf the parser shares."""
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


def _builder_source(template: Formula, in_next: list) -> str:
    """Python source of ``build(columns, n, leaves)``: ``template`` for n lines, its placeholder
    ``_i`` replaced by the propositions of ``columns[i]`` (their leaf nodes from ``leaves``, a
    _LeafNodes), one node column (a list over the lines) at a time (``in_next[i]`` is set if
    ``_i`` is read in the next step)."""
    statements = []

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
            fields = {'left': column(formula.left, under_next), 'right': column(formula.right, under_next)}
        nodes = new_column(f'list(map(new, repeat({kind}, n)))')
        statements.extend(f'consume(map({kind}_{field}, {nodes}, {values}))' for field, values in fields.items())
        return nodes

    def new_column(expression: str) -> str:
        name = f'c{len(statements)}'
        statements.append(f'{name} = {expression}')
        return name

    result = column(template, False)
    return '\n'.join(['def build(columns, n, leaves):', *(f'    {line}' for line in statements), f'    return {result}'])


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

