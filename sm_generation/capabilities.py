"""State machines for robots described by capabilities (CNU's flexbe_synthesis format).

Each capability becomes a FlexBE state: its ``interface`` class with its ``parameters`` as
Python source text (strings quoted, ``'None'`` -> ``None``, ``*name`` a variable reference, other
values as literals), its outcomes grouped by the transition outcome they mean (``c_c``,
``c_f``), and its ``autonomy`` per outcome (default Low, 1). A parameter ``@x`` takes the
value integer variable ``x`` has while the capability runs, named by ``variable_mappings``
(``item: {1: soda}`` gives ``'soda'``): a capability running with different values becomes
one state per value (``give_soda``). Memories and integer bits are bookkeeping: they never
reach FlexBE, and the reduction (``sm_generation.reduction``, on by default for these systems)
merges states that differ only in them.

A specification may model its environment with inputs no capability reports: a sensor of the
spec file (``battery_low``), the coffee maker's button ``bu`` in CNU's full spec, a failure of a
LogState, which has no failure outcome. FlexBE cannot see them: the machine is built from what
it sees, the outcomes of the capabilities, as CNU's generator does; a sensor reaches it through
the outcomes of the states that observe it (the spec's ``ENV_TRANS`` binds them).
"""

from __future__ import annotations

import re
from typing import Iterable, Mapping

from respec.automaton import Automaton, AutomatonState
from respec.robot.cnu import CapabilitySystem
from respec.vocabulary.naming import activation
from respec.parsing import IntegerVariable
from respec.robot.state_library import StateClass, capability_outcomes
from sm_generation.config import FlexBEConfig, StateConfig
from sm_generation.errors import StateConfigInvalidError
from sm_generation.generator import generate_from_config
from sm_generation.state_machine import StateMachine

DEFAULT_AUTONOMY = 1
_UNSAFE = re.compile(r'[^A-Za-z0-9_]+')


def generate_capability_machine(automaton: Automaton, system: CapabilitySystem, library: Mapping[str, StateClass],
                                reduce: bool | None = None) -> StateMachine:
    """The FlexBE state machine implementing ``automaton`` on a capability system."""
    outcomes = capability_outcomes(system, library)
    flexbe_automaton, variants = _with_parameter_variants(automaton, system, _reported_inputs(system, outcomes))
    sm_outcomes = [o for o in flexbe_automaton.output_variables if o in system.possible_sm_outcomes()]
    config = _flexbe_config(system, outcomes, library, variants, sm_outcomes)
    return generate_from_config(flexbe_automaton, config, None, system.reduce if reduce is None else reduce)


def parameter_source(value: object) -> str:
    """A capability parameter as the Python source FlexBE's behavior code takes."""
    if isinstance(value, str):
        if value == 'None':
            return 'None'
        if value.startswith('*'):
            return value[1:]
        return repr(value)
    return repr(value)


def _reported_inputs(system: CapabilitySystem, outcomes: Mapping[str, tuple[str, ...]]) -> set[str]:
    """The inputs FlexBE sees: the capabilities' outcomes. A sensor (a spec ``INPUT``) reaches the
    machine through the outcomes of the states that observe it, as the spec's ``ENV_TRANS`` binds
    them (CNU's coffee maker: ``bd_c' <-> bu' & bd_a``, the button detector completes when the
    button is pressed)."""
    return {system.outcome_proposition(name, system.transition_outcome(name, outcome))
            for name in system.capabilities for outcome in outcomes[name]}


def _with_parameter_variants(automaton: Automaton, system: CapabilitySystem, reported: set[str]
                             ) -> tuple[Automaton, dict[str, tuple[str, dict[str, int | str]]]]:
    """The automaton with only what FlexBE sees: one activation per (capability, @var values),
    the SM outcomes the specification has (the request chose them) and the ``reported`` inputs.
    Returns it and the variants: proposition -> (capability, values)."""
    outputs = list(automaton.output_variables)
    inputs = list(automaton.input_variables)
    seen = [k for k, name in enumerate(inputs) if name in reported]
    integers = {name: IntegerVariable(name, r.low, r.high) for name, r in system.integers.items()}
    sm_props = [o for o in system.possible_sm_outcomes() if o in outputs]
    variants: dict[str, tuple[str, dict[str, int | str]]] = {}
    rows = []
    for state in automaton.states:
        values = dict(zip(outputs, state.output_valuation))
        values.update(zip(inputs, state.input_valuation))
        active = []
        for name, capability in system.capabilities.items():
            if not values.get(activation(name)):
                continue
            chosen = {parameter: _integer_value(integers[variable], values, system.integers[variable].value_names)
                      for parameter, variable in capability.variable_parameters().items()}
            label = '_'.join(_UNSAFE.sub('_', str(v)).strip('_') or 'none' for v in chosen.values())
            proposition = activation(f'{name}_{label}' if chosen else name)
            variants.setdefault(proposition, (name, chosen))
            active.append(proposition)
        rows.append((state, active, [bool(values.get(o)) for o in sm_props]))
    activation_props = list(variants)
    states = [AutomatonState(name=str(state.name), output_valuation=[p in active for p in activation_props] + exits,
                             input_valuation=[bool(state.input_valuation[k]) for k in seen],
                             transitions=[str(t) for t in state.transitions], rank=int(getattr(state, 'rank', 0)))
              for state, active, exits in rows]
    reduced = Automaton(output_variables=activation_props + sm_props, input_variables=[inputs[k] for k in seen],
                        states=states,
                        initial_states=[str(n) for n in (getattr(automaton, 'initial_states', None) or [])])
    unreported = {system.outcome_proposition(name, t) for name in system.capabilities
                  for t in system.transition_outcomes} - reported
    _check_observable(automaton, reduced, [name for k, name in enumerate(inputs) if k not in seen], unreported)
    return reduced, variants


