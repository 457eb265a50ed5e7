"""GR(1) specifications for robots described by capabilities (CNU's flexbe_synthesis format).

Our encoding of a capability system (see ``respec.robot.cnu`` for the file format). For
each capability ``c``: a system proposition ``c_a`` (c runs) and one environment proposition
per transition outcome its FlexBE outcomes mean (``c_c`` completed, ``c_f`` failure).

Environment (assumptions)
  * no outcome initially; no outcome of ``c`` unless ``c`` ran; at most one at a time;
  * fairness: a capability that keeps running eventually completes, □◇(¬c_a ∨ ◯c_c);
  * the spec file's INPUTs (sensors) change as its ENV_TRANS and ENV_LIVENESS say; a state
    observes one when ENV_TRANS binds the sensor to that capability's outcomes
    (``check_l' <-> (check_a & low')``): FlexBE sees outcomes only (``sm_generation.capabilities``).

System (guarantees)
  * exactly one capability runs, or the machine has ended in an SM outcome, at every step
    after the first (CNU's one-hot activation); SM outcomes are final;
  * a running capability keeps running until one of its outcomes arrives (FlexBE cannot
    leave a state that has not returned);
  * ``preconditions`` hold whenever a capability starts (or restarts after an outcome);
  * ``transition_relation``: after outcome ``t`` of ``c``, the next capability is one of
    each listed choice;
  * a requested ``failed`` (``_machine_outcomes``): a failure no transition relation handles
    ends the machine in ``failed``; otherwise failures are retried;
  * ``postconditions``: outcome ``t`` of ``c`` sets the listed memories and integers in the
    same step (``@x`` lets the system choose ``x``); memories and integers keep their values
    otherwise;
  * the request: initial conditions set initial values (a capability or memory name means its
    memory, ``c_a`` starts ``c``, ``x=2`` an integer); the goals' conjunction is reached, then
    the machine ends in its success outcome (``finished``), □◇finished — or, when the system
    has no SM outcomes (CNU's "infinite" mappings), each goal holds infinitely often.

Initial values not given by the request or the spec file: no capability runs, memories as
declared (default false), integers at their lowest value; a spec INPUT (a sensor) may start
either way (slugs' meaning of a variable ENV_INIT does not constrain). The spec file's other formulas
(ENV_TRANS, SYS_TRANS, the livenesses) are added as they are (CNU's capability pipeline loads the
spec file first and adds the capabilities' formulas to it).

Without goals (CNU's request semantics) the request adds no success formula: the capabilities
or the spec file already say what the machine does (a given machine, CNU's ``sm/`` route, is
one: its transition relation leaves the strategy no choice).

CNU's full-spec pipeline (``cnu_pipeline: full_spec``) takes the spec file as the whole
specification; the request adds its initial conditions (each replaces the file's initial
literal of the same proposition) and its goals, as CNU's request semantics say: with a success
outcome among the file's outputs, reaching the goals' conjunction raises it and nothing else
does, ``(!goal & X goal) -> X success`` and ``(!X goal & !success) -> !X success``; without one,
each goal holds infinitely often. A goal or initial condition that names a capability with a
memory proposition in the file (``soda`` -> ``soda_m``) means the memory.
"""

from __future__ import annotations

from typing import Mapping, Sequence

from respec.vocabulary.errors import CodedError
from respec.robot.cnu import FAILURE, CapabilityConfigError, CapabilitySystem, Literal, parse_literal
from respec.ltl import TRUE, Formula, Not, Var, conj, disj, iff, implies, neg, next_, var, variables
from respec.vocabulary.naming import COMPLETED, FAILED, FINISHED, activation, did_you_mean, memory, remembered
from respec.parsing import IntegerVariable
from respec.parsing.errors import ParseError
from respec.parsing.grammar import parse_in_scope
from respec.parsing.scope import Source, section_scopes
from respec.spec import FORMULA_SECTIONS, GR1Specification
from respec.robot.state_library import StateClass, capability_outcomes

