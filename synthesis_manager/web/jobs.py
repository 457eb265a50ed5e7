"""Synthesis jobs of the GUI: what the page asks for, what happened to it, its summary."""

from __future__ import annotations

import re
import threading
import time
from dataclasses import asdict, dataclass, field

from respec.vocabulary.errors import ErrorCode, quoted
from respec.vocabulary.naming import DEFAULT_SM_OUTCOMES, parse_names
from respec.spec import SECTIONS
from sm_generation.instantiation import StateInstantiation, count_states
from synthesis_manager.limits import oversized_strings, too_long
from synthesis_manager.web.artifacts import available_artifacts, download_labels, made_in_page
from synthesis_manager.web.errors import InvalidCharacterError, InvalidJobRequestError, NotFoundError
from synthesis_manager.web.outcome import JobOutcome

# The stop-early options the page offers (ltl_synthesis_only needs a whole specification).
JOB_OPTIONS = ('ltl_compilation_only', 'ltl_steps_only')
REQUEST_FIELDS = ('system', 'initial_conditions', 'goals', 'sm_outcomes', 'option', 'unordered', 'name',
                  'custom_ltl')
_NAME = re.compile(r'[A-Za-z][A-Za-z0-9_]*')
# Goals and initial conditions may also be negated (CNU's capability robots: '!soda').
_LITERAL = re.compile(r'!?[A-Za-z][A-Za-z0-9_]*')
LITERAL_FIELDS = ('initial_conditions', 'goals')
# Control characters (NUL included) and lone surrogates, which no request text may hold: a NUL
# cut a goal short downstream, and a surrogate cannot be encoded into any answer.
_FORBIDDEN_CHARACTER = re.compile('[\x00-\x1f\x7f-\x9f\ud800-\udfff]')
# The same, but for fields of several names, where tab, newline and carriage return may
# separate the names of a text (parse_names).
_FORBIDDEN_IN_NAME_LISTS = re.compile('[\x00-\x08\x0b\x0c\x0e-\x1f\x7f-\x9f\ud800-\udfff]')
NAME_LIST_FIELDS = ('initial_conditions', 'goals', 'sm_outcomes', 'fail_first')


@dataclass(frozen=True)
class JobRequest:
    """What the page asks for; ``goals`` in the order they must be achieved."""

    system: str
    initial_conditions: tuple[str, ...]
    goals: tuple[str, ...]
    sm_outcomes: tuple[str, ...] = DEFAULT_SM_OUTCOMES
    option: str | None = None
    unordered: bool = False
    name: str = ''
    # Formulas added to the compiled specification, by section (the action's ltl_specification,
    # ``--custom-ltl``'s mapping); None: none.
    custom_ltl: dict[str, list[str]] | None = None

    @classmethod
    def from_json(cls, body, systems: list[str]) -> 'JobRequest':
        """Validate a decoded JSON body; names may be lists or comma/space-separated text.

        Goal and initial-condition names are not checked against the system here: the
        pipeline does that and explains unknown names itself (UNKNOWN_PROPOSITION).
        """
        body = checked_body(body)
        unknown = sorted(set(body) - set(REQUEST_FIELDS))
        if unknown:
            raise InvalidJobRequestError(
                f'unknown field {quoted(unknown[0])} (fields: {", ".join(REQUEST_FIELDS)})', unknown[0])
        system = body.get('system')
        if not isinstance(system, str) or not system:
            raise InvalidJobRequestError('field "system" must name a system', 'system')
        if system not in systems:
            raise NotFoundError(f'unknown system {quoted(system)} (known systems: {", ".join(systems)})', system)
        goals = names_field(body, 'goals')
        if not goals:
            raise InvalidJobRequestError('field "goals" must name at least one goal', 'goals')
        sm_outcomes = names_field(body, 'sm_outcomes') or DEFAULT_SM_OUTCOMES
        option = body.get('option') or None
        if option is not None and option not in JOB_OPTIONS:
            raise InvalidJobRequestError(
                f'unknown option {quoted(option)} (options: {", ".join(JOB_OPTIONS)})', str(option))
        unordered = body.get('unordered', False)
        if not isinstance(unordered, bool):
            raise InvalidJobRequestError('field "unordered" must be true or false', 'unordered')
        name = body.get('name') or ''
        if not isinstance(name, str) or (name and not _NAME.fullmatch(name)):
            raise InvalidJobRequestError(
                f'behavior name {quoted(name)} must start with a letter and contain only letters, '
                'digits and underscores', str(name))
        return cls(system=system, initial_conditions=names_field(body, 'initial_conditions'), goals=goals,
                   sm_outcomes=sm_outcomes, option=option, unordered=unordered, name=name,
                   custom_ltl=custom_ltl_field(body))


