"""The synthesis service: one request's answer, as the ``ltl_synthesis`` node gives it (ROS-free).

The policy around a synthesis lives here, the node only adapts messages to it: which backend
synthesizes (our own in a child process, or a slugs executable), the byproduct files written on
the way, the strategy cache of identical requests (its key, and the answer kept as an
:class:`KeptAnswer`), and, for an unrealizable specification, its diagnosis and, for a
realizable one, the well-separation check, both in a child process within the request's time.

    service = SynthesisService(settings=lambda: SynthesisSettings(), byproducts=store_factory,
                               cache=answer_cache(64 * 2**20), processes=SynthesisProcesses(),
                               explainers=Explainers(diagnose, check_well_separation, read_provenance))
    job = SynthesisJob(sections, 'paper', timeout=60, deadline=time.monotonic() + 60)
    answer, key = service.cached_answer(job)      # a hit, cheap enough for any thread
    answer = answer or service.answer(job, key)   # a synthesis (a worker thread's job)

The diagnosis and the well-separation explanation speak the task's terms, from the
specification's provenance: they belong to ltl_specification, above this package, so the
caller hands them in (:class:`Explainers`). Byproduct files are the caller's too: ``byproducts()``
gives a store whose ``open_set(spec_name)`` yields a set with ``write(kind, text) -> path``,
``paths`` and ``name`` (synthesis_manager.byproducts).
"""

from __future__ import annotations

import importlib.metadata
import json
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, ContextManager, Protocol

from ltl_synthesizer.cache import CacheDirectoryError, Entry, StrategyCache, cache_key, source_digest
from ltl_synthesizer.errors import SynthesisCancelledError, SynthesisError
from ltl_synthesizer.external import run_external_synthesizer
from ltl_synthesizer.interrupt import Limits
from ltl_synthesizer.isolated import (SpecificationText, SynthesisProcesses, WellSeparationCheck, WellSeparationOutcome,
                                     byproduct_texts)
from ltl_synthesizer.strategy import strategy_to_json
from respec.automaton import Automaton, AutomatonState, automaton_from_strategy, strategy_move_problems
from respec.vocabulary.errors import CodedError, ErrorCode
from respec.parsing import spec_from_text_sections
from respec.spec import GR1Specification
from respec.untrusted import utf8_length

class ByproductFiles(Protocol):
    """The files of one synthesis (``synthesis_manager.byproducts.ByproductSet``)."""

    name: str
    paths: dict[str, Path]

    def write(self, extension: str, text: str) -> Path: ...


class Byproducts(Protocol):
    """Where syntheses write their files (``synthesis_manager.byproducts.ByproductStore``)."""

    def open_set(self, spec_name: str) -> ContextManager[ByproductFiles]: ...


BACKENDS = ('builtin', 'slugs')
DIAGNOSIS_GRACE = 1.0  # seconds past its own time limit before the diagnosis process is killed
#: Specifications (bytes of text) over this are parsed and printed in a synthesis child process,
#: where a deadline or a cancel stops them, not in the caller's (builtin backend).
LARGE_SPEC_BYTES = 64 * 1024
#: Largest strategy (transitions) a builtin synthesis sends back: about 900 B each in the
#: server (automaton, JSON byproduct, messages), so about 90 MB per goal at most.
DEFAULT_MAX_STRATEGY_EDGES = 100_000
#: The code an answer comes from: part of every cache key, so that entries kept on disk by
#: other code miss (ltl_synthesizer.cache.source_digest).
ANSWERING_PACKAGES = ('respec', 'ltl_specification', 'ltl_synthesizer', 'synthesis_manager')
#: A job's provenance not read yet (None is one read: there is none, or it is unreadable).
_NOT_READ: Any = object()


@dataclass(frozen=True)
class SynthesisSettings:
    """What a synthesis service is set to (the ltl_synthesis node's parameters of these names)."""

    backend: str = 'builtin'
    slugs_executable: str = 'slugs'
    robotics_semantics: bool = True
    memory_limit_mb: int = 2048
    diagnosis_timeout: float = 20.0
    check_well_separation: bool = True
    max_strategy_edges: int = DEFAULT_MAX_STRATEGY_EDGES