from ltl_specification.errors import (InvalidFormulaError, InvalidGoalsError, InvalidInitialConditionsError,
                                      InvalidSmOutcomesError, UnknownPropositionError)



class CapabilitySpecification:
    """The propositions of a capability system and the literals over them (current or next step)."""

    def __init__(self, system: CapabilitySystem, outcomes: Mapping[str, tuple[str, ...]],
                 sm_outcomes: Sequence[str] = ()):
        self.system = system
        self.outcome_props: dict[str, dict[str, str]] = {}   # capability -> transition outcome -> proposition
        for name in system.capabilities:
            meanings = {system.transition_outcome(name, o) for o in outcomes[name]}
            self.outcome_props[name] = {t: system.outcome_proposition(name, t)
                                        for t in system.transition_outcomes if t in meanings}
        self.activations = {name: activation(name) for name in system.capabilities}
        self.success, self.failed, self.ending_failures = _machine_outcomes(system, self.outcome_props, sm_outcomes)
        named = [system.sm_outcomes[t.name] for c in system.capabilities.values()
                 for clauses in c.transition_relation.values() for clause in clauses for t in clause
                 if t.name in system.sm_outcomes]
        self.sm_props = list(dict.fromkeys(o for o in [self.success, *named, self.failed] if o))
        self.integers = {name: IntegerVariable(name, r.low, r.high) for name, r in system.integers.items()}
        self.memories = dict.fromkeys(system.capabilities, False)
        self.memories.update(system.memory)
        self.env_props = [p for props in self.outcome_props.values() for p in props.values()]
        self.env_props += [p for p in system.spec_inputs if p not in self.env_props]
        self.sys_props = [*self.activations.values(), *self.sm_props]
        self.sys_props += [p for p in system.spec_outputs if p not in self.sys_props]
        for name, integer in self.integers.items():
            (self.env_props if system.integers[name].environment else self.sys_props).extend(integer.bits)
        self.used_memories: dict[str, None] = {}

    def propositions(self) -> set[str]:
        return set(self.env_props) | set(self.sys_props)

    def atom(self, literal: Literal, next_step: bool, item: str,
             error: type[CodedError] = CapabilityConfigError) -> Formula:
        """The formula of a literal; a capability or memory name means its memory proposition."""
        if literal.value is not None:
            formula = self.integers[literal.name].equals(literal.value, next_step)
            return neg(formula) if literal.negated else formula
        if literal.name in self.memories:
            self.used_memories.setdefault(literal.name)
            name = memory(literal.name)
        elif literal.name in self.propositions():
            name = literal.name
        else:
            known = sorted(n for n in {*self.memories, *self.propositions(), *self.integers} if '@' not in n)
            raise error(f'{self.system.system}: {item} names {literal.name!r}, which is no capability, memory, '
                        f'integer or proposition of the system{did_you_mean(literal.name, known)} '
                        f'(known: {", ".join(known)})', item=literal.name)
        formula = next_(var(name)) if next_step else var(name)
        return neg(formula) if literal.negated else formula

    def outcome_next(self, capability: str) -> Formula:
        return disj(next_(var(p)) for p in self.outcome_props[capability].values())


