"""What a compiled specification was made from, self-contained: the diagnosis needs nothing else.

A ``Provenance`` records the request, the pertinent items and, for every formula, its paper
equation, item and origin in words (the configuration entry or request field), the meaning of
each proposition in a play told in words, and what the robot abstraction alone shows to be
impossible. Everything that needs the robot configuration is computed at compile time
(:func:`task_provenance`), so a specification can be diagnosed wherever it is, with the
settings of whoever holds it (the synthesis node does, in its child process).

It travels as JSON (:func:`provenance_to_json`, :func:`provenance_from_json`; the
``provenance`` fields of the GenerateLTLSpecification response and the SynthesizeAutomaton
request). The text is deterministic: the same compilation always gives the same bytes.
Formulas are written in infix, as in the LTLSpecification message, so they read back equal
to the formulas of the specification sent beside them.
"""

from __future__ import annotations

import json
from dataclasses import asdict, dataclass, field
from typing import Any, Iterable, Mapping, cast

from respec.robot.abstraction import RobotAbstraction
from ltl_specification.components import (SOURCE_ACTIONS, SOURCE_CONTROL_MODES, SOURCE_GOALS, SOURCE_INITIAL_CONDITIONS,
                               SOURCE_SM_OUTCOMES, FormulaGroup)
from respec.ltl import to_infix
from respec.vocabulary.naming import BEHAVIOR_CLASS, activation, memory, outcome_proposition
from respec.parsing import ParseError, parse_formula

from ltl_specification.pertinence import Pertinence
from ltl_specification.reachability import Finding, unreachable_goal_modes

#: Written into every JSON text, so that a reader can refuse texts of another shape.
FORMAT_VERSION = 1


@dataclass
class Provenance:
    """What a compiled specification was made from, and why each item is in it."""

    system: str
    initial_conditions: tuple[str, ...]
    goals: tuple[str, ...]
    sm_outcomes: tuple[str, ...]
    strict_order: bool
    pertinence: Pertinence
    custom_sections: tuple[str, ...] = ()
    # Every formula's origin: paper equation, item and config section or request field.
    groups: tuple[FormulaGroup, ...] = ()
    # For each group (same order), the configuration entry or request field that made it, in words.
    origins: tuple[str, ...] = ()
    # What each proposition of the task means when it turns true in a play, in words.
    meanings: dict[str, str] = field(default_factory=dict)
    # Goals that the configured mode changes make impossible (the pre-check's part that needs
    # the robot abstraction; the custom-LTL part needs only the groups).
    findings: tuple[Finding, ...] = ()

    def origin(self, group: FormulaGroup) -> str:
        """The origin of one of this provenance's groups."""
        return self.origins[next(i for i, g in enumerate(self.groups) if g is group)]


def task_provenance(system: str, abstraction: RobotAbstraction, where: str, initial_conditions: Iterable[str],
                    goals: Iterable[str], sm_outcomes: Iterable[str], strict_order: bool, pertinence: Pertinence,
                    custom_sections: Iterable[str], groups: Iterable[FormulaGroup],
                    flexbe_states: Mapping[str, Any] | None = None) -> Provenance:
    """The provenance of a task compiled for ``system`` on its ``abstraction`` (whose file, as
    users know it, is ``where``); ``flexbe_states`` is the ``flexbe.states`` section of its file
    (if any), which names the state machine's states and outcomes in a play told in words."""
    provenance = Provenance(system, tuple(initial_conditions), tuple(goals), tuple(sm_outcomes),
                            strict_order, pertinence, tuple(custom_sections), tuple(groups))
    provenance.origins = tuple(_origin(group, provenance, abstraction, where) for group in groups)
    provenance.meanings = _meanings(provenance, abstraction, flexbe_states or {})
    if pertinence.initial_mode is not None:
        provenance.findings = tuple(unreachable_goal_modes(abstraction, provenance.goals, pertinence.initial_mode,
                                                           strict_order, where))
    return provenance


def _origin(group: FormulaGroup, provenance: Provenance, abstraction: RobotAbstraction, where: str) -> str:
    """The configuration entry or request field that produced ``group``, in words."""
    if group.source == SOURCE_CONTROL_MODES:
        if group.item:
            targets = ', '.join(abstraction.control_modes.get(group.item, ())) or 'nothing'
            return f'control_modes.{group.item} in {where}: {group.item} -> {targets}'
        return f'control_modes in {where}'
    if group.source == SOURCE_ACTIONS:
        preconditions = ', '.join(abstraction.actions.get(group.item, ())) or 'none'
        return f'actions.{group.item} in {where}: preconditions {preconditions}'
    if group.source == SOURCE_GOALS:
        order = 'in this order' if provenance.strict_order else 'in any order'
        return f'request goals: {", ".join(provenance.goals)} ({order})'
    if group.source == SOURCE_INITIAL_CONDITIONS:
        named = ', '.join(provenance.initial_conditions) or f'initial_mode {provenance.pertinence.initial_mode}'
        return f'request initial conditions: {named}'
    if group.source == SOURCE_SM_OUTCOMES:
        return f'request state-machine outcomes: {", ".join(provenance.sm_outcomes)}'
    return 'request custom LTL'


