"""The synthesized automaton (the FSAutomaton message shape), and its reading from a slugs
JSON strategy. Shared by the synthesizer (which produces it) and sm_generation (which reads it).

Port of the original ltl_synthesis_server's conversion: state names are the node ids as
strings, valuations split into inputs and outputs, goal-memory propositions (names ending in
``_m``) dropped from the outputs.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from respec.vocabulary.errors import CodedError, ErrorCode
from respec.ltl import Formula, Not, Var, conj, evaluate
from respec.vocabulary.naming import is_memory
from respec.spec import GR1Specification


class AutomatonError(CodedError):
    code = ErrorCode.AUTOMATON_INVALID


@dataclass
class AutomatonState:
    name: str
    output_valuation: list[bool]
    input_valuation: list[bool]
    transitions: list[str]
    rank: int


@dataclass
class Automaton:
    output_variables: list[str] = field(default_factory=list)
    input_variables: list[str] = field(default_factory=list)
    states: list[AutomatonState] = field(default_factory=list)
    initial_states: list[str] = field(default_factory=list)


def automaton_from_strategy(strategy: dict[str, Any], spec: GR1Specification,
                            drop_memory: bool = True) -> Automaton:
    """The automaton of a slugs JSON strategy; ``initial_states`` are the nodes whose valuation
    satisfies ENV_INIT and SYS_INIT (the extraction numbers them first)."""
    inputs, outputs = list(spec.env_props), list(spec.sys_props)
    expected = inputs + outputs
    if list(strategy.get('variables', [])) != expected:
        raise AutomatonError(
            f"strategy variables {strategy.get('variables')} do not match the specification's "
            f'inputs then outputs {expected}', item='variables')
    kept = [i for i, name in enumerate(outputs) if not (drop_memory and is_memory(name))]
    nodes = strategy['nodes']
    n_inputs = len(inputs)
    states = []
    for name in sorted(nodes, key=int):
        node = nodes[name]
        valuation = node['state']
        if len(valuation) != len(expected) or any(v not in (0, 1) for v in valuation):
            raise AutomatonError(f'node {name} has an invalid valuation {valuation}', item=name)
        for successor in node['trans']:
            if str(successor) not in nodes:
                raise AutomatonError(f'node {name} has an unknown successor {successor}', item=name)
        output_values = valuation[n_inputs:]
        states.append(AutomatonState(
            name=str(name),
            output_valuation=[bool(output_values[i]) for i in kept],
            input_valuation=[bool(v) for v in valuation[:n_inputs]],
            transitions=[str(t) for t in node['trans']],
            rank=int(node['rank'])))
    initial = _initial_nodes(strategy, spec)
    return Automaton(output_variables=[outputs[i] for i in kept], input_variables=inputs,
                     states=states, initial_states=initial)


def _initial_nodes(strategy: dict[str, Any], spec: GR1Specification) -> list[str]:
    # Literals first: a node that is not initial breaks one of them at once, without evaluating
    # the rest (a robot of N capabilities has N^2/2 exclusions of its one-hot activations;
    # at 160, 13,000 formulas evaluated for each node took most of the automaton's seconds).
    parts = list(spec.env_init) + list(spec.sys_init)
    condition = conj(sorted(parts, key=lambda part: not _is_literal(part)))
    names = list(strategy['variables'])
    try:
        return [str(name) for name in sorted(strategy['nodes'], key=int)
                if evaluate(condition, {v: bool(x) for v, x in zip(names, strategy['nodes'][name]['state'])})]
    except KeyError as unknown:
        raise AutomatonError(f'an initial condition mentions {unknown.args[0]!r}, which is not a '
                             'variable of the strategy', item=unknown.args[0]) from None


def _is_literal(formula: Formula) -> bool:
    return isinstance(formula, Var) or isinstance(formula, Not) and isinstance(formula.arg, Var)


def strategy_move_problems(strategy: dict[str, Any], spec: GR1Specification, seconds: float = 0.5) -> list[str]:
    """What in a slugs JSON ``strategy`` its ``spec`` forbids: no initial node, or a move that
    breaks a transition formula (ENV_TRANS or SYS_TRANS, on both steps' whole valuations).
    Moves are checked for up to ``seconds`` (a strategy of thousands of moves is checked in
    part); empty when nothing was found. Liveness is not checked (see bench/strategy_check.py)."""
    import time

    names = list(strategy.get('variables', ()))
    if names != list(spec.env_props) + list(spec.sys_props):
        return ["its variables are not the specification's inputs then outputs"]
    nodes = strategy.get('nodes') or {}
    try:
        if not _initial_nodes(strategy, spec):
            return ['no node satisfies the initial conditions']
    except AutomatonError as error:
        return [str(error)]
    valuations = {str(name): {v: bool(x) for v, x in zip(names, node['state'])} for name, node in nodes.items()}
    formulas = [('env_trans', index, f) for index, f in enumerate(spec.env_trans)] + \
               [('sys_trans', index, f) for index, f in enumerate(spec.sys_trans)]
    stop = time.monotonic() + seconds
    for name, node in nodes.items():
        current = valuations[str(name)]
        for successor in node['trans']:
            following = valuations.get(str(successor))
            if following is None:
                return [f'node {name} has an unknown successor {successor}']
            for section, index, formula in formulas:
                if not evaluate(formula, current, following):
                    return [f'the move {name} -> {successor} breaks {section}[{index}]']
        if time.monotonic() > stop:
            break
    return []