def compile_capability_task(system: CapabilitySystem, library: Mapping[str, StateClass],
                            initial_conditions: Sequence[str], goals: Sequence[str],
                            custom_ltl: Mapping[str, Sequence[str]] | None = None,
                            sm_outcomes: Sequence[str] = ()) -> GR1Specification:
    """The GR(1) specification of reaching ``goals`` from ``initial_conditions`` on ``system``,
    with the requested state-machine outcomes ``sm_outcomes`` (CNU's request semantics: the
    first one that is not ``failed`` is the success outcome, ``finished`` when none is given).

    State classes are checked against ``library`` first (StateClassError names the bad one).
    """
    if custom_ltl and any(custom_ltl.get(s) for s in FORMULA_SECTIONS + ('env_props', 'sys_props')):
        raise InvalidFormulaError(f'{system.system} is described by capabilities; custom LTL is not supported '
                                  'for it (put the formulas into its capability file)', item=system.system)
    spec = CapabilitySpecification(system, capability_outcomes(system, library), sm_outcomes)
    if system.full_spec:
        return _full_specification(spec, initial_conditions, goals)
    parts: dict[str, list[Formula]] = {section: [] for section in FORMULA_SECTIONS}
    _environment(spec, parts)
    _activations(spec, parts)
    _failures(spec, parts)
    if goals:
        _goals(spec, goals, parts)
    setters = _conditions(spec, parts)
    _initial_values(spec, initial_conditions, parts)
    _spec_file_formulas(spec, parts)
    _frames(spec, setters, parts)
    memories = [memory(m) for m in spec.used_memories]
    return GR1Specification(env_props=list(spec.env_props), sys_props=[*spec.sys_props, *memories], **parts)


def _machine_outcomes(system: CapabilitySystem, outcome_props: Mapping[str, Mapping[str, str]],
                      requested: Sequence[str]) -> tuple[str | None, str | None, list[str]]:
    """The machine's success outcome, its failure outcome and the failure outcomes that end in it.

    The success outcome is the first requested outcome that is not ``failed`` (``finished`` by
    default), as the mappings name it; a system without SM outcomes (CNU's infinite mappings)
    never ends. A requested ``failed`` ends the machine after every failure its capabilities'
    transition relations do not handle (their ``failure`` outcome, CNU's failure transition
    outcome); without it those failures are retried. No capability that can fail: nothing to end.
    """
    wanted = [o for o in requested if o != FAILED][:1] or [FINISHED]
    success = None
    if system.sm_outcomes:
        if wanted[0] not in system.sm_outcomes and wanted[0] not in system.sm_outcomes.values():
            raise InvalidSmOutcomesError(
                f'{system.system}: state-machine outcome {wanted[0]!r} is not one of its mappings\' '
                f'sm_outcome_mappings ({", ".join(system.sm_outcomes)})', item=wanted[0])
        success = system.sm_outcome(wanted[0])
    ending = [props[FAILURE] for name, props in outcome_props.items()
              if FAILURE in props and FAILURE not in system.capabilities[name].transition_relation]
    if FAILED not in requested or not ending or not system.sm_outcomes:
        return success, None, []
    return success, system.sm_outcome(FAILED), ending


def _environment(spec: CapabilitySpecification, parts: dict[str, list[Formula]]) -> None:
    for name, props in spec.outcome_props.items():
        running = var(spec.activations[name])
        outcomes = list(props.values())
        parts['env_init'] += [neg(var(p)) for p in outcomes]
        parts['env_trans'] += [implies(neg(running), neg(next_(var(p)))) for p in outcomes]
        parts['env_trans'] += [neg(conj([next_(var(a)), next_(var(b))]))
                               for i, a in enumerate(outcomes) for b in outcomes[i + 1:]]
        progress = props.get(COMPLETED) or (outcomes[0] if outcomes else None)
        if progress:
            parts['env_liveness'].append(disj([neg(running), next_(var(progress))]))


def _activations(spec: CapabilitySpecification, parts: dict[str, list[Formula]]) -> None:
    activities = [*spec.activations.values(), *spec.sm_props]
    parts['sys_trans'].append(disj(next_(var(a)) for a in activities))
    parts['sys_trans'] += [neg(conj([next_(var(a)), next_(var(b))]))
                           for i, a in enumerate(activities) for b in activities[i + 1:]]
    parts['sys_init'] += [neg(conj([var(a), var(b)])) for i, a in enumerate(activities) for b in activities[i + 1:]]
    parts['sys_trans'] += [implies(var(o), next_(var(o))) for o in spec.sm_props]
    for name, active in spec.activations.items():
        parts['sys_trans'].append(implies(conj([var(active), neg(spec.outcome_next(name))]),
                                          next_(var(active))))


