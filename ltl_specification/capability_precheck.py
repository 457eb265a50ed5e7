"""Impossible requests on a capability robot, named before synthesis (ATLAS's pre-check, for CNU's format).

A synthesizer's verdict "unrealizable" says nothing about why; for robots of our own format
``ltl_specification.diagnosis`` names the impossible part first. For a robot described by CNU's
capability files the same three mistakes are common and visible in the files alone:

* an initial condition that names nothing of the system (a typo, a capability of another robot):
  ``check_capability_names``, before compiling, UNKNOWN_PROPOSITION;
* a goal no capability can make true: its memory (or integer value) is not set by any
  postcondition and does not hold initially, INVALID_GOALS;
* a precondition nothing establishes: no postcondition, initial value or environment input can
  make any term of it true, so its capability can never start, ABSTRACTION_CONFIG_INVALID.

The last two are ``check_capability_task``'s, run after the compiler accepted the files (their
own errors, such as a condition naming an unknown proposition, come first). Each error is one
plain sentence naming the item and the file entry to change.

Why the reasoning is exact enough to refuse: the compiler lets a memory or system integer change
only through a postcondition (its frame axiom keeps it otherwise, whatever the spec file's
formulas say), so a value that holds neither initially nor after any postcondition never holds.
Everything else (activations, outcomes, the spec file's INPUTs and OUTPUTs, environment
integers) is counted as possibly true. CNU's full-spec pipeline is not checked: its spec file
is the whole specification, and its formulas may set any output.
"""

from __future__ import annotations

from typing import Iterable, Sequence

from respec.vocabulary.naming import activation, did_you_mean, memory
from respec.robot import RobotSystem
from respec.robot.cnu import (CAPABILITIES_KEY, SPEC_KEY, CapabilityConfigError, CapabilitySystem, Literal,
                              parse_literal)

from ltl_specification.errors import InvalidGoalsError, UnknownPropositionError

REQUEST_INITIAL_CONDITIONS = "the request's initial conditions"


def check_capability_names(system: RobotSystem, initial_conditions: Sequence[str]) -> None:
    """Raise the first ``unknown_initial_conditions`` error (the names are checked before compiling,
    so the sentence names the entry to change rather than a formula the compiler was building)."""
    errors = [] if system.required_capabilities().full_spec else unknown_initial_conditions(system, initial_conditions)
    if errors:
        raise errors[0]


def check_capability_task(system: RobotSystem, initial_conditions: Sequence[str], goals: Sequence[str]) -> None:
    """Raise the first goal or precondition that can never become true (see the module doc)."""
    if system.required_capabilities().full_spec:
        return
    errors = [*unreachable_goals(system, initial_conditions, goals),
              *unestablished_preconditions(system, initial_conditions)]
    if errors:
        raise errors[0]


def system_names(capabilities: CapabilitySystem) -> set[str]:
    """Every name a condition may use, as the files declare them: capabilities and memories (their
    memory propositions), integers, the spec's INPUTs and OUTPUTs, activations, SM outcomes and
    every capability's outcome propositions (whether its FlexBE class has the outcome is checked
    by the compiler)."""
    names = {*capabilities.capabilities, *capabilities.memory, *capabilities.integers,
             *capabilities.spec_inputs, *capabilities.spec_outputs, *capabilities.sm_outcomes.values()}
    for name in capabilities.capabilities:
        names.add(activation(name))
        names.update(capabilities.outcome_proposition(name, t) for t in capabilities.transition_outcomes)
    return names


def unknown_initial_conditions(system: RobotSystem, initial_conditions: Sequence[str]) -> list[UnknownPropositionError]:
    """An initial condition of the request or the spec file that names nothing of the system: a
    misspelt or foreign name would otherwise be reported as a formula the compiler cannot build."""
    capabilities = system.required_capabilities()
    known = system_names(capabilities)
    listed = sorted(n for n in known if not _is_outcome(capabilities, n))
    errors = []
    for text, entry in _initial_entries(system, initial_conditions):
        literal = _literal(capabilities, text)
        if literal is None or literal.name in known:
            continue
        errors.append(UnknownPropositionError(
            f'Initial condition {text!r} names nothing of {capabilities.system} (no capability, memory, integer or '
            f'proposition is called {literal.name}{did_you_mean(literal.name, listed)}): change {entry} '
            f'(known: {", ".join(listed)}).', item=text))
    return errors


def unreachable_goals(system: RobotSystem, initial_conditions: Sequence[str],
                      goals: Sequence[str]) -> list[InvalidGoalsError]:
    """A goal on a memory or integer that neither holds initially nor is set by any postcondition:
    the frame axioms keep it false forever, so synthesis could only answer "unrealizable"."""
    capabilities = system.required_capabilities()
    initial = _initial_values(capabilities, initial_conditions)
    errors = []
    for goal in goals:
        literal = _literal(capabilities, goal)
        if literal is None or _can_hold(capabilities, literal, initial):
            continue
        errors.append(InvalidGoalsError(
            f'Goal {goal!r} can never be reached: no capability sets {_value_words(literal)} and it '
            f'{_initially_words(literal, initial)}; add {_term_text(literal)!r} to the '
            f'postconditions of the capability that achieves it in {capability_file(system)}, or change the '
            "request's goals.", item=goal))
    return errors


