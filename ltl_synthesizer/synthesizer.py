"""The synthesizer's entry points, one small function per product of a solved game.

    solved = solve(spec, robotics_semantics, limits)   # the game and its verdict
    explicit_strategy(solved)   stream_strategy(solved)  # when solved.realizable
    counter_strategy(solved)    explain(solved)          # when not
    synthesize(spec, ...)       # the common answer: the strategy, or why there is none

as omega separates solving a game from making its transducer. A ``Solved`` game holds BDDs and
lives in the process that solved it; ``synthesize`` returns a plain ``SynthesisResult`` that
crosses process boundaries (``ltl_synthesizer.isolated``).
"""

from __future__ import annotations

import time
from contextlib import contextmanager
from dataclasses import dataclass, field
from typing import Any, Iterator

from respec.spec import GR1Specification

from ltl_synthesizer.gr1 import (EnvironmentSolution, Solver, SystemSolution, solve_environment_game,
                                 solve_system_game)
from ltl_synthesizer.errors import StrategyTooLargeError
from ltl_synthesizer.interrupt import Interrupt, Limits, memory_exceeded
from ltl_synthesizer.policy import Options
from ltl_synthesizer.cudd_import import Node
from ltl_synthesizer.symbolic import SymbolicGame

__all__ = ['Limits', 'Solved', 'SynthesisResult', 'counter_strategy', 'explain',
           'explicit_strategy', 'initial_positions_win', 'is_realizable', 'solve', 'stream_strategy',
           'synthesis_result', 'synthesize']


@dataclass
class SynthesisResult:
    """The answer of :func:`synthesize` (plain data: it may be pickled to another process)."""

    realizable: bool
    strategy: dict[str, Any] | None = None
    counterstrategy: dict[str, Any] | None = None
    explanation: str = ''
    stats: dict[str, Any] = field(default_factory=dict)


@dataclass
class Solved:
    """A solved game: the verdict, and the solutions strategies and explanations are made of.

    ``stats`` has the seconds spent building and solving, the number of variables and the
    game's BDD statistics; ``warnings`` what a realizable verdict should be read with.
    """

    spec: GR1Specification
    robotics_semantics: bool
    game: SymbolicGame
    solver: Solver
    solution: SystemSolution
    realizable: bool
    interrupt: Interrupt
    stats: dict[str, Any] = field(default_factory=dict)
    warnings: list[str] = field(default_factory=list)
    _environment: EnvironmentSolution | None = field(default=None, repr=False)

    def environment(self) -> EnvironmentSolution:
        """The environment's side of an unrealizable game (solved once, when first asked)."""
        if self._environment is None:
            with _memory_failures_reported(self.interrupt, "solving the environment's game"):
                self._environment = solve_environment_game(self.solver)
        return self._environment


def initial_positions_win(game: SymbolicGame, winning: Node, robotics_semantics: bool) -> bool:
    """slugs' realizability check on the initial positions.

    Standard: for every initial input allowed by ENV_INIT some output allowed by SYS_INIT is
    winning (forall x. env_init -> exists y. sys_init & W). Robotics semantics
    (``--sysInitRoboticsSemantics``): every position allowed by both sections is winning.
    """
    if robotics_semantics:
        return bool(game.env_init & game.sys_init & ~winning == game.false)  # dd's BDDs are Any to mypy
    good_outputs_exist = game.bdd.exist(game.outputs, winning & game.sys_init)
    return bool(game.env_init & ~good_outputs_exist == game.false)


def solve(spec: GR1Specification, robotics_semantics: bool = True, limits: Limits = Limits(),
          options: Options | None = None) -> Solved:
    """Build the game of ``spec`` and decide its realizability.

    ``limits`` (checked in every long loop of every phase, here and in the products of the
    result): a set ``cancel`` raises ``SynthesisCancelledError`` (code PREEMPTED), the
    ``deadline`` ``SynthesisTimeoutError`` (code SYNTHESIS_TIMEOUT), the ``memory_limit``
    ``SynthesisMemoryError``. ``UndeclaredPropositionError`` / ``NotGR1FormulaError`` for
    formulas outside the declared propositions or GR(1).
    """
    interrupt = limits.interrupt()
    interrupt.size = f'{len(spec.env_props)} inputs and {len(spec.sys_props)} outputs'
    with _memory_failures_reported(interrupt, 'building the game'):
        start = time.perf_counter()
        interrupt.check()
        game = SymbolicGame(spec, options, interrupt)
        solver = Solver(game, options)
        built = time.perf_counter()
        interrupt.stage = 'solving the game'
        interrupt.size = game_size(game)

        def still_possible(winning: Node) -> bool:
            return initial_positions_win(game, winning, robotics_semantics)

        solution = solve_system_game(solver, stop_when_losing=still_possible)
        realizable = solution.complete and still_possible(solution.winning)
        if realizable:  # the counter-game of an unrealizable one is another solve: it may sift
            solver.reordering.stop()
        solved = time.perf_counter()
    warnings = []
    if realizable and game.env_init & game.sys_init == game.false:
        warnings.append('ENV_INIT and SYS_INIT are contradictory: realizable vacuously, the strategy '
                        'has no initial state')
    return Solved(spec, robotics_semantics, game, solver, solution, realizable, interrupt,
                  {'build_seconds': built - start, 'solve_seconds': solved - built,
                   'variables': len(game.variables)}, warnings)