def _failures(spec: CapabilitySpecification, parts: dict[str, list[Formula]]) -> None:
    """A requested ``failed``: a failure no transition relation handles ends the machine there,
    and nothing else does (a failure that a transition relation handles is followed as it says)."""
    if spec.failed is None:
        return
    failed = var(spec.failed)
    parts['sys_trans'] += [implies(next_(var(p)), next_(failed)) for p in spec.ending_failures]
    failures = [props[FAILURE] for props in spec.outcome_props.values() if FAILURE in props]
    parts['sys_trans'].append(implies(next_(failed), disj([failed, *(next_(var(p)) for p in failures)])))


def _conditions(spec: CapabilitySpecification, parts: dict[str, list[Formula]]) -> dict[str, list[Formula]]:
    """Preconditions, transition relations and postconditions; returns the outcomes that set
    each memory or integer (the others keep their values)."""
    system = spec.system
    setters: dict[str, list[Formula]] = {}   # memory or integer -> the outcomes (next step) that set it
    for name, capability in system.capabilities.items():
        activation = var(spec.activations[name])
        if capability.preconditions:
            required = conj(disj(spec.atom(term, True, f'{name}.preconditions') for term in clause)
                            for clause in capability.preconditions)
            starts = conj([next_(activation), disj([neg(activation), spec.outcome_next(name)])])
            parts['sys_trans'].append(implies(starts, required))
        for outcome, clauses in capability.transition_relation.items():
            happened = _outcome_happens(spec, name, outcome, 'transition_relation')
            for clause in clauses:
                targets = [_target(spec, term) for term in clause]
                parts['sys_trans'].append(implies(happened, disj(targets)))
        for outcome, literals in capability.postconditions.items():
            happened = _outcome_happens(spec, name, outcome, 'postconditions')
            for literal in literals:
                key = literal.name if literal.name in spec.integers else (
                    literal.name if literal.name in spec.memories else None)
                if key is None:
                    target = spec.atom(literal, True, f'{name}.postconditions')
                    if literal.name in spec.env_props:
                        raise CapabilityConfigError(f'{system.system}: capability {name!r} postcondition sets '
                                                    f'{literal.name!r}, an environment proposition',
                                                    item=f'{name}.postconditions')
                    parts['sys_trans'].append(implies(happened, target))
                    continue
                setters.setdefault(key, []).append(happened)
                if key in spec.memories:
                    spec.used_memories.setdefault(key)
                if not literal.choose:
                    parts['sys_trans'].append(implies(happened, spec.atom(literal, True, f'{name}.postconditions')))
    return setters


def _frames(spec: CapabilitySpecification, setters: dict[str, list[Formula]], parts: dict[str, list[Formula]]) -> None:
    """Memories and system integers keep their values unless an outcome sets them."""
    variables = [(name, [memory(name)]) for name in spec.used_memories]
    variables += [(name, integer.bits) for name, integer in spec.integers.items()
                  if not spec.system.integers[name].environment]
    for name, bits in variables:
        unchanged = conj(iff(next_(var(b)), var(b)) for b in bits)
        changes = setters.get(name)
        parts['sys_trans'].append(implies(neg(disj(changes)), unchanged) if changes else unchanged)
    for integer in spec.integers.values():
        if integer.in_range(True) is not TRUE:
            parts['sys_trans' if not spec.system.integers[integer.name].environment else 'env_trans'].append(
                integer.in_range(True))


def _outcome_happens(spec: CapabilitySpecification, name: str, outcome: str, key: str) -> Formula:
    proposition = spec.outcome_props[name].get(outcome)
    if proposition is None:
        raise CapabilityConfigError(f'{spec.system.system}: capability {name!r} {key} names outcome {outcome!r}, '
                                    f'which none of its FlexBE outcomes means', item=f'{name}.{key}.{outcome}')
    return next_(var(proposition))


