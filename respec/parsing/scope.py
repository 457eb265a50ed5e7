"""What a formula may mention, and where its text comes from.

Proposition names and keywords; each formula section's scope, following slugs
(src/synthesisContextBasics.cpp): [ENV_INIT] may mention only current input variables,
[SYS_INIT] only current variables, [ENV_TRANS] no next-step output. ``Source`` places a
formula's text in its file or message section, for error positions.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

from respec.vocabulary.errors import quoted
from respec.parsing.errors import ParseError, UnknownVariableError
from respec.parsing.integers import IntegerVariable
from respec.spec import SLUGS_HEADERS

NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_.@]*")
KEYWORDS = {'TRUE', 'FALSE', 'next'}


@dataclass(frozen=True)
class Source:
    """Where a formula's text comes from: for error positions."""

    filename: str = '<string>'
    line: int = 1
    column: int = 1

    def error(self, problem: str, token: str, line: int, column: int,
              kind: type[ParseError] = ParseError) -> ParseError:
        # Positions inside the text are relative to its first character.
        absolute_column = column + self.column - 1 if line == 1 else column
        return kind(problem, token, self.filename, self.line + line - 1, absolute_column)


@dataclass(frozen=True)
class Scope:
    """Which propositions a formula may use, and which of them in the next step."""

    names: frozenset[str] | None        # None: any name (parse_formula without declarations)
    current: frozenset[str]             # read only when names is set
    next_step: frozenset[str]
    section: str = ''
    integers: dict[str, IntegerVariable] = field(default_factory=dict)   # structured slugs' integers by name


ANY = Scope(None, frozenset(), frozenset())


def scope_problem(scope: Scope, name: str, next_step: bool) -> str:
    """Why ``scope`` does not allow ``name`` (in the next step if ``next_step``); '' if it does."""
    if scope.names is None:
        return ''
    where = f' in {scope.section}' if scope.section else ''
    if name not in scope.names:
        return f'unknown variable {quoted(name)}{where}'
    allowed = scope.next_step if next_step else scope.current
    if name not in allowed:
        step = 'next-step' if next_step else 'current'
        return f'{step} variable {quoted(name)} is not allowed{where}'
    return ''


def error_kind(problem: str) -> type[ParseError]:
    """The error class of a scope problem: an undeclared proposition has its own."""
    return UnknownVariableError if problem.startswith('unknown') else ParseError


def section_scopes(env_props: list[str], sys_props: list[str],
                   integers: dict[str, IntegerVariable] | None = None) -> dict[str, Scope]:
    """slugs' rules for which variables each formula section may read (synthesisContextBasics.cpp)."""
    inputs, outputs = frozenset(env_props), frozenset(env_props) | frozenset(sys_props)
    nothing: frozenset[str] = frozenset()

    def scope(section: str, current: frozenset[str], next_step: frozenset[str]) -> Scope:
        return Scope(outputs, current, next_step, f'[{SLUGS_HEADERS[section]}]', integers or {})

    return {
        'env_init': scope('env_init', inputs, nothing),
        'sys_init': scope('sys_init', outputs, nothing),
        'env_trans': scope('env_trans', outputs, inputs),
        'sys_trans': scope('sys_trans', outputs, outputs),
        'env_liveness': scope('env_liveness', outputs, outputs),
        'sys_liveness': scope('sys_liveness', outputs, outputs),
    }
