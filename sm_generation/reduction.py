"""Merging equivalent states of a machine (bisimulation by partition refinement).

Two states are equivalent when they run the same FlexBE states (same parts, same
observations) and, for every observation, move to equivalent states or to the same
machine outcome. The coarsest such partition is computed with Hopcroft's algorithm:
start from "same parts and observations" (each machine outcome is a block of its own)
and split every block whose states disagree on whether an observation leads into a
*splitter* block, until no splitter is left. Every block is then replaced by its first
state in breadth-first order.
"""

from __future__ import annotations

from collections import defaultdict, deque

from sm_generation.abstract_machine import AbstractMachine, AbstractState, Observation, Target


def bisimulation_blocks(machine: AbstractMachine) -> dict[str, int]:
    """Block number of every state; equal numbers mean equivalent states."""
    keys = list(machine.states)
    # Machine outcomes take part as states without transitions, one block each.
    nodes: list[Target] = [('state', key) for key in keys]
    nodes += sorted({t for s in machine.states.values() for _, t in s.transitions if t[0] == 'outcome'})
    predecessors: dict[Target, dict[Observation, list[Target]]] = defaultdict(lambda: defaultdict(list))
    for key, state in machine.states.items():
        for observation, target in state.transitions:
            predecessors[target][observation].append(('state', key))

    initial: dict[tuple[object, ...], set[Target]] = {}
    for node in nodes:
        signature = _local_signature(machine.states[node[1]]) if node[0] == 'state' else node
        initial.setdefault(signature, set()).add(node)
    blocks = list(initial.values())
    block_of = {node: index for index, block in enumerate(blocks) for node in block}
    pending, waiting = deque(range(len(blocks))), set(range(len(blocks)))

    while pending:
        splitter = pending.popleft()
        waiting.discard(splitter)
        entering: dict[Observation, set[Target]] = defaultdict(set)  # observation -> states moving into splitter
        for node in list(blocks[splitter]):
            for observation, sources in predecessors[node].items():
                entering[observation].update(sources)
        for observation in sorted(entering):
            touched: dict[int, set[Target]] = defaultdict(set)
            for source in entering[observation]:
                touched[block_of[source]].add(source)
            for index in sorted(touched):
                inside = touched[index]
                if len(inside) == len(blocks[index]):
                    continue  # the whole block agrees
                blocks[index] -= inside
                blocks.append(inside)
                new = len(blocks) - 1
                for node in inside:
                    block_of[node] = new
                # Hopcroft: if the old block still waits, both halves must; else the smaller suffices.
                if index in waiting or len(inside) <= len(blocks[index]):
                    half = new
                else:
                    half = index
                pending.append(half)
                waiting.add(half)
    # Number blocks by first appearance in breadth-first order (deterministic ids).
    numbers: dict[int, int] = {}
    return {key: numbers.setdefault(block_of[('state', key)], len(numbers)) for key in keys}


def _local_signature(state: AbstractState) -> tuple[str, tuple[str, ...], tuple[Observation, ...]]:
    return (state.helper, tuple(part.proposition for part in state.parts),
            tuple(observation for observation, _ in state.transitions))


def target_class(target: Target, blocks: dict[str, int]) -> tuple[str, int | str]:
    """What a transition target is up to equivalence (a block, or a machine outcome)."""
    kind, name = target
    return (kind, blocks[name]) if kind == 'state' else (kind, name)


def reduce_machine(machine: AbstractMachine) -> AbstractMachine:
    """The quotient machine: one state per equivalence block, reachable part only."""
    blocks = bisimulation_blocks(machine)
    representative: dict[int, str] = {}
    for key in machine.states:  # breadth-first order: the first state represents its block
        representative.setdefault(blocks[key], key)

    def retarget(target: Target) -> Target:
        kind, name = target
        return (kind, representative[blocks[name]]) if kind == 'state' else target

    initial = representative[blocks[machine.initial]]
    states: dict[str, AbstractState] = {}
    queue = deque([initial])
    while queue:
        key = queue.popleft()
        if key in states:
            continue
        original = machine.states[key]
        transitions = [(observation, retarget(target)) for observation, target in original.transitions]
        states[key] = AbstractState(key=key, parts=original.parts, transitions=transitions, helper=original.helper)
        queue.extend(name for _, (kind, name) in transitions if kind == 'state')
    return AbstractMachine(states=states, initial=initial, outcomes=machine.outcomes, dropped=machine.dropped)
