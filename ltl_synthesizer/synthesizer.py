"""The synthesizer's entry point: specification in, strategy (or counter-strategy) out."""

from __future__ import annotations

import threading
import time
from contextlib import contextmanager
from dataclasses import dataclass, field

from respec.spec import GR1Specification

from ltl_synthesizer.gr1 import Solver, solve_environment_game, solve_system_game
from ltl_synthesizer.interrupt import Interrupt, memory_exceeded
from ltl_synthesizer.policy import Options
from ltl_synthesizer.symbolic import SymbolicGame

# Default memory limit of one synthesis: BDD memory, in bytes.
DEFAULT_MEMORY_LIMIT = 2 * 2**30


@dataclass
class SynthesisResult:
    realizable: bool
    strategy: dict | None = None
    counterstrategy: dict | None = None
    explanation: str = ''
    stats: dict = field(default_factory=dict)


def initial_positions_win(game: SymbolicGame, winning, robotics_semantics: bool) -> bool:
    """slugs' realizability check on the initial positions.

    Standard: for every initial input allowed by ENV_INIT some output allowed by SYS_INIT is
    winning (forall x. env_init -> exists y. sys_init & W). Robotics semantics
    (``--sysInitRoboticsSemantics``): every position allowed by both sections is winning.
    """
    if robotics_semantics:
        return game.env_init & game.sys_init & ~winning == game.false
    good_outputs_exist = game.bdd.exist(game.outputs, winning & game.sys_init)
    return game.env_init & ~good_outputs_exist == game.false


def synthesize(spec: GR1Specification, robotics_semantics: bool = True,
               cancel: threading.Event | None = None, deadline: float | None = None,
               counterstrategy: bool = False, explain: bool = True,
               options: Options | None = None, strategy: bool | str = True,
               memory_limit: int | None = DEFAULT_MEMORY_LIMIT) -> SynthesisResult:
    """Decide realizability of ``spec``; extract an explicit strategy (``strategy``), or a
    counter-strategy (``counterstrategy``) and an explanation (``explain``) when unrealizable.

    ``strategy='stream'``: the strategy's ``nodes`` are an iterator, made while it is read
    (``strategy_json_chunks`` writes them out; memory holds no edges).

    Limits (all optional, checked in every long loop of every phase): ``cancel`` (a
    threading.Event) raises ``SynthesisCancelledError`` (code PREEMPTED), ``deadline`` (a
    ``time.monotonic()`` instant) raises ``SynthesisTimeoutError`` (code SYNTHESIS_TIMEOUT),
    ``memory_limit`` (bytes of BDD memory, default 2 GiB) raises ``SynthesisMemoryError``.
    ``UndeclaredPropositionError`` / ``NotGR1FormulaError`` for formulas outside the declared
    propositions or GR(1).
    """
    interrupt = Interrupt(cancel, deadline, memory_limit)
    with _memory_failures_reported(memory_limit):
        return _synthesize(spec, robotics_semantics, interrupt, counterstrategy, explain,
                           options, strategy)


def is_realizable(spec: GR1Specification, robotics_semantics: bool = True,
                  cancel: threading.Event | None = None, deadline: float | None = None,
                  memory_limit: int | None = DEFAULT_MEMORY_LIMIT,
                  options: Options | None = None) -> bool:
    """Only the verdict (no strategy, no explanation); same limits as ``synthesize``."""
    return synthesize(spec, robotics_semantics, cancel, deadline, explain=False, options=options,
                      strategy=False, memory_limit=memory_limit).realizable


@contextmanager
def _memory_failures_reported(memory_limit: int | None):
    """CUDD fails an operation beyond its memory limit; dd reports that as a NULL node."""
    try:
        yield
    except ValueError as error:
        if memory_limit is not None and 'NULL' in str(error):
            raise memory_exceeded(memory_limit) from error
        raise


def _synthesize(spec, robotics_semantics, interrupt, counterstrategy, explain, options,
                strategy) -> SynthesisResult:
    start = time.perf_counter()
    interrupt.check()
    game = SymbolicGame(spec, options, interrupt)
    solver = Solver(game, options)
    built = time.perf_counter()

    def still_possible(winning):
        return initial_positions_win(game, winning, robotics_semantics)

    solution = solve_system_game(solver, stop_when_losing=still_possible)
    realizable = solution.complete and still_possible(solution.winning)
    if realizable:  # the counter-game of an unrealizable one is another solve: it may sift
        solver.reordering.stop()
    solved = time.perf_counter()
    result = SynthesisResult(realizable=realizable)
    # Strategies and explanations load only when asked: a verdict alone on a tiny
    # specification is mostly start-up (5 ms less of about 120).
    if realizable:
        if strategy:
            from ltl_synthesizer.strategy import extract_strategy, streamed_strategy
            result.strategy = streamed_strategy(game, solution) if strategy == 'stream' \
                else extract_strategy(game, solution)
        if game.env_init & game.sys_init == game.false:
            result.stats['warnings'] = ['ENV_INIT and SYS_INIT are contradictory: realizable '
                                        'vacuously, the strategy has no initial state']
    elif counterstrategy or explain:
        from ltl_synthesizer.explain import explain_unrealizable
        from ltl_synthesizer.strategy import extract_counterstrategy
        environment = solve_environment_game(solver)
        if counterstrategy:
            result.counterstrategy = extract_counterstrategy(game, environment, robotics_semantics)
        if explain:
            result.explanation = explain_unrealizable(game, solution, environment, robotics_semantics)
    else:
        result.explanation = 'Specification is unrealizable.'
    finished = time.perf_counter()
    result.stats.update({
        'build_seconds': built - start, 'solve_seconds': solved - built,
        'extract_seconds': finished - solved, 'total_seconds': finished - start,
        'variables': len(game.variables), 'strategy_nodes':
            len(result.strategy['nodes']) if result.strategy and strategy != 'stream' else 0,
        **game.statistics()})
    return result
