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

A full specification (CNU's full-spec pipeline) may model its environment with inputs no
capability reports (the coffee maker's button ``bu``, a failure of a LogState, which has no
failure outcome). FlexBE cannot see them: the machine is built from what it sees, the outcomes
of the capabilities, as CNU's generator does.
"""

from __future__ import annotations

import re
from typing import Mapping

from respec.automaton import Automaton, AutomatonState
from respec.robot.cnu import CapabilitySystem
from respec.naming import activation
from respec.parsing import IntegerVariable
from respec.robot.state_library import StateClass, capability_outcomes
from sm_generation.config import FlexBEConfig, StateConfig
from sm_generation.generator import generate_from_config
from sm_generation.instantiation import StateInstantiation

DEFAULT_AUTONOMY = 1
_UNSAFE = re.compile(r'[^A-Za-z0-9_]+')


def generate_capability_machine(automaton, system: CapabilitySystem, library: Mapping[str, StateClass],
                                reduce: bool | None = None) -> list[StateInstantiation]:
    """The FlexBE state machine implementing ``automaton`` on a capability system."""
    outcomes = capability_outcomes(system, library)
    flexbe_automaton, variants = _with_parameter_variants(automaton, system, _reported_inputs(system, outcomes))
    config = _flexbe_config(system, outcomes, library, variants)
    return generate_from_config(flexbe_automaton, config, None, system.reduce if reduce is None else reduce)


def parameter_source(value) -> str:
    """A capability parameter as the Python source FlexBE's behavior code takes."""
    if isinstance(value, str):
        if value == 'None':
            return 'None'
        if value.startswith('*'):
            return value[1:]
        return repr(value)
    return repr(value)


def _reported_inputs(system: CapabilitySystem, outcomes) -> set[str] | None:
    """The inputs FlexBE sees in a full specification (the capabilities' outcomes); None: all."""
    if not system.full_spec:
        return None
    return {system.outcome_proposition(name, system.transition_outcome(name, outcome))
            for name in system.capabilities for outcome in outcomes[name]}


def _with_parameter_variants(automaton, system: CapabilitySystem, reported: set[str] | None = None):
    """The automaton with only what FlexBE sees: one activation per (capability, @var values),
    the SM outcomes and the ``reported`` inputs (None: all). Returns it and the variants:
    proposition -> (capability, values)."""
    outputs = list(automaton.output_variables)
    inputs = list(automaton.input_variables)
    seen = [k for k, name in enumerate(inputs) if reported is None or name in reported]
    integers = {name: IntegerVariable(name, r.low, r.high) for name, r in system.integers.items()}
    sm_props = list(dict.fromkeys(system.sm_outcomes.values()))
    variants: dict[str, tuple[str, dict[str, object]]] = {}
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
    return reduced, variants


def _integer_value(integer: IntegerVariable, values: dict, names: dict[int, str]):
    number = integer.low + sum(1 << k for k, bit in enumerate(integer.bits) if values.get(bit))
    return names.get(number, number)


def _flexbe_config(system: CapabilitySystem, outcomes, library, variants) -> FlexBEConfig:
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
    return capability_flexbe_config(system, library, states)


def capability_flexbe_config(system: CapabilitySystem, library: Mapping[str, StateClass],
                             states: dict[str, StateConfig] | None = None) -> FlexBEConfig:
    """The FlexBE side of a capability system: its SM outcomes and the package of each state class
    (what ``sm_generation.flexbe_behavior`` needs to export a machine as a behavior)."""
    packages = {c.interface: library[c.interface].package for c in system.capabilities.values()}
    sm_outcomes = {o: o for o in dict.fromkeys(system.sm_outcomes.values())}
    return FlexBEConfig(system=system.system, sm_outcomes=sm_outcomes, states=states or {},
                        state_class_packages=packages)
