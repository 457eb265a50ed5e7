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
from contextlib import contextmanager

from respec.ltl import TRUE, Formula, variables
from respec.spec import FORMULA_SECTIONS, PROPOSITION_SECTIONS, SLUGS_HEADERS, GR1Specification
from respec.parsing.errors import ParseError, UnknownVariableError
from respec.parsing.integers import IntegerVariable
from respec.parsing.grammar import (
    parse_formula, parse_in_scope as _parse, xor,
)
from respec.parsing.quick import quick_infix as _quick_infix, quick_prefix as _quick_prefix
from respec.parsing.shapes import (
    LINES_BETWEEN_CHECKS as _LINES_BETWEEN_CHECKS, LeafNodes as _LeafNodes,
    parse_section_by_shapes as _parse_section_by_shapes,
)
from respec.parsing.scope import (
    KEYWORDS as _KEYWORDS, NAME as _NAME, Scope as _Scope, Source as _Source,
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

