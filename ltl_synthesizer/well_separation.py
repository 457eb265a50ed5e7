"""Well-separation: can the system win by forcing the environment to break its assumptions?

A GR(1) specification promises the guarantees only while the environment keeps its
assumptions. If the system can *force* the environment into a position from which the
assumptions cannot all be kept, a synthesized controller may "win" vacuously, by cheating,
instead of doing its job. Maoz and Ringert ("On well-separation of GR(1) specifications",
FSE 2016) call such a specification non-well-separated, and check it as a game: the
specification is non-well-separated iff the system, obeying its own initial and safety
guarantees, wins the game whose winning condition is the *negation* of the assumptions —
that is, realizability of the specification with every system justice guarantee replaced by
FALSE.

The variant implemented here (their check "with system safety", from the initial states):

* the environment's side is the generalized Büchi game of its assumptions — keep ENV_TRANS
  at every step and satisfy every ENV_LIVENESS infinitely often —, played against any system
  move that SYS_TRANS allows (a position where the system has no legal move counts as won by
  the environment: a system that blocks itself breaks its own guarantees, it does not cheat);
* the positions from which the environment can keep its assumptions are the fixpoint
  ``keepable = νZ. ⋀_j μY. EnvCpre((J_j ∧ Z') ∨ Y')`` (:func:`assumptions_keepable`);
* the specification is non-well-separated iff some initial position (ENV_INIT ∧ SYS_INIT)
  lies outside ``keepable`` (the system can cheat from there), or ENV_INIT is
  unsatisfiable (the environment breaks its assumptions at once).

The assumptions involved are named as a minimal set (deletion-based, as the unrealizable
cores of ``ltl_synthesizer.unrealizable_core``): ENV_TRANS formulas and ENV_LIVENESS
formulas that the system can still force the environment to break when only they are
assumed; dropping any one of them lets the environment keep the rest.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

from respec.ltl import to_infix
from respec.spec import GR1Specification

from ltl_synthesizer.interrupt import Interrupt, Limits
from ltl_synthesizer.cudd_import import Node
from ltl_synthesizer.symbolic import SymbolicGame

# Beyond this many assumptions the involved ones are all listed rather than minimized (each
# deletion step solves a game).
MAX_MINIMIZED_ASSUMPTIONS = 60


@dataclass
class WellSeparation:
    """The check's answer: ``well_separated``, and otherwise the assumptions the system can
    force the environment to break (e.g. ``env_trans #0 'x -> next(!x)'``) and from how many
    initial positions."""

    well_separated: bool
    assumptions: list[str] = field(default_factory=list)
    cheating_initial_positions: int = 0
    involved: list[tuple[str, int]] = field(default_factory=list)   # (section, index) of each assumption

    def summary(self) -> str:
        """The check's answer in one line, either way (what ``gr1synth --check-well-separation`` prints)."""
        return self.warning() or ('Well-separated: the system cannot force the environment to break '
                                  'its assumptions.')

    def warning(self, names: list[str] | None = None) -> str:
        """One sentence for users ('' when well-separated); ``names``: the assumptions as a
        caller knows them (e.g. by paper equation and configuration entry), in ``involved``'s
        order, instead of by section and index."""
        if self.well_separated:
            return ''
        named = '; '.join(names or self.assumptions)
        return ('Warning: the controller can win by forcing the environment to break its assumptions '
                f'(the specification is not well-separated): the system can force a violation of {named}. '
                'A controller synthesized from it may meet its goals only by cheating; weaken or correct '
                'these assumptions.')


# --- the fixpoint ----------------------------------------------------------------------------

def environment_controllable_predecessor(game: SymbolicGame, target: Node) -> Node:
    """EnvCpre: positions from which the environment has a next input allowed by ENV_TRANS such
    that every next output SYS_TRANS allows makes the move satisfy ``target`` (a set of moves,
    over current and next variables).

    It is the dual of the system's controllable predecessor (slugs' "cox": for every next input
    some next output lands in a set), ``EnvCpre(T) = ¬cox(¬T)``, computed by the solver's own
    partitioned product (a monolithic ENV_TRANS conjunction per step was 100x slower)."""
    return ~game.cox(~target)


def assumptions_keepable(game: SymbolicGame) -> Node:
    """``νZ. ⋀_j μY. EnvCpre((J_j ∧ Z') ∨ Y')``: the positions from which the environment can keep
    ENV_TRANS forever and satisfy every ENV_LIVENESS J_j infinitely often, whatever the system
    does (the generalized Büchi game of the assumptions, played by the environment)."""
    keepable = game.true
    while True:
        narrowed = game.true
        for goal in game.env_goals:
            narrowed &= _reach_goal_then(game, goal, keepable)
        if narrowed == keepable:
            return keepable
        keepable = narrowed


def _reach_goal_then(game: SymbolicGame, goal: Node, keepable: Node) -> Node:
    """``μY. EnvCpre((J ∧ Z') ∨ Y')``: positions from which the environment can force a move
    satisfying ``goal`` into ``keepable``, keeping ENV_TRANS on the way."""
    arrived_in = goal & game.prime(keepable)
    reaching = game.false
    while True:
        game.interrupt.check()
        grown = environment_controllable_predecessor(game, arrived_in | game.prime(reaching))
        if grown == reaching:
            return reaching
        reaching = grown


def cheating_initial_positions(game: SymbolicGame) -> Node:
    """Initial positions (ENV_INIT ∧ SYS_INIT) from which the system can force the environment
    to break its assumptions."""
    return game.env_init & game.sys_init & ~assumptions_keepable(game)


# --- the check -------------------------------------------------------------------------------

def is_well_separated(game: SymbolicGame) -> bool:
    """The verdict alone (no assumptions named): for callers that try many specifications."""
    return bool(game.env_init != game.false and cheating_initial_positions(game) == game.false)  # dd: Any


def check_well_separation(spec: GR1Specification, limits: Limits = Limits(),
                          game: SymbolicGame | None = None) -> WellSeparation:
    """Whether ``spec`` is well-separated (see the module doc), naming the assumptions involved
    when it is not; ``game``: the game of ``spec`` if one is built already (a solved one: the
    check then stops by ``limits``, not by the game's own, and names its own stage)."""
    if game is None:
        return _checked(spec, limits, SymbolicGame(spec, None, _interrupt(spec, limits)))
    solver_interrupt, game.interrupt = game.interrupt, _interrupt(spec, limits)
    try:
        return _checked(spec, limits, game)
    finally:
        game.interrupt = solver_interrupt


def _checked(spec: GR1Specification, limits: Limits, game: SymbolicGame) -> WellSeparation:
    if game.env_init == game.false:
        return WellSeparation(False, ['env_init (unsatisfiable: the environment breaks it at once)'])
    if is_well_separated(game):
        return WellSeparation(True)
    cheating = cheating_initial_positions(game)
    count = int(game.bdd.count(cheating, nvars=len(game.variables))) if game.variables else 1
    involved = _involved_assumptions(spec, limits)
    return WellSeparation(False, [_assumption_text(spec, section, index) for section, index in involved], count,
                          involved)


def _interrupt(spec: GR1Specification, limits: Limits) -> Interrupt:
    """The limits' check, naming this stage and the specification's size when they stop it."""
    interrupt = limits.interrupt()
    interrupt.stage = 'checking well-separation'
    interrupt.size = f'{len(spec.env_props)} inputs and {len(spec.sys_props)} outputs'
    return interrupt


def _forces_violation(spec: GR1Specification, kept: list[tuple[str, int]], limits: Limits) -> bool:
    """Whether the system can force a violation when only the assumptions ``kept`` are assumed
    (ENV_INIT always is)."""
    restricted = replace(spec, env_trans=[spec.env_trans[i] for s, i in kept if s == 'env_trans'],
                         env_liveness=[spec.env_liveness[i] for s, i in kept if s == 'env_liveness'])
    game = SymbolicGame(restricted, None, _interrupt(spec, limits))
    return bool(cheating_initial_positions(game) != game.false)  # dd's BDDs are Any to mypy


def _involved_assumptions(spec: GR1Specification, limits: Limits) -> list[tuple[str, int]]:
    """A minimal set of ENV_TRANS and ENV_LIVENESS formulas the system can force the environment
    to break (deletion-based: each one is left out if the violation stays forced without it)."""
    involved = [('env_trans', i) for i in range(len(spec.env_trans))] + \
               [('env_liveness', i) for i in range(len(spec.env_liveness))]
    if len(involved) > MAX_MINIMIZED_ASSUMPTIONS:
        return involved
    position = 0
    while position < len(involved):
        rest = involved[:position] + involved[position + 1:]
        if _forces_violation(spec, rest, limits):
            involved = rest
        else:
            position += 1
    return involved


def _assumption_text(spec: GR1Specification, section: str, index: int) -> str:
    return f"{section} #{index} '{to_infix(getattr(spec, section)[index])}'"