def is_realizable(spec: GR1Specification, robotics_semantics: bool = True, limits: Limits = Limits(),
                  options: Options | None = None) -> bool:
    """Only the verdict (no strategy, no explanation)."""
    return solve(spec, robotics_semantics, limits, options).realizable


# Strategies and explanations load only when asked: a verdict alone on a tiny specification is
# mostly start-up (5 ms less of about 120).

def explicit_strategy(solved: Solved, max_edges: int | None = None) -> dict[str, Any]:
    """The explicit-state strategy of a realizable game (slugs ``--explicitStrategy --jsonOutput``
    shape). With ``max_edges``, StrategyTooLargeError as soon as the nodes extracted so far have
    more transitions: a strategy too large to use is not extracted to the end."""
    from ltl_synthesizer.strategy import streamed_strategy
    with _memory_failures_reported(solved.interrupt, 'extracting the strategy'):
        strategy = streamed_strategy(solved.game, _realizable(solved).solution)
        nodes: dict[str, Any]
        nodes, edges = {}, 0
        for name, node in strategy['nodes']:
            edges += len(node['trans'])
            if max_edges and edges > max_edges:
                raise StrategyTooLargeError(
                    f'the strategy has over {max_edges:,} transitions (found after {len(nodes) + 1:,} states), '
                    'more than this server sends (max_strategy_edges); constrain the inputs (ENV_TRANS) or '
                    'raise the limit', item='max_strategy_edges')
            nodes[name] = node
        return {**strategy, 'nodes': nodes}


def stream_strategy(solved: Solved) -> dict[str, Any]:
    """The strategy with its ``nodes`` an iterator, made while it is read
    (``strategy_json_chunks`` writes them out; memory holds no edges)."""
    from ltl_synthesizer.strategy import streamed_strategy
    with _memory_failures_reported(solved.interrupt, 'extracting the strategy'):
        return streamed_strategy(solved.game, _realizable(solved).solution)


def counter_strategy(solved: Solved) -> dict[str, Any]:
    """The environment's explicit counter-strategy of an unrealizable game."""
    from ltl_synthesizer.strategy import extract_counterstrategy
    environment = _unrealizable(solved).environment()
    with _memory_failures_reported(solved.interrupt, 'extracting the counter-strategy'):
        return extract_counterstrategy(solved.game, environment, solved.robotics_semantics)


def explain(solved: Solved) -> str:
    """Why an unrealizable game is lost: losing initial states, a blocked goal, a play."""
    from ltl_synthesizer.explanation import explain_unrealizable
    environment = _unrealizable(solved).environment()
    with _memory_failures_reported(solved.interrupt, 'explaining why it is unrealizable'):
        return explain_unrealizable(solved.game, solved.solution, environment, solved.robotics_semantics)


def synthesize(spec: GR1Specification, robotics_semantics: bool = True, limits: Limits = Limits(),
               options: Options | None = None, max_edges: int | None = None) -> SynthesisResult:
    """Solve ``spec``; its explicit strategy when realizable (at most ``max_edges`` transitions,
    see :func:`explicit_strategy`), else the explanation why not (limits and errors as :func:`solve`)."""
    start = time.perf_counter()
    return synthesis_result(solve(spec, robotics_semantics, limits, options), max_edges, start)


def synthesis_result(solved: Solved, max_edges: int | None = None, start: float | None = None) -> SynthesisResult:
    """:func:`synthesize`'s answer from a game solved already (``start``: when the solve began,
    for its total seconds), for callers that use the solved game afterwards (the well-separation
    check of ``ltl_synthesizer.isolated.synthesize_then_check``)."""
    extracting = time.perf_counter()
    start = extracting if start is None else start
    result = SynthesisResult(solved.realizable)
    if solved.realizable:
        result.strategy = explicit_strategy(solved, max_edges)
    else:
        result.explanation = explain(solved)
    if solved.warnings:
        result.stats['warnings'] = solved.warnings
    finished = time.perf_counter()
    result.stats.update({
        **solved.stats, 'extract_seconds': finished - extracting, 'total_seconds': finished - start,
        'strategy_nodes': len(result.strategy['nodes']) if result.strategy else 0, **solved.game.statistics()})
    return result


def _realizable(solved: Solved) -> Solved:
    if not solved.realizable:
        raise ValueError('the specification is unrealizable: it has no strategy')
    return solved


def _unrealizable(solved: Solved) -> Solved:
    if solved.realizable:
        raise ValueError('the specification is realizable: it has no counter-strategy')
    return solved


def game_size(game: SymbolicGame) -> str:
    """The size measure a limit's message names: what the work is as large as."""
    return (f'{len(game.inputs)} inputs and {len(game.outputs)} outputs: {2 * len(game.variables)} BDD '
            f'variables, safety relations of {game.relation_nodes:,} nodes')


@contextmanager
def _memory_failures_reported(interrupt: Interrupt, stage: str) -> Iterator[None]:
    """Runs ``stage`` (named by a limit that stops it, with the interrupt's size measure).
    CUDD fails an operation beyond its memory limit; dd reports that as a NULL node."""
    interrupt.stage = stage
    try:
        yield
    except ValueError as error:
        if interrupt.memory_limit is not None and 'NULL' in str(error):
            raise memory_exceeded(interrupt.memory_limit, interrupt.during()) from error
        raise