def _meanings(provenance: Provenance, abstraction: RobotAbstraction, flexbe_states: Mapping[str, Any]) -> dict[str, str]:
    """Proposition -> what it turning true means (activations, outcomes, goal memories, SM outcomes),
    in the state machine's terms where the FlexBE mapping names them: the state (named after its
    action or mode, as ``sm_generation`` names it), its class and the outcome it returns."""
    meaning = {}
    pertinence = provenance.pertinence
    for item in [*pertinence.modes, *pertinence.actions]:
        is_mode = item in pertinence.modes
        state_class, returns = _flexbe_state(flexbe_states, activation(item))
        meaning[activation(item)] = (f'state {item} ({state_class}) starts' if state_class else
                                     f'the robot starts {"changing to " if is_mode else ""}{item}')
        for outcome in abstraction.outcomes:
            proposition = outcome_proposition(item, outcome)
            now_in = is_mode and outcome == abstraction.success_outcome
            if proposition in returns:
                meaning[proposition] = f'{item} returns {returns[proposition]}' + (f' (now in {item})' if now_in else '')
            else:
                meaning[proposition] = f'now in {item}' if now_in else f'{item} {outcome}'
    for goal in provenance.goals:
        meaning[memory(goal)] = f'goal {goal} achieved'
    for outcome in provenance.sm_outcomes:
        meaning[outcome] = f'the state machine ends {outcome}'
    return meaning


def _flexbe_state(flexbe_states: Mapping[str, Any], proposition: str) -> tuple[str, dict[str, str]]:
    """The FlexBE class of the state ``proposition`` activates ('' if unmapped) and, for each
    outcome proposition, the state outcome(s) that mean it (read leniently: sm_generation
    validates the section when it generates the machine)."""
    entry = flexbe_states.get(proposition)
    if not isinstance(entry, Mapping) or not isinstance(entry.get('class_decl'), Mapping):
        return '', {}
    declaration = entry['class_decl']
    state_class = declaration.get('behavior_class') if declaration.get('name') == BEHAVIOR_CLASS else declaration.get('name')
    mapping = cast('Mapping[Any, Any]', entry.get('output_mapping')) if isinstance(entry.get('output_mapping'), Mapping) else {}
    returns = {str(name): ' or '.join(map(str, outcomes)) for name, outcomes in mapping.items()
               if isinstance(outcomes, (list, tuple)) and outcomes}
    return (str(state_class) if state_class else ''), returns


# --- JSON ---------------------------------------------------------------------------------

def provenance_to_json(provenance: Provenance) -> str:
    """The provenance as one deterministic JSON text (formulas in infix)."""
    pertinence = provenance.pertinence
    return json.dumps({
        'format': FORMAT_VERSION, 'system': provenance.system,
        'initial_conditions': list(provenance.initial_conditions), 'goals': list(provenance.goals),
        'sm_outcomes': list(provenance.sm_outcomes), 'strict_order': provenance.strict_order,
        'pertinence': {'initial_mode': pertinence.initial_mode, 'modes': list(pertinence.modes),
                       'actions': list(pertinence.actions), 'reasons': pertinence.reasons,
                       'left_out': pertinence.left_out},
        'custom_sections': list(provenance.custom_sections),
        # Each group as [section, equation, title, item, source, [formulas]]: a 12-goal ATLAS
        # task has ~150 groups (41 KB), and the text travels in one message string (64 KiB at most).
        'groups': [[g.section, g.equation, g.title, g.item, g.source, [to_infix(f) for f in g.formulas]]
                   for g in provenance.groups],
        'origins': list(provenance.origins), 'meanings': provenance.meanings,
        'findings': [asdict(finding) for finding in provenance.findings],
    }, ensure_ascii=False, separators=(',', ':'))


def provenance_from_json(text: str) -> Provenance:
    """The provenance written by :func:`provenance_to_json`; ValueError for any other text."""
    try:
        return _provenance(json.loads(text))
    except (KeyError, TypeError, ValueError, ParseError) as error:  # JSONDecodeError is a ValueError
        raise ValueError(f'not a provenance of format {FORMAT_VERSION}: {error}') from error


def _provenance(data: Any) -> Provenance:
    if data['format'] != FORMAT_VERSION:
        raise ValueError(f'format {data["format"]!r}')
    pertinence = data['pertinence']
    return Provenance(
        data['system'], tuple(data['initial_conditions']), tuple(data['goals']), tuple(data['sm_outcomes']),
        bool(data['strict_order']),
        Pertinence(pertinence['initial_mode'], tuple(pertinence['modes']), tuple(pertinence['actions']),
                   dict(pertinence['reasons']), dict(pertinence['left_out'])),
        tuple(data['custom_sections']),
        tuple(FormulaGroup(section, equation, title, item, source, tuple(parse_formula(f) for f in formulas))
              for section, equation, title, item, source, formulas in data['groups']),
        tuple(data['origins']), dict(data['meanings']),
        tuple(Finding(**finding) for finding in data['findings']))