def checked_body(body) -> dict:
    """A decoded request body that is a JSON object whose strings (keys too) are neither too
    long nor hold a character no name may have; else the error naming the first field that does."""
    if not isinstance(body, dict):
        raise InvalidJobRequestError('the request body must be a JSON object', 'body')
    for item, value in oversized_strings(body, 'body'):
        raise InvalidJobRequestError(too_long(item, value), item)
    for path, text in _strings(body, ''):
        field = re.split(r'[.\[]', path, maxsplit=1)[0] or 'body'
        found = (_FORBIDDEN_IN_NAME_LISTS if field in NAME_LIST_FIELDS else _FORBIDDEN_CHARACTER).search(text)
        if found:
            character = found.group()
            kind = 'a lone surrogate' if '\ud800' <= character <= '\udfff' else 'the control character'
            raise InvalidCharacterError(f'{quoted(path) if path else "a field name"} holds {kind} '
                                        f'U+{ord(character):04X} at character {found.start()}; names are '
                                        'letters, digits and _', field if len(field) <= 64 else 'body')
    return body


def _strings(value, path: str):
    """``(field path, string)`` for every string of decoded JSON, dict keys included (path of
    the dict). The guard bounds the nesting, so recursion is safe."""
    if isinstance(value, str):
        yield path, value
    elif isinstance(value, list):
        for index, element in enumerate(value):
            yield from _strings(element, f'{path}[{index}]')
    elif isinstance(value, dict):
        for key, element in value.items():
            yield path, key
            yield from _strings(element, f'{path}.{key}' if path else key)


def names_field(body: dict, key: str) -> tuple[str, ...]:
    value = body.get(key) or []
    if isinstance(value, list) and not all(isinstance(v, str) for v in value):
        raise InvalidJobRequestError(f'field {quoted(key)} must be a list of names', key)
    if not isinstance(value, (str, list)):
        raise InvalidJobRequestError(f'field {quoted(key)} must be a list of names or comma-separated text', key)
    names = tuple(parse_names(value))
    for name in names:
        if not (_LITERAL if key in LITERAL_FIELDS else _NAME).fullmatch(name):
            raise InvalidJobRequestError(f'{key}: {quoted(name)} is not a proposition name', name)
    return names


def custom_ltl_field(body: dict) -> dict[str, list[str]] | None:
    """The request's custom LTL: a JSON object mapping specification sections to lists of
    formulas (their syntax is the compiler's to check); None when absent or empty."""
    value = body.get('custom_ltl')
    if value is None:
        return None
    if not isinstance(value, dict):
        raise InvalidJobRequestError('field "custom_ltl" must map specification sections to lists of formulas',
                                     'custom_ltl')
    for section, formulas in value.items():
        if section not in SECTIONS:
            raise InvalidJobRequestError(f'custom_ltl: unknown section {quoted(section)} (sections: '
                                         f'{", ".join(SECTIONS)})', section)
        if not isinstance(formulas, list) or not all(isinstance(f, str) for f in formulas):
            raise InvalidJobRequestError(f'custom_ltl: section {quoted(section)} must be a list of formulas', section)
    return {section: list(formulas) for section, formulas in value.items() if formulas} or None


# --- jobs ---------------------------------------------------------------------------------

@dataclass(frozen=True)
class ProgressNote:
    """One status of a running job, as the timeline shows it."""

    seconds: float    # since the job was created
    status: str
    progress: float   # 0..1, as the pipeline's feedback says


@dataclass(frozen=True)
class StageTiming:
    """How long one pipeline stage took."""

    stage: str
    seconds: float