@dataclass(frozen=True)
class Explainers:
    """How an answer is explained: picklable top-level functions, run in a synthesis child.

    ``diagnose(details, spec, provenance, robotics_semantics, limits) -> message``;
    ``check_well_separation(spec, provenance, limits, game=None) -> warning`` (``game``: the
    solved game, when the builtin synthesis's child checks it); ``read_provenance(text)``
    (raises ValueError for text it cannot read); ``incomplete_mark``: what a diagnosis whose
    time ran out before its core was computed says (such an answer is not kept)."""

    # a provenance is the explainers' own (ltl_specification.provenance.Provenance, or None)
    diagnose: Callable[[str, GR1Specification, Any, bool, Limits], str]
    check_well_separation: Callable[..., str]
    read_provenance: Callable[[str], Any]
    incomplete_mark: str


@dataclass
class SynthesisJob:
    """One request: the specification's text sections, the byproducts' spec name, what the
    answer is explained with, and its limits (``deadline``: time.monotonic(); ``timeout``: the
    limit it stands for, as messages name it)."""

    sections: dict[str, list[str]]
    spec_name: str
    timeout: float
    deadline: float
    provenance: str = ''
    diagnosis_timeout: float = 0.0
    cancel: threading.Event = field(default_factory=threading.Event)

    def stopped(self) -> bool:
        return self.cancel.is_set() or time.monotonic() > self.deadline

    def stopped_answer(self, reason: str = '', during: str = '', synthesizable: bool = False) -> SynthesisAnswer:
        """The answer of a job stopped by ``reason`` (default: its cancel or its deadline);
        ``during``: the stage the synthesis was in and its size measure, when it said."""
        reason = reason or ('cancelled' if self.cancel.is_set() else 'timeout')
        code = ErrorCode.SYNTHESIS_TIMEOUT if reason == 'timeout' else ErrorCode.PREEMPTED
        where = f' while {during}' if during else ''
        return SynthesisAnswer(code, f'synthesis stopped: {reason}{where} (time limit {self.timeout:g} s)',
                               synthesizable)

    def is_large(self) -> bool:
        """Whether the specification's text is over LARGE_SPEC_BYTES."""
        return sum(utf8_length(line) for lines in self.sections.values() for line in lines) > LARGE_SPEC_BYTES


@dataclass
class SynthesisAnswer:
    """What a request is answered: its code and message, the verdict and, when realizable, the automaton."""

    code: ErrorCode
    message: str = ''
    synthesizable: bool = False
    automaton: Automaton | None = None


@dataclass(frozen=True)
class KeptAnswer:
    """What the strategy cache keeps of an answer: its byproduct files' texts and the answer,
    an unrealizable one's message without its spec name (``message`` is then the parts before
    and after the head naming it)."""

    byproducts: dict[str, str]
    synthesizable: bool
    code: str
    message: str | tuple[str, str]
    automaton: Automaton | None = None

    def to_entry(self) -> dict[str, bytes]:
        """The cache entry: named byte strings."""
        entry = {kind: text.encode() for kind, text in self.byproducts.items()}
        entry.update(synthesizable=b'1' if self.synthesizable else b'0', code=self.code.encode())
        if self.synthesizable:
            assert isinstance(self.message, str) and self.automaton is not None  # a realizable answer's
            entry.update(message=self.message.encode(), automaton=_automaton_json(self.automaton).encode())
        else:
            entry.update(message_before=self.message[0].encode(), message_after=self.message[1].encode())
        return entry

    @classmethod
    def from_entry(cls, entry: Entry) -> KeptAnswer:
        """The kept answer of a cache entry (KeyError, ValueError: not one)."""
        byproducts = {kind: entry[kind].decode() for kind in ('structuredslugs', 'slugsin', 'json') if kind in entry}
        if entry['synthesizable'] != b'1':
            return cls(byproducts, False, entry['code'].decode(),
                       (entry['message_before'].decode(), entry['message_after'].decode()))
        automaton = _automaton_from_json(entry['automaton'])
        return cls(byproducts, True, entry['code'].decode(), entry['message'].decode(), automaton)

    def answer(self, spec_name: str) -> SynthesisAnswer:
        """The answer to a request naming ``spec_name``, byte-identical to the one it was kept from."""
        message = self.message if self.synthesizable else unrealizable_head(spec_name).join(self.message)
        assert isinstance(message, str)  # a realizable answer's message is one text
        return SynthesisAnswer(ErrorCode[self.code], message, self.synthesizable, self.automaton)


