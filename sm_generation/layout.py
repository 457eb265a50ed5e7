"""A layered drawing for the FlexBE editor: breadth-first layers from the initial state.

Layers run top to bottom (y), states of one layer left to right (x) in breadth-first
order; the machine's outcomes get a last layer of their own. Everything is derived from
the graph, so the same machine always gets the same positions.
"""

from __future__ import annotations

LAYER_SPACING = 140.0
COLUMN_SPACING = 260.0
MARGIN = 60.0
INNER_MARGIN = 30.0
INNER_SPACING = 230.0


def layered_positions(edges: dict[str, list[str]], initial: str, outcomes: list[str]) -> dict[str, list[float]]:
    """Positions [x, y] of states (``edges``: state -> targets in order) and outcomes."""
    layers = _breadth_first_layers(edges, initial) if initial in edges else []
    placed = {node for layer in layers for node in layer}
    stragglers = [node for node in edges if node not in placed]
    if stragglers:  # not reachable from the initial state; keep them visible
        layers.append(stragglers)
    # Sorting by the order of ``edges`` makes a layer's order independent of the search.
    rank = {node: index for index, node in enumerate(edges)}
    layers = [sorted(layer, key=rank.__getitem__) for layer in layers]
    layers.append(list(outcomes))
    return {node: [MARGIN + COLUMN_SPACING * column, MARGIN + LAYER_SPACING * row]
            for row, layer in enumerate(layers) for column, node in enumerate(layer)}


def _breadth_first_layers(edges: dict[str, list[str]], initial: str) -> list[list[str]]:
    """The states by their distance from ``initial`` (targets that are not states are skipped).

    A plain search rather than networkx: importing networkx took most of a small machine's
    generation (about 0.1 s of 0.14 s for ten capabilities)."""
    layers, seen = [[initial]], {initial}
    while True:
        following = []
        for node in layers[-1]:
            for target in edges[node]:
                if target in edges and target not in seen:
                    seen.add(target)
                    following.append(target)
        if not following:
            return layers
        layers.append(following)


def inner_positions(count: int) -> list[list[float]]:
    """Positions of the states inside a container, side by side."""
    return [[INNER_MARGIN + INNER_SPACING * index, INNER_MARGIN] for index in range(count)]


def container_outcome_positions(count: int) -> list[list[float]]:
    """Positions of a container's outcomes, in a row below its states."""
    return [[INNER_MARGIN + INNER_SPACING * index, INNER_MARGIN + LAYER_SPACING] for index in range(count)]
