"""Human-readable summaries of synthesis results (ROS-free; works on plain dicts)."""

from __future__ import annotations

from sm_generation.instantiation import StateInstantiation


def state_machine_tree(states: list[dict]) -> str:
    """The state machine as an indented tree: containers, their states and transitions.

        /  (:STATEMACHINE, initial: stand, outcomes: finished, failed)
          stand  [ChangeControlModeActionState]  changed -> look_down, failed -> failed
    """
    lines = []
    for state in states:  # the generator's order is deterministic and lists parents first
        path = state['state_path']
        depth = 0 if path == '/' else path.count('/')
        indent = '  ' * depth
        name = '/' if path == '/' else path.rsplit('/', 1)[-1]
        kind = state['state_class']
        if kind == StateInstantiation.CLASS_BEHAVIOR:
            kind = f"{kind} {state['behavior_class']}"
        details = []
        if state.get('initial_state_name'):
            details.append(f"initial: {state['initial_state_name']}")
        edges = ', '.join(f'{o} -> {t}' for o, t in zip(state['outcomes'], state['transitions']))
        if path == '/':
            details.append(f"outcomes: {', '.join(state['outcomes'])}")
            edges = ''
        for outcome, condition in zip(state.get('cond_outcome', []), state.get('cond_transition', [])):
            pairs = ' & '.join(f'{n}={o}' for n, o in zip(condition['state_name'], condition['state_outcome']))
            details.append(f'{outcome} if {pairs}')
        suffix = f"  ({'; '.join(details)})" if details else ''
        lines.append(f'{indent}{name}  [{kind}]{suffix}' + (f'  {edges}' if edges else ''))
    return '\n'.join(lines)


def spec_size(sections: dict) -> str:
    """'12 inputs, 14 outputs, 61 formulas' for an LTLSpecification section dict."""
    formulas = sum(len(sections.get(name, [])) for name in
                   ('env_init', 'sys_init', 'env_trans', 'sys_trans', 'env_liveness', 'sys_liveness'))
    return (f"{len(sections.get('env_props', []))} inputs, "
            f"{len(sections.get('sys_props', []))} outputs, {formulas} formulas")
