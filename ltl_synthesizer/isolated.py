"""Syntheses in child processes that a cancel, a deadline or a shutdown ends at once: the
synthesizer's use of the project's process runner (``respec.child_processes``).

The synthesizer checks its limits between BDD operations, but one CUDD operation on a large
specification can run for seconds, holding Python's GIL; so a synthesis runs in a child process
that the caller kills when it must stop (``respec.child_processes.runner``). ``SynthesisProcesses``
is a pool of such children for syntheses and other solver work (diagnoses, well-separation
checks), whose children import the synthesizer before their first request; the runner's stops
reach its callers as the synthesizer's errors (:func:`ltl_synthesizer.errors.in_synthesis_words`).

    processes = SynthesisProcesses()
    result = processes.synthesize(spec, limits=Limits(cancel=event, deadline=time.monotonic() + 60))
    value = processes.call(function, (SpecificationText(sections), ...), cancel=event, deadline=deadline)
    processes.close()

A cancel raises SynthesisCancelledError, the deadline SynthesisTimeoutError, a child that dies
SynthesisProcessDiedError. A synthesis's memory limit is its own (``ltl_synthesizer.Limits``,
checked in the child, which can say what it was doing); the pool's ``memory_limit`` bounds work
that checks none (SynthesisMemoryError).
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Callable

from ltl_synthesizer.errors import SynthesisError, in_synthesis_words
from ltl_synthesizer.interrupt import Limits, memory_exceeded
from respec.child_processes.errors import ChildWorkError
from respec.child_processes.runner import CHILD_NICENESS, IDLE_SECONDS, BuiltInChild, CancelFlag, ChildProcesses

if TYPE_CHECKING:
    from ltl_synthesizer.policy import Options
    from ltl_synthesizer.synthesizer import SynthesisResult
    from respec.spec import GR1Specification

#: What messages call the synthesizer's children.
SYNTHESIS_PROCESS = 'synthesis process'
#: What the pool's children import before their first request.
SYNTHESIZER_MODULE = 'ltl_synthesizer.synthesizer'


class SpecificationText(BuiltInChild):
    """A specification as its text sections, parsed where it is used: in the child (passed as
    an argument, the child gives the function the parsed GR1Specification). Parsing, printing
    and pickling a large specification take seconds of pure Python: done in the caller, they
    hold its interpreter, uninterruptible (a 3.9 MB one, about 9 s)."""

    def __init__(self, sections: dict[str, Any]) -> None:
        self.sections = sections

    def built(self) -> GR1Specification:
        from respec.parsing import spec_from_text_sections
        return spec_from_text_sections(self.sections)


def byproduct_texts(spec: GR1Specification) -> tuple[str, str, list[str], list[str]]:
    """The ``.structuredslugs`` and ``.slugsin`` texts of ``spec``, and its inputs and outputs."""
    return spec.to_structuredslugs(), spec.to_slugsin(), list(spec.env_props), list(spec.sys_props)


def synthesize_within(spec: GR1Specification, robotics_semantics: bool, limits: Limits, options: Options | None,
                      max_strategy_edges: int) -> SynthesisResult:
    """:func:`ltl_synthesizer.synthesize`, refusing (StrategyTooLargeError) a strategy of more
    than ``max_strategy_edges`` edges as soon as its extraction passes them, before anything is
    sent: each edge costs the receiving server about 900 B once turned into an automaton, its
    byproduct and its messages (a 215-byte specification with 11 free inputs has 8.4 M edges and
    grew a server to 7.7 GB; counted only after extraction, it took minutes in the child)."""
    from ltl_synthesizer.synthesizer import synthesize
    return synthesize(spec, robotics_semantics, limits, options, max_edges=max_strategy_edges)


@dataclass(frozen=True)
class WellSeparationCheck:
    """The well-separation check a synthesis child runs on the game it has just solved, when it
    is realizable: ``check(spec, provenance, limits, game) -> warning`` (a top-level function,
    e.g. ``ltl_specification.diagnosis.explain_well_separation``), ending within ``seconds`` of
    its start and by the synthesis's deadline, with its memory limit. Run in a child of its own,
    the check built the game again: 60-80 % of its time, a fifth of a small robot's pipeline."""

    check: Callable[..., str]
    provenance: Any
    seconds: float


@dataclass(frozen=True)
class WellSeparationOutcome:
    """What the check said: its ``warning`` ('' when well-separated), or, when a limit stopped
    it first, why (``stopped``; its warning is then '')."""

    warning: str = ''
    stopped: str = ''


