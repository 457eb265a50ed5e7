"""A GR(1) synthesizer on CUDD (``dd.cudd``) speaking slugs' formats (ROS-free).

    from ltl_synthesizer import synthesize
    result = synthesize(spec)            # spec: respec.spec.GR1Specification
    result.realizable, result.strategy   # slugs --explicitStrategy --jsonOutput shape;
    result.explanation                   # or why it is unrealizable

The steps one at a time (a solved game holds BDDs: it stays in the process that solved it)::

    solved = solve(spec, robotics_semantics=True, limits=Limits(...), options=None)
    solved.realizable
    explicit_strategy(solved), stream_strategy(solved)   # realizable
    counter_strategy(solved), explain(solved)            # unrealizable
    is_realizable(spec, ...)                             # the verdict alone

Limits (every phase -- parsing, BDD building, solving, extraction, explanation -- checks them
in each of its loops, so a synthesis stops within a few milliseconds plus one BDD operation)::

    Limits(deadline=time.monotonic() + 60,   # -> SynthesisTimeoutError, code SYNTHESIS_TIMEOUT
           cancel=threading.Event(),         # set() -> SynthesisCancelledError, code PREEMPTED
           memory_limit=2 * 2**30)           # bytes (the default; None: none) -> SynthesisMemoryError

``limits.interrupt()`` is their check as one callable object: pass it to
``respec.parsing.parse_structuredslugs(text, check=interrupt)`` to bound parsing too.

Modules: interrupt (Limits and their check), symbolic (the game: formulas to BDDs,
enforceable predecessors), policy (Options and the automatic plan), synthesizer (the entry
points above), gr1 (the solver and its fixpoints), strategy (explicit strategies,
counter-strategies, slugs JSON), explanation (why unrealizable), unrealizable_core (minimal
unrealizable subsets of guarantees, by delta debugging), isolated (syntheses in child
processes that a cancel, a deadline or a shutdown ends at once, on respec.child_processes), cache (answers of identical requests),
service (one request's answer with the synthesis node's policy: backend, cache, diagnosis,
well-separation), command (the ``gr1synth`` command:
arguments, one run, outputs), cli (``gr1synth``) and serve (its resident mode), both on
command. Imports are lazy, so ``gr1synth --help`` starts without loading CUDD.
"""

import importlib
from typing import Any

_EXPORTS = {
    **{name: 'ltl_synthesizer.synthesizer' for name in (
        'solve', 'Solved', 'explicit_strategy', 'stream_strategy', 'counter_strategy', 'explain',
        'synthesize', 'is_realizable', 'SynthesisResult')},
    'Limits': 'ltl_synthesizer.interrupt', 'DEFAULT_MEMORY_LIMIT': 'ltl_synthesizer.interrupt',
    'Options': 'ltl_synthesizer.policy', 'Interrupt': 'ltl_synthesizer.interrupt',
    'SynthesisCancelledError': 'ltl_synthesizer.errors', 'SynthesisError': 'ltl_synthesizer.errors',
    'SynthesisMemoryError': 'ltl_synthesizer.errors', 'SynthesisTimeoutError': 'ltl_synthesizer.errors',
    'UndeclaredPropositionError': 'ltl_synthesizer.errors',
    'NotGR1FormulaError': 'ltl_synthesizer.errors',
}

__all__ = sorted(_EXPORTS)


def __getattr__(name: str) -> Any:
    if name not in _EXPORTS:
        raise AttributeError(f'module {__name__!r} has no attribute {name!r}')
    return getattr(importlib.import_module(_EXPORTS[name]), name)
