"""State-machine generation speed (prints a table; not a test).

    python bench/bench_sm_generation.py [--sizes 100 1000 5000]

Times generate_state_machine (plain and reduce=True) on the hand-written fixtures, on the
paper's tasks (compiled and synthesized first; synthesis time not counted) and on large
synthetic chain automata (each step activates an ATLAS action; completion goes on, failure
retries through a copy of the step, so half the states are bisimilar duplicates).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from sm_generation import Automaton, AutomatonState, generate_state_machine, load_automaton
from respec.robot import robot_system

ACTIONS = ['look_down', 'pregrasp', 'pregrasp_plan', 'approach_object', 'footstep_plan', 'footstep_goal']


def timed(function, repeat: int = 3) -> tuple[float, object]:
    best, result = float('inf'), None
    for _ in range(repeat):
        start = time.perf_counter()
        result = function()
        best = min(best, time.perf_counter() - start)
    return best, result


def chain_automaton(steps: int) -> Automaton:
    outputs = [f'{a}_a' for a in ACTIONS] + ['finished', 'failed']
    inputs = [f'{a}_{o}' for a in ACTIONS for o in 'cf']
    n_out, n_in = len(outputs), len(inputs)

    def valuation(size, true_indices):
        return [i in true_indices for i in range(size)]

    states = [AutomatonState('start', valuation(n_out, set()), valuation(n_in, set()), ['s0'], 0),
              AutomatonState('done', valuation(n_out, {n_out - 2}), valuation(n_in, set()), ['done'], 0)]
    for step in range(steps):
        action = step % len(ACTIONS)
        success = 'done' if step == steps - 1 else f's{step + 1}'
        for copy, retry in ((f's{step}', f'r{step}'), (f'r{step}', f's{step}')):
            entered_by = {2 * ((step - 1) % len(ACTIONS))} if step and copy.startswith('s') else set()
            if copy.startswith('r'):
                entered_by = {2 * action + 1}
            states.append(AutomatonState(copy, valuation(n_out, {action}), valuation(n_in, entered_by),
                                         [copy, success, retry], 0))
    # successors must show the outcome that led to them
    by_name = {s.name: s for s in states}
    by_name['done'].input_valuation = valuation(n_in, {2 * ((steps - 1) % len(ACTIONS))})
    return Automaton(outputs, inputs, states, ['start'])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--sizes', type=int, nargs='*', default=[100, 1000, 5000])
    args = parser.parse_args()
    print(f'{"case":42s} {"aut. states":>11s} {"SM states":>9s} {"plain ms":>9s} {"reduced":>8s} {"reduce ms":>9s}')

    def row(label, automaton, system='atlas'):
        system = robot_system(system)
        plain_time, plain = timed(lambda: generate_state_machine(automaton, system))
        reduced_time, reduced = timed(lambda: generate_state_machine(automaton, system, reduce=True))
        top = lambda machine: len(machine.states)  # noqa: E731
        print(f'{label:42s} {len(automaton.states):11d} {top(plain):9d} {plain_time * 1e3:9.2f} '
              f'{top(reduced):8d} {reduced_time * 1e3:9.2f}')

    for path in sorted((ROOT / 'test' / 'automata').glob('*.yaml')):
        row(f'fixture {path.stem}', load_automaton(path))
    try:
        from ltl_specification import compile_task
        from ltl_synthesizer import synthesize
        from respec.automaton import automaton_from_strategy
    except ImportError as error:
        print(f'(paper tasks skipped: {error})')
    else:
        for system, initial, goals in [('atlas', 'stand_prep', 'look_down, pickup_object'),
                                       ('atlas', 'stand_prep', 'pickup_object, grasp_object'),
                                       ('atlas', 'stand_prep', 'footstep_execution'),
                                       ('mobile_manipulator', 'parked', 'grasp, dock')]:
            spec = compile_task(robot_system(system), initial, goals)
            automaton = automaton_from_strategy(synthesize(spec).strategy, spec)
            row(f'{system}: {goals}', automaton, system)
    for size in args.sizes:
        row(f'synthetic chain, {size} steps', chain_automaton(size))


if __name__ == '__main__':
    main()