def unestablished_preconditions(system: RobotSystem,
                                initial_conditions: Sequence[str]) -> list[CapabilityConfigError]:
    """A precondition entry none of whose terms can ever hold: its capability can never start, and
    a task that needs it would be refused as unrealizable without naming it."""
    capabilities = system.required_capabilities()
    initial = _initial_values(capabilities, initial_conditions)
    errors = []
    for name, capability in capabilities.capabilities.items():
        for clause in capability.preconditions:
            if any(_can_hold(capabilities, term, initial) for term in clause):
                continue
            entry = clause_text(clause)
            reasons = '; '.join(f'{_value_words(term)} is set by no postcondition and it '
                                f'{_initially_words(term, initial)}' for term in clause)
            errors.append(CapabilityConfigError(
                f'Capability {name!r} can never start: nothing establishes its precondition {entry!r} ({reasons}); '
                f'change {name}.preconditions or add a postcondition that sets it in {capability_file(system)}.',
                item=f'{name}.preconditions'))
    return errors


# --- values ----------------------------------------------------------------------------------

def _can_hold(capabilities: CapabilitySystem, literal: Literal, initial: dict[str, set[int | bool]]) -> bool:
    """Whether ``literal`` holds initially or after some postcondition; a name the frames do not
    keep (a proposition, an environment integer, an unknown name) counts as possibly true."""
    values = _possible_values(capabilities, literal.name, initial)
    if values is None:
        return True
    if literal.value is not None:
        return bool(values - {literal.value}) if literal.negated else literal.value in values
    return (not literal.negated) in values


def _possible_values(capabilities: CapabilitySystem, name: str,
                     initial: dict[str, set[int | bool]]) -> set[int | bool] | None:
    """The values a memory or system integer can ever take (None for anything else)."""
    integer = capabilities.integers.get(name)
    if integer is not None and integer.environment:
        return None
    if integer is None and name not in capabilities.capabilities and name not in capabilities.memory:
        return None
    values = set(initial[name])
    everything: set[int | bool] = set(range(integer.low, integer.high + 1)) if integer else {False, True}
    for capability in capabilities.capabilities.values():
        for literals in capability.postconditions.values():
            for literal in literals:
                if literal.name == name:
                    values |= _values_of(literal, everything)
    return values


def _values_of(literal: Literal, everything: set[int | bool]) -> set[int | bool]:
    """The values a postcondition or initial literal sets its variable to."""
    if literal.choose:
        return set(everything)
    if literal.value is None:
        return {not literal.negated}
    return everything - {literal.value} if literal.negated else {literal.value}


def _initial_values(capabilities: CapabilitySystem, initial_conditions: Sequence[str]) -> dict[str, set[int | bool]]:
    """Each memory's and integer's initial values, as the compiler sets them: declared (memories
    false unless the memory section says otherwise, integers at their lowest value), then the spec
    file's initial entries, then the request's (a later literal replaces an earlier one)."""
    initial: dict[str, set[int | bool]] = {name: {False} for name in capabilities.capabilities}
    initial.update({name: {value} for name, value in capabilities.memory.items()})
    initial.update({name: {integer.low} for name, integer in capabilities.integers.items()})
    for text in [*capabilities.spec_initial, *initial_conditions]:
        literal = _literal(capabilities, text)
        if literal is not None and literal.name in initial:
            integer = capabilities.integers.get(literal.name)
            everything: set[int | bool] = set(range(integer.low, integer.high + 1)) if integer else {False, True}
            initial[literal.name] = _values_of(literal, everything)
    return initial


def _literal(capabilities: CapabilitySystem, text: str) -> Literal | None:
    """``text`` read as the compiler reads it; None when it does not parse (the compiler says why)."""
    try:
        return parse_literal(text, text, capabilities.system, capabilities.integers, False)
    except CapabilityConfigError:
        return None


# --- words -----------------------------------------------------------------------------------

def _initial_entries(system: RobotSystem, initial_conditions: Sequence[str]) -> list[tuple[str, str]]:
    """Each initial condition with the entry a user changes: the spec file's section or the request."""
    spec_file = system.sections.get(SPEC_KEY)
    sections = {text: section.upper() for section, text in system.required_capabilities().spec_formulas
                if section in ('env_init', 'sys_init')}
    entries = [(text, f'specs.{sections[text]} in {spec_file}' if text in sections and spec_file
                else f'the initial state of {system.config_file}') for text in system.required_capabilities().spec_initial]
    return entries + [(text, REQUEST_INITIAL_CONDITIONS) for text in initial_conditions]


def capability_file(system: RobotSystem) -> str:
    """The capability file as the system file names it (where pre- and postconditions are)."""
    return str(system.sections.get(CAPABILITIES_KEY) or system.config_file)


def _is_outcome(capabilities: CapabilitySystem, name: str) -> bool:
    """Outcome propositions are left out of the names offered: they cannot hold initially."""
    return any(name == capabilities.outcome_proposition(c, t)
               for c in capabilities.capabilities for t in capabilities.transition_outcomes)


def _value_words(literal: Literal) -> str:
    """What a postcondition would have to set (``pick_m true``, ``bin to 2``)."""
    if literal.value is not None:
        return f'{literal.name} {"to a value other than" if literal.negated else "to"} {literal.value}'
    return f'{memory(literal.name)} {"false" if literal.negated else "true"}'


def _initially_words(literal: Literal, initial: dict[str, set[int | bool]]) -> str:
    """How the variable starts, as the compiler sets it (``starts false``, ``starts at 0``)."""
    values = sorted(initial[literal.name])
    if literal.value is not None:
        return f'starts at {", ".join(str(v) for v in values)}'
    return f'starts {"true" if values == [True] else "false"}'


def clause_text(clause: Iterable[Literal]) -> str:
    """A precondition clause (its literals, any of which may hold) as the files write it."""
    return ' | '.join(_term_text(term) for term in clause)


def _term_text(literal: Literal) -> str:
    """The literal as the files write it."""
    if literal.value is not None:
        return f'{literal.name}{"!=" if literal.negated else "="}{literal.value}'
    return f'{"!" if literal.negated else ""}{literal.name}'
