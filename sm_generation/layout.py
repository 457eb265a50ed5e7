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
    import networkx as nx  # here: networkx is ~22 MiB, and running a machine (atlas_sim) needs no layout

    graph = nx.DiGraph()
    graph.add_nodes_from(edges)
    for source, targets in edges.items():
        graph.add_edges_from((source, t) for t in targets if t in edges)
    layers = [list(layer) for layer in nx.bfs_layers(graph, [initial])] if initial in graph else []
    placed = {node for layer in layers for node in layer}
    stragglers = [node for node in edges if node not in placed]
    if stragglers:  # not reachable from the initial state; keep them visible
        layers.append(stragglers)
    # networkx yields each layer in discovery order already; sorting by the breadth-first
    # order of ``edges`` makes the drawing independent of its internals.
    rank = {node: index for index, node in enumerate(edges)}
    layers = [sorted(layer, key=rank.__getitem__) for layer in layers]
    layers.append(list(outcomes))
    return {node: [MARGIN + COLUMN_SPACING * column, MARGIN + LAYER_SPACING * row]
            for row, layer in enumerate(layers) for column, node in enumerate(layer)}


def inner_positions(count: int) -> list[list[float]]:
    """Positions of the states inside a container, side by side."""
    return [[INNER_MARGIN + INNER_SPACING * index, INNER_MARGIN] for index in range(count)]


def container_outcome_positions(count: int) -> list[list[float]]:
    """Positions of a container's outcomes, in a row below its states."""
    return [[INNER_MARGIN + INNER_SPACING * index, INNER_MARGIN + LAYER_SPACING] for index in range(count)]