def synthesize_then_check(spec: GR1Specification, robotics_semantics: bool, limits: Limits, options: Options | None,
                          max_strategy_edges: int | None,
                          well_separation: WellSeparationCheck) -> tuple[SynthesisResult, WellSeparationOutcome | None]:
    """:func:`synthesize_within`, then ``well_separation`` on the solved game when realizable
    (None when not run). A limit that stops the check leaves the synthesis's answer standing."""
    from ltl_synthesizer.synthesizer import solve, synthesis_result
    start = time.perf_counter()
    solved = solve(spec, robotics_semantics, limits, options)
    result = synthesis_result(solved, max_strategy_edges, start)
    if not result.realizable:
        return result, None
    deadline = time.monotonic() + well_separation.seconds
    if limits.deadline is not None:
        deadline = min(deadline, limits.deadline)
    try:
        warning = well_separation.check(spec, well_separation.provenance,
                                        Limits(deadline=deadline, memory_limit=limits.memory_limit), solved.game)
    except SynthesisError as stopped:
        return result, WellSeparationOutcome(stopped=str(stopped))
    except ValueError as error:  # CUDD failed an operation beyond the memory limit (dd: a NULL node)
        if limits.memory_limit is None or 'NULL' not in str(error):
            raise
        return result, WellSeparationOutcome(stopped=str(memory_exceeded(limits.memory_limit,
                                                                         'checking well-separation')))
    return result, WellSeparationOutcome(warning)


class SynthesisProcesses(ChildProcesses):
    """A pool of synthesis child processes, one per synthesis running at the same time, each
    ``niceness`` below its parent's CPU priority."""

    def __init__(self, idle_seconds: float = IDLE_SECONDS, niceness: int = CHILD_NICENESS):
        super().__init__(idle_seconds, niceness, SYNTHESIZER_MODULE, SYNTHESIS_PROCESS)

    def synthesize(self, spec: GR1Specification | SpecificationText, robotics_semantics: bool = True,
                   limits: Limits = Limits(), options: Options | None = None,
                   max_strategy_edges: int | None = None) -> SynthesisResult:
        """:func:`ltl_synthesizer.synthesize` in a child, killed once ``limits`` stop it; with
        ``max_strategy_edges``, a larger strategy is refused in the child (:func:`synthesize_within`)."""
        from ltl_synthesizer.synthesizer import synthesize
        result: SynthesisResult
        if max_strategy_edges:
            result = self.call(synthesize_within, (spec, robotics_semantics, limits.without_cancel(), options,
                                                   max_strategy_edges), cancel=limits.cancel, deadline=limits.deadline)
        else:
            result = self.call(synthesize, (spec, robotics_semantics, limits.without_cancel(), options),
                               cancel=limits.cancel, deadline=limits.deadline)
        return result

    def synthesize_then_check(self, spec: GR1Specification | SpecificationText, robotics_semantics: bool,
                              limits: Limits, well_separation: WellSeparationCheck, options: Options | None = None,
                              max_strategy_edges: int | None = None, grace: float = 0.0,
                              ) -> tuple[SynthesisResult, WellSeparationOutcome | None]:
        """:func:`synthesize_then_check` in a child, killed once ``limits`` stop it (its deadline:
        ``grace`` seconds later, for the check to say it ran out of time)."""
        deadline = None if limits.deadline is None else limits.deadline + grace
        result: tuple[SynthesisResult, WellSeparationOutcome | None] = self.call(
            synthesize_then_check, (spec, robotics_semantics, limits.without_cancel(), options, max_strategy_edges,
                                    well_separation), cancel=limits.cancel, deadline=deadline)
        return result

    def call(self, function: Callable[..., Any], args: tuple[Any, ...] | list[Any] = (),
             kwargs: dict[str, Any] | None = None, cancel: CancelFlag | None = None,
             deadline: float | None = None, memory_limit: int | None = None) -> Any:
        """``function(*args, **kwargs)`` in a child (:meth:`ChildProcesses.call`); the runner's
        stops raised as the synthesizer's errors."""
        try:
            return super().call(function, args, kwargs, cancel, deadline, memory_limit)
        except ChildWorkError as stopped:
            if isinstance(stopped, SynthesisError):  # raised by the work in the child
                raise
            raise in_synthesis_words(stopped) from None
