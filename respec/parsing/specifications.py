"""Specifications from text: slugs' two file formats and the LTLSpecification message's sections.

A file's sections (respec.parsing.files) are read by shape where many lines share one
(respec.parsing.shapes), else line by line by the quick readers (respec.parsing.quick), and
any line they leave, with every error, by the grammar (respec.parsing.grammar).
"""

from __future__ import annotations

import gc
import re
from contextlib import contextmanager
from typing import Callable, Iterator, cast

from respec.ltl import TRUE, Formula, variables
from respec.parsing.errors import ParseError, UnknownVariableError
from respec.parsing.files import SectionText, sections_of
from respec.parsing.grammar import parse_in_scope
from respec.parsing.integers import IntegerVariable
from respec.parsing.quick import quick_infix, quick_prefix
from respec.parsing.scope import KEYWORDS, NAME, Scope, Source, section_scopes
from respec.parsing.shapes import LINES_BETWEEN_CHECKS, LeafNodes, parse_section_by_shapes
from respec.spec import FORMULA_SECTIONS, PROPOSITION_SECTIONS, GR1Specification

_INTEGER_DECLARATION = re.compile(r"^([A-Za-z_][A-Za-z0-9_]*)\s*:\s*(-?[0-9]+)\s*\.\.\.\s*(-?[0-9]+)$")


def parse_structuredslugs(text: str, filename: str = '<string>',
                          check: Callable[[], object] | None = None) -> GR1Specification:
    """Parse a ``.structuredslugs`` file: one infix conjunct per non-empty line.

    Like slugs' structured compiler, a line that is not infix but is a valid slugsin prefix
    formula is accepted as prefix. ``check``, if given, is called every 1,024 lines (e.g. a
    synthesizer's Interrupt, which raises to stop a long parse).
    """
    return _parse_slugs_file(text, filename, 'infix', check)


def parse_slugsin(text: str, filename: str = '<string>',
                  check: Callable[[], object] | None = None) -> GR1Specification:
    """Parse a ``.slugsin`` file: one prefix conjunct per non-empty line (``check``: as above)."""
    return _parse_slugs_file(text, filename, 'prefix', check)


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
    declared: dict[str, list[str]] = {}
    for section in PROPOSITION_SECTIONS:
        declared[section] = []
        for index, name in enumerate(sections.get(section, [])):
            _check_proposition_name(name.strip(), seen, 'message', Source(f'{section}[{index}]'))
            declared[section].append(name.strip())
            seen.add(name.strip())

    scopes = section_scopes(declared['env_props'], declared['sys_props'])
    formulas = {
        section: [parse_in_scope(text, 'infix', scopes[section], Source(f'{section}[{index}]'))
                  for index, text in enumerate(sections.get(section, []))]
        for section in FORMULA_SECTIONS}
    return GR1Specification(env_props=declared['env_props'], sys_props=declared['sys_props'], **formulas)


def _parse_slugs_file(text: str, filename: str, syntax: str,
                      check: Callable[[], object] | None = None) -> GR1Specification:
    sections = sections_of(text, filename)
    declared: dict[str, list[str]] = {}
    integers: dict[str, IntegerVariable] = {}
    seen: set[str] = set()
    for section in PROPOSITION_SECTIONS:
        declared[section] = []
        for index, name in enumerate(sections[section].lines):
            if (syntax != 'infix' or ':' not in name) and name not in seen \
                    and name not in KEYWORDS and NAME.fullmatch(name):
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

    scopes = section_scopes(declared['env_props'], declared['sys_props'], integers)
    formulas: dict[str, list[Formula]] = {}
    leaves = LeafNodes()
    quick = quick_infix if syntax == 'infix' else quick_prefix
    with _collector_paused():
        for section in FORMULA_SECTIONS:
            scope, lines = scopes[section], sections[section].lines
            parsed: list[Formula | None] = parse_section_by_shapes(lines, syntax, scope, leaves, check) \
                if not scope.integers else [None] * len(lines)
            for index, formula in enumerate(parsed):
                if check is not None and index % LINES_BETWEEN_CHECKS == 0:
                    check()
                if formula is None:
                    formula = parsed[index] = quick(lines[index], scope, leaves.variables)
                if formula is None:
                    parsed[index] = _parse_line(lines[index], syntax, scope, sections[section].source(index, filename))
            formulas[section] = cast('list[Formula]', parsed)  # each None was replaced by a formula
    _check_declared_before_use(sections, formulas, integers, filename)
    # Like slugs' compiler, keep integers in range: initially and after every step.
    for variable in integers.values():
        owner = 'env' if variable.bits and variable.bits[0] in declared['env_props'] else 'sys'
        for section, next_step in ((f'{owner}_init', False), (f'{owner}_trans', True)):
            limit = variable.in_range(next_step)
            if limit != TRUE:
                formulas[section].append(limit)
    return GR1Specification(env_props=declared['env_props'], sys_props=declared['sys_props'], **formulas)


def _check_declared_before_use(sections: dict[str, SectionText], formulas: dict[str, list[Formula]],
                               integers: dict[str, IntegerVariable], filename: str) -> None:
    """slugs reads a file top to bottom: a formula may use only variables declared above it.
    Only files with a formula section above a declaration section need the (slower) look."""
    def lines_of(section: str) -> list[int]:  # the file line of each of the section's lines
        return [sections[section].source(index, filename).line
                for index in range(len(sections[section].lines))]
    last_declaration = max((first for section in PROPOSITION_SECTIONS
                            for first in sections[section].first_lines()), default=0)
    if not any(first < last_declaration for section in FORMULA_SECTIONS
               for first in sections[section].first_lines()):
        return
    declared_at: dict[str, int] = {}
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


def _integer_variable(declaration: re.Match[str], seen: set[str], source: Source) -> IntegerVariable:
    name, low, high = declaration.group(1), int(declaration.group(2)), int(declaration.group(3))
    if low > high:
        raise source.error(f'empty integer range {low}...{high}', name, 1, 1)
    variable = IntegerVariable(name, low, high)
    for taken in [name] + variable.bits:
        if taken in seen or taken in KEYWORDS:
            raise source.error('proposition declared twice', taken, 1, 1)
    return variable


@contextmanager
def _collector_paused() -> Iterator[None]:
    """Python's cyclic garbage collector off while a file's formula trees are built: trees
    have no cycles, and its passes over millions of new nodes are slow (docs/parsing.md)."""
    was_enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if was_enabled:
            gc.enable()


def _parse_line(line: str, syntax: str, scope: Scope, source: Source) -> Formula:
    try:
        return parse_in_scope(line, syntax, scope, source)
    except ParseError as infix_error:
        if syntax != 'infix' or isinstance(infix_error, UnknownVariableError):
            raise
        try:
            return parse_in_scope(line, 'prefix', scope, source)
        except ParseError:
            raise infix_error from None


def _check_proposition_name(name: str, seen: set[str], syntax: str, source: Source) -> None:
    if ':' in name and syntax == 'infix':
        raise source.error('invalid integer declaration (expected name: low...high)',
                           name.split(':', 1)[0].strip(), 1, 1)
    if not NAME.fullmatch(name) or name in KEYWORDS:
        raise source.error('invalid proposition name', name, 1, 1)
    if name in seen:
        raise source.error('proposition declared twice', name, 1, 1)