def _target(spec: CapabilitySpecification, term: Literal) -> Formula:
    if term.name in spec.activations:
        proposition = spec.activations[term.name]
    else:
        proposition = spec.system.sm_outcomes[term.name]
    formula = next_(var(proposition))
    return neg(formula) if term.negated else formula


def _request_literal(spec: CapabilitySpecification, text: str, what: str, error: type[CodedError]) -> Literal:
    try:  # one grammar for files and requests
        return parse_literal(text, text, f'{spec.system.system} {what}', spec.system.integers, False)
    except CapabilityConfigError as problem:
        raise error(str(problem), item=text) from None


def _goals(spec: CapabilitySpecification, goals: Sequence[str], parts: dict[str, list[Formula]]) -> None:
    literals = [_request_literal(spec, goal, 'goal', InvalidGoalsError) for goal in goals]
    atoms = [spec.atom(literal, False, 'goal', UnknownPropositionError) for literal in literals]
    success = spec.success
    if success is None:
        parts['sys_liveness'] += atoms
        return
    reached = conj(spec.atom(literal, True, 'goal', UnknownPropositionError) for literal in literals)
    parts['sys_trans'].append(implies(next_(var(success)), disj([var(success), reached])))
    parts['sys_liveness'].append(disj([var(success), var(spec.failed)]) if spec.failed else var(success))


def _initial_values(spec: CapabilitySpecification, initial_conditions: Sequence[str],
                    parts: dict[str, list[Formula]]) -> None:
    given: dict[str, Formula] = {}    # variable -> its initial condition(s)
    for text in [*spec.system.spec_initial, *initial_conditions]:
        literal = _request_literal(spec, text, 'initial condition', InvalidInitialConditionsError)
        formula = spec.atom(literal, False, 'initial condition', UnknownPropositionError)
        key = literal.name
        if key in spec.env_props and key not in spec.system.spec_inputs:
            raise InvalidInitialConditionsError(f'initial condition {text!r}: outcomes cannot hold initially',
                                                item=text)
        given[key] = formula
    for name in spec.activations.values():
        if name not in given:
            given[name] = neg(var(name))
    for name in spec.sm_props:
        given.setdefault(name, neg(var(name)))
    for name in spec.used_memories:
        given.setdefault(name, var(memory(name)) if spec.memories[name] else neg(var(memory(name))))
    for name, integer in spec.integers.items():
        given.setdefault(name, integer.equals(integer.low, False))
    environment = set(spec.env_props)
    for key, formula in given.items():
        bits = spec.integers[key].bits if key in spec.integers else [key]
        section = 'env_init' if bits[0] in environment else 'sys_init'
        parts[section].append(formula)
    for integer in spec.integers.values():
        if integer.in_range(False) is not TRUE:
            environment_owned = spec.system.integers[integer.name].environment
            parts['env_init' if environment_owned else 'sys_init'].append(integer.in_range(False))


def _parsed_spec_formulas(system: CapabilitySystem, env_props: list[str], sys_props: list[str],
                          integers: Mapping[str, IntegerVariable], sections: Sequence[str]) -> dict[str, list[Formula]]:
    """The spec file's formulas of ``sections``, each read in its section's scope (slugs' rules)."""
    scopes = section_scopes(env_props, sys_props, dict(integers))
    parsed: dict[str, list[Formula]] = {section: [] for section in FORMULA_SECTIONS}
    for section, text in system.spec_formulas:
        if section not in sections:
            continue
        where = f'specs.{section.upper()}'
        try:
            parsed[section].append(parse_in_scope(text, 'infix', scopes[section], Source(where)))
        except ParseError as error:
            raise CapabilityConfigError(f'{system.system}: {error}', item=where) from None
    return parsed