@dataclass(frozen=True)
class ResultSummary:
    """Realizability and sizes of a finished job, as the result page shows them."""

    succeeded: bool
    realizable: bool | None    # None: synthesis did not run (compile only, or an earlier failure)
    input_propositions: int
    output_propositions: int
    formulas: int
    automaton_states: int
    state_machine_states: int
    state_instantiations: int
    concurrency_containers: int
    seconds: float

    @classmethod
    def of(cls, outcome: JobOutcome) -> 'ResultSummary':
        sections = outcome.ltl_specification
        automaton_states = len(outcome.automaton_states)
        entries = list(outcome.machine.walk()) if outcome.machine else []
        if outcome.error_name == ErrorCode.SPEC_UNSYNTHESIZABLE:
            realizable = False
        elif automaton_states:
            realizable = True
        else:
            realizable = None
        return cls(
            succeeded=outcome.succeeded,
            realizable=realizable,
            input_propositions=len(sections.get('env_props', [])),
            output_propositions=len(sections.get('sys_props', [])),
            formulas=sum(len(lines) for name, lines in sections.items() if not name.endswith('_props')),
            automaton_states=automaton_states,
            state_machine_states=count_states(entries),
            state_instantiations=len(entries),
            concurrency_containers=sum(1 for s in entries if s.state_class == StateInstantiation.CLASS_CONCURRENCY),
            seconds=round(outcome.seconds, 4),
        )


@dataclass
class Job:
    """One synthesis request and everything that happened to it."""

    id: str
    request: JobRequest
    state: str = 'queued'              # queued -> running -> finished
    status: str = 'waiting to be sent'
    progress: float = 0.0
    timeline: list[ProgressNote] = field(default_factory=list)
    outcome: JobOutcome | None = None  # once finished
    cancel_requested: threading.Event = field(default_factory=threading.Event, repr=False)
    created: float = field(default_factory=time.monotonic, repr=False)
    revision: int = 0                  # bumped on every change, so streams send only news
    finished_after: float = 0.0        # seconds from creation to the result

    @property
    def finished(self) -> bool:
        return self.state == 'finished'

    @property
    def finished_outcome(self) -> JobOutcome:
        """The outcome of a job that has finished (every finished job has one)."""
        assert self.outcome is not None, f'job {self.id} has not finished'
        return self.outcome

    def seconds_since_created(self) -> float:
        return round(time.monotonic() - self.created, 4)

    def to_dict(self) -> dict:
        """The job's JSON (the routes' answer and event data)."""
        outcome = self.outcome
        artifacts = available_artifacts(outcome) if outcome else []
        return {'id': self.id, 'revision': self.revision, 'state': self.state, 'status': self.status,
                'progress': round(self.progress, 4), 'request': asdict(self.request),
                'cancel_requested': self.cancel_requested.is_set(),
                'timeline': [asdict(note) for note in self.timeline],
                'outcome': outcome.to_dict() if outcome else None,
                'summary': asdict(ResultSummary.of(outcome)) if outcome else None,
                'stages': [asdict(stage) for stage in stage_timings(self.timeline, self.finished_after)]
                if outcome else [],
                'artifacts': artifacts, 'download_labels': download_labels(artifacts),
                'made_in_page': made_in_page(artifacts)}


def stage_timings(timeline: list[ProgressNote], total_seconds: float) -> list[StageTiming]:
    """How long each pipeline stage took, from the feedback timeline.

    A stage starts with a status whose first word is a gerund ("Compiling ...",
    "Synthesizing ...") and lasts until the next status (or the end of the job).
    """
    stages = []
    for index, note in enumerate(timeline):
        first_word = note.status.split(' ', 1)[0]
        if not first_word.endswith('ing'):
            continue
        end = timeline[index + 1].seconds if index + 1 < len(timeline) else total_seconds
        stages.append(StageTiming(note.status, round(max(0.0, end - note.seconds), 4)))
    return stages


def update_record(record, lock: threading.Lock, **changes) -> None:
    """Change a Job or Simulation under ``lock`` and bump its revision (what the event streams watch)."""
    with lock:
        for name, value in changes.items():
            setattr(record, name, value)
        record.revision += 1
