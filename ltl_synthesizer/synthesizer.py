"""The synthesizer's entry point: specification in, strategy (or counter-strategy) out."""

from __future__ import annotations

import threading
import time
from dataclasses import dataclass, field

from respec.spec import GR1Specification

from ltl_synthesizer.explain import explain_unrealizable
from ltl_synthesizer.gr1 import solve_environment_game, solve_system_game
from ltl_synthesizer.strategy import extract_counterstrategy, extract_strategy
from ltl_synthesizer.symbolic import Interrupt, Options, SymbolicGame


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
               options: Options | None = None) -> SynthesisResult:
    """Decide realizability of ``spec`` and extract an explicit strategy (or counter-strategy).

    Raises ``SynthesisCancelled`` when ``cancel`` is set or ``deadline`` (a
    ``time.monotonic()`` instant) passes; ``UnknownPropositionError`` /
    ``InvalidFormulaError`` for formulas outside the declared propositions or GR(1).
    """
    start = time.perf_counter()
    interrupt = Interrupt(cancel, deadline)
    interrupt.check()
    game = SymbolicGame(spec, options, interrupt)
    built = time.perf_counter()

    def still_possible(winning):
        return initial_positions_win(game, winning, robotics_semantics)

    solution = solve_system_game(game, stop_when_losing=still_possible)
    realizable = solution.complete and still_possible(solution.winning)
    solved = time.perf_counter()
    result = SynthesisResult(realizable=realizable)
    if realizable:
        result.strategy = extract_strategy(game, solution)
        if game.env_init & game.sys_init == game.false:
            result.stats['warnings'] = ['ENV_INIT and SYS_INIT are contradictory: realizable '
                                        'vacuously, the strategy has no initial state']
    elif counterstrategy or explain:
        environment = solve_environment_game(game)
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
            len(result.strategy['nodes']) if result.strategy else 0,
        **game.statistics()})
    return result