def _spec_file_formulas(spec: CapabilitySpecification, parts: dict[str, list[Formula]]) -> None:
    """CNU's capability pipeline: the spec file's transitions and livenesses join the capabilities'
    (its initial values are read as literals by ``_initial_values``). A memory they name is kept."""
    memories = [memory(name) for name in spec.memories]
    sections = ('env_trans', 'sys_trans', 'env_liveness', 'sys_liveness')
    parsed = _parsed_spec_formulas(spec.system, spec.env_props, [*spec.sys_props, *memories], spec.integers,
                                   sections)
    for section in sections:
        for formula in parsed[section]:
            for name in variables(formula):
                if name in memories:
                    spec.used_memories.setdefault(str(remembered(name)))  # a memory's: never None
            parts[section].append(formula)


def _full_specification(spec: CapabilitySpecification, initial_conditions: Sequence[str],
                        goals: Sequence[str]) -> GR1Specification:
    """CNU's full-spec pipeline: the spec file, with the request's initial conditions and goals."""
    system = spec.system
    integers = {name: spec.integers[name] for name in system.integers}
    env_props = [*system.spec_inputs, *(b for n, i in integers.items() if system.integers[n].environment
                                        for b in i.bits)]
    sys_props = [*system.spec_outputs, *(b for n, i in integers.items() if not system.integers[n].environment
                                         for b in i.bits)]
    parts = _parsed_spec_formulas(system, env_props, sys_props, integers, FORMULA_SECTIONS)
    known = set(env_props) | set(sys_props)

    def formula_of(text: str, what: str, error: type[CodedError], next_step: bool = False) -> tuple[str, Formula]:
        literal = _request_literal(spec, text, what, error)
        name = literal.name
        if literal.value is None and name not in known and memory(name) in known:
            name = memory(name)
        if literal.value is not None:
            formula = integers[name].equals(literal.value, next_step)
        elif name in known:
            formula = next_(var(name)) if next_step else var(name)
        else:
            choices = sorted(n for n in known | set(integers) if '@' not in n)
            raise UnknownPropositionError(f'{system.system} {what} {text!r} names {literal.name!r}, which is no '
                                          f'proposition of its spec file{did_you_mean(literal.name, choices)} '
                                          f'(known: {", ".join(choices)})', item=text)
        return name, neg(formula) if literal.negated else formula

    for text in initial_conditions:
        name, formula = formula_of(text, 'initial condition', InvalidInitialConditionsError)
        section = 'env_init' if name in env_props or name in integers and system.integers[name].environment \
            else 'sys_init'
        parts[section] = [f for f in parts[section] if _literal_name(f) != name] + [formula]
    if goals:
        now = conj(formula_of(g, 'goal', InvalidGoalsError)[1] for g in goals)
        following = conj(formula_of(g, 'goal', InvalidGoalsError, True)[1] for g in goals)
        success = spec.success if spec.success in sys_props else None
        if success is None:
            parts['sys_liveness'] += [formula_of(g, 'goal', InvalidGoalsError)[1] for g in goals]
        else:
            parts['sys_trans'].append(implies(conj([neg(now), following]), next_(var(success))))
            parts['sys_trans'].append(implies(conj([neg(following), neg(var(success))]), neg(next_(var(success)))))
    for integer in integers.values():
        owner = 'env' if system.integers[integer.name].environment else 'sys'
        for section, next_step in ((f'{owner}_init', False), (f'{owner}_trans', True)):
            if integer.in_range(next_step) is not TRUE:
                parts[section].append(integer.in_range(next_step))
    return GR1Specification(env_props=env_props, sys_props=sys_props, **parts)


def _literal_name(formula: Formula) -> str | None:
    """The proposition of an initial literal (``x`` or ``!x``), else None."""
    if isinstance(formula, Not):
        formula = formula.arg
    return formula.name if isinstance(formula, Var) else None
