"""GR(1) specifications: eight sections over environment (input) and system (output) propositions.

The section names follow the LTLSpecification message; the slugs section headers follow
slugs' file formats. Formulas are ``respec.ltl`` trees; text is made only by the printers.
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields
from typing import Any, Callable, Iterable

from respec.vocabulary.errors import CodedError, ErrorCode
from respec.ltl import Formula, to_infix, to_prefix, variables

PROPOSITION_SECTIONS = ('env_props', 'sys_props')
FORMULA_SECTIONS = ('env_init', 'sys_init', 'env_trans', 'sys_trans', 'env_liveness', 'sys_liveness')
SECTIONS = PROPOSITION_SECTIONS + FORMULA_SECTIONS

# slugs' section headers, in the order slugs' own tools write them.
SLUGS_HEADERS = {
    'env_props': 'INPUT', 'sys_props': 'OUTPUT',
    'env_init': 'ENV_INIT', 'sys_init': 'SYS_INIT',
    'env_trans': 'ENV_TRANS', 'sys_trans': 'SYS_TRANS',
    'env_liveness': 'ENV_LIVENESS', 'sys_liveness': 'SYS_LIVENESS',
}


@dataclass
class GR1Specification:
    """A GR(1) specification: propositions and six formula sections (lists of conjuncts)."""

    env_props: list[str] = field(default_factory=list)
    sys_props: list[str] = field(default_factory=list)
    env_init: list[Formula] = field(default_factory=list)
    sys_init: list[Formula] = field(default_factory=list)
    env_trans: list[Formula] = field(default_factory=list)
    sys_trans: list[Formula] = field(default_factory=list)
    env_liveness: list[Formula] = field(default_factory=list)
    sys_liveness: list[Formula] = field(default_factory=list)

    @property
    def env_prop_set(self) -> frozenset[str]:
        """The environment propositions, for membership tests (never iterate it: unordered)."""
        return frozenset(self.env_props)

    @property
    def sys_prop_set(self) -> frozenset[str]:
        """The system propositions, for membership tests (never iterate it: unordered)."""
        return frozenset(self.sys_props)

    def propositions(self) -> list[str]:
        """All propositions: environment ones first, then system ones, in declared order."""
        return [*self.env_props, *self.sys_props]

    def formulas(self) -> list[Formula]:
        """All formulas of the six formula sections, in section order."""
        return [f for name in FORMULA_SECTIONS for f in getattr(self, name)]

    def undeclared_variables(self) -> list[str]:
        """Names used by some formula but declared in neither proposition list (sorted)."""
        declared = self.env_prop_set | self.sys_prop_set
        used = set().union(*(variables(f) for f in self.formulas()))
        return sorted(used - declared)

    def merge(self, *others: 'GR1Specification') -> 'GR1Specification':
        """A new specification with this one's entries first, then the others' (see module doc)."""
        return merge_specifications([self, *others])

    def to_text_sections(self) -> dict[str, list[str]]:
        """The LTLSpecification message shape: each section as a list of infix strings."""
        sections = {name: list(getattr(self, name)) for name in PROPOSITION_SECTIONS}
        sections.update({name: [to_infix(f) for f in getattr(self, name)] for name in FORMULA_SECTIONS})
        return sections

    def to_structuredslugs(self) -> str:
        """The specification as a ``.structuredslugs`` file (infix formulas)."""
        return self._slugs_text(to_infix)

    def to_slugsin(self) -> str:
        """The specification as a ``.slugsin`` file (prefix formulas, primed next-step variables)."""
        return self._slugs_text(to_prefix)

    def _slugs_text(self, printer: Callable[[Formula], str]) -> str:
        blocks = []
        for name in SECTIONS:
            lines = getattr(self, name)
            if name in FORMULA_SECTIONS:
                lines = [printer(f) for f in lines]
            blocks.append('\n'.join([f'[{SLUGS_HEADERS[name]}]', *lines]))
        return '\n\n'.join(blocks) + '\n'


class PropositionConflictError(CodedError, ValueError):
    """A proposition is declared as both an environment and a system proposition."""

    code = ErrorCode.INVALID_FORMULA


def merge_specifications(specifications: Iterable[GR1Specification]) -> GR1Specification:
    """Conjoin specifications: each section concatenated in order, first appearances kept.

    Raises PropositionConflictError if a proposition would be both input and output.
    """
    # dicts as insertion-ordered sets (of names or of formulas: each section's own type)
    merged: dict[str, dict[Any, None]] = {name: {} for name in SECTIONS}
    for specification in specifications:
        for section in fields(GR1Specification):
            for entry in getattr(specification, section.name):
                merged[section.name].setdefault(entry, None)
    for name in merged['env_props']:
        if name in merged['sys_props']:
            raise PropositionConflictError(
                f'proposition {name!r} is declared as both environment and system proposition', item=name)
    return GR1Specification(**{name: list(entries) for name, entries in merged.items()})
