"""Human-readable summaries of synthesis results (ROS-free)."""

from __future__ import annotations

from sm_generation.instantiation import StateInstantiation, count_states
from sm_generation.state_machine import State, StateMachine


def generated_summary(states: list) -> str:
    """A goal's last progress note: the state machine it generated (StateInstantiation entries)."""
    return f'Generated a state machine with {count_states(states)} states'


def state_machine_tree(machine: StateMachine) -> str:
    """The state machine as an indented tree: containers, their states and transitions.

        /  (:STATEMACHINE, initial: stand, outcomes: finished, failed)
          stand  [ChangeControlModeActionState]  changed -> look_down, failed -> failed

    """
    lines = []

    def show(node: State, depth: int) -> None:
        kind = node.state_class
        if kind == StateInstantiation.CLASS_BEHAVIOR:
            kind = f'{kind} {node.behavior_class}'
        details = []
        if node.initial_state_name:
            details.append(f'initial: {node.initial_state_name}')
        edges = ', '.join(f'{o} -> {t}' for o, t in zip(node.outcomes, node.transitions))
        if depth == 0:
            details.append(f"outcomes: {', '.join(node.outcomes)}")
            edges = ''
        for outcome, condition in zip(node.cond_outcome, node.cond_transition):
            pairs = ' & '.join(f'{n}={o}' for n, o in zip(condition.state_name, condition.state_outcome))
            details.append(f'{outcome} if {pairs}')
        suffix = f"  ({'; '.join(details)})" if details else ''
        lines.append(f"{'  ' * depth}{node.name or '/'}  [{kind}]{suffix}" + (f'  {edges}' if edges else ''))
        for child in node.children:
            show(child, depth + 1)

    show(machine, 0)
    return '\n'.join(lines)


def spec_size(sections: dict) -> str:
    """'12 inputs, 14 outputs, 61 formulas' for an LTLSpecification section dict."""
    formulas = sum(len(sections.get(name, [])) for name in
                   ('env_init', 'sys_init', 'env_trans', 'sys_trans', 'env_liveness', 'sys_liveness'))
    return (f"{len(sections.get('env_props', []))} inputs, "
            f"{len(sections.get('sys_props', []))} outputs, {formulas} formulas")