def _check_observable(automaton: Automaton, seen: Automaton, hidden: list[str], impossible: set[str]) -> None:
    """FlexBE chooses a state's successor from the outcome it returns: two successors that return
    the same outcomes must run the same states. A strategy that tells them apart by an input no
    state reports (a sensor no ENV_TRANS binds to an outcome) cannot be a FlexBE machine.
    Successors with an ``impossible`` input (an outcome the capability's class never returns, the
    failure of a LogState) never happen in FlexBE."""
    if not hidden:
        return
    full = {str(s.name): s for s in automaton.states}
    hidden_index = [list(automaton.input_variables).index(name) for name in hidden]
    never = [k for name, k in zip(hidden, hidden_index) if name in impossible]
    visible = {s.name: s for s in seen.states}
    for state in seen.states:
        chosen: dict[tuple[bool, ...], str] = {}
        for successor in state.transitions:
            if any(full[successor].input_valuation[k] for k in never):
                continue
            target = visible[successor]
            earlier = chosen.setdefault(tuple(target.input_valuation), successor)
            if visible[earlier].output_valuation == target.output_valuation:
                continue
            differing = [hidden[i] for i, k in enumerate(hidden_index)
                         if full[earlier].input_valuation[k] != full[successor].input_valuation[k]]
            raise StateConfigInvalidError(
                f'after automaton state {state.name} the strategy reacts to input '
                f'{", ".join(map(repr, differing or hidden))}, which no state reports: bind it to the outcome of '
                f'a capability that observes it (the spec\'s ENV_TRANS, e.g. "check_c\' <-> (check_a & sensor\')")',
                (differing or hidden)[0])


def _integer_value(integer: IntegerVariable, values: dict[str, bool], names: dict[int, str]) -> int | str:
    number = integer.low + sum(1 << k for k, bit in enumerate(integer.bits) if values.get(bit))
    return names.get(number, number)


def _flexbe_config(system: CapabilitySystem, outcomes: Mapping[str, tuple[str, ...]],
                   library: Mapping[str, StateClass], variants: dict[str, tuple[str, dict[str, int | str]]],
                   sm_outcomes: list[str]) -> FlexBEConfig:
    states = {}
    for proposition, (name, chosen) in variants.items():
        capability = system.capabilities[name]
        mapping: dict[str, tuple[str, ...]] = {}
        for transition_outcome in system.transition_outcomes:
            mine = tuple(o for o in outcomes[name] if system.transition_outcome(name, o) == transition_outcome)
            if mine:
                mapping[system.outcome_proposition(name, transition_outcome)] = mine
        parameters = {**capability.parameters, **chosen}
        states[proposition] = StateConfig(
            proposition=proposition, state_class=capability.interface, behavior_class='',
            parameter_names=tuple(parameters), parameter_values=tuple(parameter_source(v) for v in parameters.values()),
            output_mapping=mapping, autonomy={o: capability.autonomy.get(o, DEFAULT_AUTONOMY) for o in outcomes[name]},
            userdata_keys=(), userdata_remapping=())
    return capability_flexbe_config(system, library, states, sm_outcomes)


def capability_flexbe_config(system: CapabilitySystem, library: Mapping[str, StateClass],
                             states: dict[str, StateConfig] | None = None,
                             sm_outcomes: Iterable[str] | None = None) -> FlexBEConfig:
    """The FlexBE side of a capability system: its SM outcomes (``sm_outcomes``, those of one
    machine; default: its mappings') and the package of each state class (what
    ``sm_generation.flexbe_behavior`` needs to export a machine as a behavior)."""
    packages = {c.interface: library[c.interface].package for c in system.capabilities.values()}
    outcomes = system.sm_outcomes.values() if sm_outcomes is None else sm_outcomes
    return FlexBEConfig(system=system.system, sm_outcomes={o: o for o in dict.fromkeys(outcomes)}, states=states or {},
                        state_class_packages=packages)