def answer_cache(max_bytes: int, directory: str = '', key_file: str = '',
                 warn: Callable[[str], None] = lambda text: None) -> StrategyCache:
    """The strategy cache of a service (``directory``: '' for memory only). An unsafe or unusable
    directory or key file is warned about and the cache kept in memory only: answers stay right,
    only a restart loses them."""
    try:
        return StrategyCache(max_bytes, directory or None, key_file or None)
    except (CacheDirectoryError, OSError) as error:
        warn(f'strategy cache kept in memory only: {error}'[:300])
        return StrategyCache(max_bytes)


class SynthesisService:
    """Answers synthesis jobs with ``settings()`` (read once per job), writing their byproducts,
    keeping answers in ``cache`` and running syntheses and explanations in ``processes``."""

    def __init__(self, settings: Callable[[], SynthesisSettings], byproducts: Callable[[], Byproducts],
                 cache: StrategyCache, processes: SynthesisProcesses, explainers: Explainers,
                 warn: Callable[[str], None] = lambda text: None) -> None:
        self.settings, self.byproducts, self.cache = settings, byproducts, cache
        self.processes, self.explainers, self.warn = processes, explainers, warn
        self.answering_code = (f"{source_digest(ANSWERING_PACKAGES)} dd {importlib.metadata.version('dd')}"
                               if cache.enabled else '')

    def cache_key(self, job: SynthesisJob, settings: SynthesisSettings | None = None) -> str | None:
        """The strategy cache's key of ``job`` (None: not cached, with the cache off or the
        slugs backend, an external program that may change unseen).

        It digests everything the answer (the response and the byproduct files) depends on:
        the specification's text as sent, the provenance (the diagnosis and the well-separation
        warning tell it), the settings that change the answer (robotics_semantics,
        check_well_separation, max_strategy_edges), and the code that computes it (the sources
        of ANSWERING_PACKAGES, the dd version). Both the specification and its provenance are
        compiled from the robot system's files, so a changed file that changes the answer
        changes the key; the request names no system beyond them. spec_name only names the
        byproduct files and appears in an unrealizable answer's message, so it is left out
        (the message is kept without it). Time and memory limits decide whether an answer
        comes, not which: a hit is the answer of a synthesis that had enough of both."""
        settings = settings or self.settings()
        if not self.cache.enabled or settings.backend != 'builtin':
            return None
        return cache_key({
            'code': self.answering_code, 'specification': job.sections, 'provenance': job.provenance,
            'robotics_semantics': settings.robotics_semantics,
            'check_well_separation': settings.check_well_separation,
            'max_strategy_edges': settings.max_strategy_edges})

    def cached_answer(self, job: SynthesisJob) -> tuple[SynthesisAnswer | None, str | None]:
        """A kept answer to ``job`` (None: none) and its key. A large specification's key is
        left to :meth:`answer`, in a worker: hashing megabytes would hold the caller's thread
        (3.9 MB: 26 ms)."""
        key = None if job.is_large() else self.cache_key(job)
        entry = self.cache.get(key, lambda entry: self.loaded_entry_problem(entry, job)) if key else None
        return (None, key) if entry is None else (self._from_entry(entry, job), key)

    def answer(self, job: SynthesisJob, key: str | None = None) -> SynthesisAnswer:
        """Synthesize ``job``, once for concurrent identical jobs: with a cache key, a job
        identical to one being synthesized waits for its answer. ``key``: the one
        :meth:`cached_answer` computed (None: computed here, e.g. a large specification's)."""
        if job.stopped():  # stopped while waiting for a worker
            return job.stopped_answer()
        settings = self.settings()
        key = key or self.cache_key(job, settings)
        if key is None:
            return self._synthesize(job, settings)[0]
        fresh = []

        def compute() -> Entry | None:
            answer, kept = self._synthesize(job, settings, keep=True)
            fresh.append(answer)
            return kept.to_entry() if kept else None
        entry, how = self.cache.answer(key, compute, give_up=job.stopped,
                                       check=lambda entry: self.loaded_entry_problem(entry, job))
        if how == 'gave up':
            return job.stopped_answer()
        if how == 'computed':
            return fresh[0]
        assert entry is not None  # a kept or a shared answer
        return self._from_entry(entry, job)

    def loaded_entry_problem(self, entry: Entry, job: SynthesisJob) -> str | None:
        """What is wrong with a realizable answer read back from the cache directory (None:
        nothing found): its strategy's moves against the job's specification
        (``respec.automaton.strategy_move_problems``), and its automaton against its strategy.
        An unrealizable verdict is signed but not re-checked (that would be a synthesis); nor
        is a specification over 64 KB, which the caller's thread does not parse."""
        if entry.get('synthesizable') != b'1' or job.is_large():
            return None
        try:
            spec = spec_from_text_sections(job.sections)
            strategy = json.loads(entry['json'])
            problems = strategy_move_problems(strategy, spec)
            if not problems and KeptAnswer.from_entry(entry).automaton != automaton_from_strategy(strategy, spec):
                problems = ['its automaton is not the one of its strategy']
        except (KeyError, ValueError, TypeError, CodedError) as error:
            problems = [f'it cannot be read back ({error!r:.100})']
        if problems:
            self.warn(f'strategy cache: an entry read from the directory is not served: {problems[0]}')
        return problems[0] if problems else None

    def _from_entry(self, entry: Entry, job: SynthesisJob) -> SynthesisAnswer:
        """``job``'s answer from a kept one: its byproduct files written again under the job's spec_name."""
        kept = KeptAnswer.from_entry(entry)
        with self.byproducts().open_set(job.spec_name) as files:
            for kind, text in kept.byproducts.items():
                files.write(kind, text)
        return kept.answer(files.name)

    def _synthesize(self, job: SynthesisJob, settings: SynthesisSettings,
                    keep: bool = False) -> tuple[SynthesisAnswer, KeptAnswer | None]:
        """Synthesize ``job``: its answer, and with ``keep`` what the strategy cache keeps of
        it, or None when it must not be kept: a stop (time limit, cancel), a failure (memory
        limit, a strategy too large, the process died), or a diagnosis or well-separation
        check cut short by its time (a fresh synthesis with more time would say more).
        Realizable and unrealizable verdicts are deterministic: kept."""
        if job.stopped():  # e.g. after waiting for an identical request
            return job.stopped_answer(), None
        backend = settings.backend
        spec: SpecificationText | GR1Specification
        if backend == 'builtin' and job.is_large():
            spec = SpecificationText(job.sections)  # parsed in the synthesis children
            try:
                structuredslugs, slugsin, inputs, outputs = self.processes.call(
                    byproduct_texts, (spec,), cancel=job.cancel, deadline=job.deadline)
            except SynthesisCancelledError as stopped:
                return job.stopped_answer(stopped.reason, getattr(stopped, 'during', '')), None
            variables = GR1Specification(env_props=inputs, sys_props=outputs)  # what the automaton names
        else:
            spec = variables = spec_from_text_sections(job.sections)
            structuredslugs, slugsin = spec.to_structuredslugs(), spec.to_slugsin()
        byproducts = {'structuredslugs': structuredslugs, 'slugsin': slugsin} if keep else {}
        memory_limit = settings.memory_limit_mb * 2**20
        with self.byproducts().open_set(job.spec_name) as files:
            files.write('structuredslugs', structuredslugs)
            slugsin_path = files.write('slugsin', slugsin)
            del structuredslugs, slugsin
            robotics = settings.robotics_semantics
            checked_in_synthesis: WellSeparationOutcome | None = None
            provenance: Any = _NOT_READ
            if backend == 'builtin':
                limits = Limits(job.cancel, job.deadline, memory_limit)
                try:
                    if settings.check_well_separation:  # on the solved game, in the synthesis's child
                        provenance = self._provenance(job)  # read once: the diagnosis needs it too
                        check = WellSeparationCheck(self.explainers.check_well_separation, provenance,
                                                    job.diagnosis_timeout or settings.diagnosis_timeout)
                        result, checked_in_synthesis = self.processes.synthesize_then_check(
                            spec, robotics, limits, check, max_strategy_edges=settings.max_strategy_edges,
                            grace=DIAGNOSIS_GRACE)
                    else:
                        result = self.processes.synthesize(spec, robotics, limits,
                                                           max_strategy_edges=settings.max_strategy_edges)
                except SynthesisCancelledError as stopped:
                    return job.stopped_answer(stopped.reason, getattr(stopped, 'during', '')), None
                realizable, strategy, explanation = result.realizable, result.strategy, result.explanation
            elif backend == 'slugs':
                realizable, strategy, stderr = run_external_synthesizer(
                    settings.slugs_executable, slugsin_path, files.paths['json'], robotics_semantics=robotics,
                    timeout=max(0.0, job.deadline - time.monotonic()), cancel=job.cancel)
                explanation = stderr.strip()
            else:
                return SynthesisAnswer(ErrorCode.SYNTHESIS_FAILED,
                                       f'unknown backend {backend!r} (use one of {", ".join(BACKENDS)})'), None
            if not realizable:
                head = unrealizable_head(files.name)
                details = f'{head}: {explanation}'.rstrip(': ')
                try:
                    message, diagnosed = self._diagnosed(details, spec, job, settings, provenance)
                except SynthesisCancelledError as stopped:
                    return job.stopped_answer(stopped.reason, getattr(stopped, 'during', '')), None
                answer = SynthesisAnswer(ErrorCode.SPEC_UNSYNTHESIZABLE, message)
                before, found, after = message.rpartition(head)  # kept without the spec name
                if not (keep and diagnosed and found):
                    return answer, None
                return answer, KeptAnswer(byproducts, False, 'SPEC_UNSYNTHESIZABLE', (before, after))
            assert strategy is not None  # both backends give a realizable specification's strategy
            strategy_json = strategy_to_json(strategy)
            files.write('json', strategy_json)
        try:
            if checked_in_synthesis is None:
                warning, checked = self._well_separation_warning(spec, job, settings)
            else:
                warning, checked = checked_in_synthesis.warning, not checked_in_synthesis.stopped
                if checked_in_synthesis.stopped:
                    self.warn(f'well-separation not checked: {checked_in_synthesis.stopped}'[:300])
        except SynthesisCancelledError as stopped:
            return job.stopped_answer(stopped.reason, getattr(stopped, 'during', ''), synthesizable=True), None
        answer = SynthesisAnswer(ErrorCode.SUCCESS, warning, True, automaton_from_strategy(strategy, variables))
        if not (keep and checked):
            return answer, None
        return answer, KeptAnswer({**byproducts, 'json': strategy_json}, True, 'SUCCESS', warning, answer.automaton)

    def _well_separation_warning(self, spec: SpecificationText | GR1Specification, job: SynthesisJob,
                                 settings: SynthesisSettings) -> tuple[str, bool]:
        """The warning that the controller can win by forcing the environment to break its
        assumptions ('' when it cannot, when check_well_separation is off, or when the check
        does not end within the diagnosis time and the job's time limit: the automaton
        stands without it), and whether the check ended (or was off). The check runs in a
        synthesis child process, with the memory limit; a cancel raises SynthesisCancelledError."""
        if not settings.check_well_separation:
            return '', True
        limit = job.diagnosis_timeout or settings.diagnosis_timeout
        check_deadline = min(time.monotonic() + limit, job.deadline)
        if check_deadline <= time.monotonic():
            return '', False
        limits = Limits(deadline=check_deadline, memory_limit=settings.memory_limit_mb * 2**20)
        try:
            return self.processes.call(self.explainers.check_well_separation, (spec, self._provenance(job), limits),
                                       cancel=job.cancel, deadline=check_deadline + DIAGNOSIS_GRACE), True
        except SynthesisError as error:
            if job.cancel.is_set():
                raise SynthesisCancelledError('cancelled') from None
            self.warn(f'well-separation not checked: {error}'[:300])
            return '', False

    def _diagnosed(self, details: str, spec: SpecificationText | GR1Specification, job: SynthesisJob,
                   settings: SynthesisSettings, provenance: Any = _NOT_READ) -> tuple[str, bool]:
        """``details`` (the synthesizer's explanation), led by why the task cannot be done: in
        the task's terms when the job carries the specification's provenance, else by its
        formulas; and whether the diagnosis was whole (its core computed). The diagnosis runs in
        a synthesis child process, with the memory limit, and ends by diagnosis_timeout and
        before the job's time limit; without an answer by then the verdict stands with
        ``details``. A cancel raises SynthesisCancelledError. ``provenance``: the job's, if read
        already (else _NOT_READ)."""
        if provenance is _NOT_READ:
            provenance = self._provenance(job)
        limit = job.diagnosis_timeout or settings.diagnosis_timeout
        diagnosis_deadline = min(time.monotonic() + limit, job.deadline - DIAGNOSIS_GRACE)
        if diagnosis_deadline <= time.monotonic():
            return details, False
        limits = Limits(deadline=diagnosis_deadline, memory_limit=settings.memory_limit_mb * 2**20)
        try:
            # The diagnosis keeps its own deadline; the child is killed only if it overruns.
            message = self.processes.call(
                self.explainers.diagnose, (details, spec, provenance, settings.robotics_semantics, limits),
                cancel=job.cancel, deadline=diagnosis_deadline + DIAGNOSIS_GRACE)
        except SynthesisError:
            if job.cancel.is_set():
                raise SynthesisCancelledError('cancelled') from None
            return details, False  # out of time, or its process died: the verdict stands without it
        # A diagnosis that failed says only the details; one whose time ran out says so.
        return message, message != details and self.explainers.incomplete_mark not in message

    def _provenance(self, job: SynthesisJob) -> Any:  # the explainers' provenance, or None
        """The job's provenance (None without one, or when it cannot be read: warned about)."""
        if not job.provenance:
            return None
        try:
            return self.explainers.read_provenance(job.provenance)
        except ValueError as error:
            self.warn(f'request.provenance ignored (no diagnosis): {error!r}'[:300])
            return None


def _automaton_json(automaton: Automaton) -> str:
    """An automaton as compact JSON: each state one array, its valuations as 0 and 1."""
    return json.dumps([automaton.output_variables, automaton.input_variables, automaton.initial_states,
                       [[state.name, [int(value) for value in state.output_valuation],
                         [int(value) for value in state.input_valuation], state.transitions, state.rank]
                        for state in automaton.states]], separators=(',', ':'))


def _automaton_from_json(text: bytes) -> Automaton:
    """The automaton of :func:`_automaton_json` (ValueError, TypeError: not one)."""
    outputs, inputs, initial, states = json.loads(text)
    return Automaton(outputs, inputs, [
        AutomatonState(name, [bool(value) for value in output_valuation], [bool(value) for value in input_valuation],
                       transitions, rank) for name, output_valuation, input_valuation, transitions, rank in states],
        initial)


def unrealizable_head(spec_name: str) -> str:
    """How an unrealizable answer's synthesizer details start (the only part naming the spec)."""
    return f'specification {spec_name!r} is unrealizable'
