"""Reading behavior synthesis requests: goal strings and option checks (ROS-free)."""

from __future__ import annotations

import hashlib
import math
import re
from dataclasses import dataclass
from types import SimpleNamespace
from typing import Any


from respec.untrusted import BoundedYamlError, load_bounded_yaml
from respec.vocabulary.errors import CodedError, ErrorCode, quoted
from respec.vocabulary.naming import DEFAULT_SM_OUTCOMES, parse_names

OPTION_NAMES = ('ltl_compilation_only', 'ltl_synthesis_only', 'ltl_steps_only')


class InvalidRequestError(CodedError):
    """A request the server cannot run (contradictory or malformed options)."""

    code = ErrorCode.INVALID_REQUEST


def selected_option(options) -> str | None:
    """The one SynthesisOptions flag that is set, or None; several flags is an error."""
    chosen = [name for name in OPTION_NAMES if getattr(options, name)]
    if len(chosen) > 1:
        raise InvalidRequestError(f'synthesis options are mutually exclusive, got {" and ".join(chosen)}')
    return chosen[0] if chosen else None


# --- One request shape for both action interfaces ------------------------------------------
# BehaviorSynthesis (the original, which FlexBE WebUI 4.0.3 sends) and FlexBESynthesis (CNU's,
# which newer WebUI revisions send) are read into one SynthesisTask, so both run the same
# pipeline and return the same states for the same task.

# What the FlexBE WebUI sends as `system` unless configured otherwise: "the robot at hand".
SYSTEM_WIDE = 'system_wide'
# The system of requests naming none (the server's default_system, `serve --default-system`).
DEFAULT_SYSTEM = 'atlas'
# Byproduct file stems must satisfy the synthesizer's spec-name rule (<= 100 characters).
MAX_STEM_LENGTH = 100
_PLAIN_CHARACTER = re.compile(r'[A-Za-z0-9_]')
_HASHED_STEM_PREFIX = MAX_STEM_LENGTH - 13


@dataclass(frozen=True)
class SynthesisTask:
    """A behavior synthesis request, independent of the action type it arrived with."""

    system: str
    initial_conditions: list[str]
    goals: list[str]
    sm_outcomes: list[str]
    behavior_name: str = ''
    option: str | None = None
    timeout: float = 0.0              # seconds; 0 means the server's default
    unordered_goals: bool = False
    custom_ltl: Any = None            # the request's LTLSpecification, passed through untouched

    @property
    def byproduct_stem(self) -> str:
        return byproduct_file_stem(self.behavior_name) if self.behavior_name else ''


def resolve_system(system: str, default_system: str) -> str:
    """The system a request names; empty or the WebUI's ``system_wide`` mean ``default_system``."""
    name = (system or '').strip()
    return default_system if name in ('', SYSTEM_WIDE) else name


def behavior_name(name: str) -> str:
    """The behavior a request names: a FlexBE container path ``/Outer/Inner`` -> ``Outer/Inner``."""
    return '/'.join(segment for segment in (name or '').split('/') if segment)


def byproduct_file_stem(behavior: str) -> str:
    """A file stem for a behavior name that stays in its directory and never collides.

    Letters, digits and ``_`` stay, the path separator ``/`` becomes ``.``, every other
    character becomes ``-`` plus the hex of its UTF-8 bytes (``a.b`` -> ``a-2eb``). The mapping
    is injective: ``-`` only ever starts a two-digit escape, and ``.`` only stands for ``/``.
    Stems must start with a letter or digit; otherwise ``x-`` is put in front, which no
    other name produces (after ``x-`` comes ``-`` or ``_``, never a hex digit). Names too long
    for a file keep a readable prefix and get a hash of the whole name.
    """
    segments = [''.join(character if _PLAIN_CHARACTER.fullmatch(character)
                        else ''.join(f'-{byte:02x}' for byte in character.encode('utf-8'))
                        for character in segment)
                for segment in behavior_name(behavior).split('/')]
    stem = '.'.join(segments)
    if not stem[:1].isalnum():
        stem = 'x-' + stem
    if len(stem) > MAX_STEM_LENGTH:
        digest = hashlib.sha256(behavior.encode('utf-8')).hexdigest()[:12]
        stem = f'{stem[:_HASHED_STEM_PREFIX].rstrip(".")}_{digest}'
    return stem


#: Deepest nesting of mappings and lists accepted in a request's YAML.
MAX_YAML_DEPTH = 16


def load_request_yaml(text: str, item: str):
    """The value of a request's YAML field ``item``; an InvalidRequestError naming it if it is not
    valid YAML, uses aliases or nests deeper than MAX_YAML_DEPTH. The message quotes none of the text."""
    try:
        return load_bounded_yaml(text, MAX_YAML_DEPTH)
    except BoundedYamlError as error:
        raise InvalidRequestError(f'{item}: {error}', item) from None


def parse_synthesis_options(text: str) -> dict:
    """FlexBESynthesis ``synthesis_options`` (YAML) -> ``{'option', 'timeout', 'unordered_goals'}``.

    Empty text means the defaults. Accepted: one option name (``ltl_compilation_only``), or a
    mapping of option flags, ``timeout`` (seconds) and ``unordered_goals``. Anything else is an
    InvalidRequestError naming the bad item (quoting at most the start of a value).
    """
    options = load_request_yaml(text or '', 'synthesis_options')
    if options is None:
        options = {}
    if isinstance(options, str):
        options = {options: True}
    if not isinstance(options, dict):
        raise InvalidRequestError(f'synthesis_options must be a YAML mapping, got {quoted(options)}',
                             'synthesis_options')
    known = (*OPTION_NAMES, 'timeout', 'unordered_goals')
    for key, value in options.items():
        if key not in known:
            raise InvalidRequestError(f'unknown synthesis option {quoted(key)} (known: {", ".join(known)})',
                                 'synthesis_options')
        if key == 'timeout':
            if (isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value)
                    or value < 0):
                raise InvalidRequestError(f'synthesis option timeout must be a finite number >= 0, '
                                     f'got {quoted(value)}', 'timeout')
        elif not isinstance(value, bool):
            raise InvalidRequestError(f'synthesis option {key} must be true or false, got {quoted(value)}', key)
    flags = SimpleNamespace(**{name: bool(options.get(name, False)) for name in OPTION_NAMES})
    return {'option': selected_option(flags), 'timeout': float(options.get('timeout', 0.0)),
            'unordered_goals': bool(options.get('unordered_goals', False))}


def make_task(*, system: str, initial_conditions, goals, sm_outcomes, name: str,
              default_system: str, option: str | None = None, timeout: float = 0.0,
              unordered_goals: bool = False, custom_ltl: Any = None) -> SynthesisTask:
    """The task a request describes, with the conventions of both interfaces applied."""
    return SynthesisTask(
        system=resolve_system(system, default_system),
        initial_conditions=parse_names(initial_conditions), goals=parse_names(goals),
        sm_outcomes=list(sm_outcomes) or list(DEFAULT_SM_OUTCOMES),
        behavior_name=behavior_name(name), option=option, timeout=float(timeout or 0.0),
        unordered_goals=bool(unordered_goals), custom_ltl=custom_ltl)


def task_from_behavior_synthesis(goal, default_system: str) -> SynthesisTask:
    """A BehaviorSynthesis goal (the original interface, as FlexBE WebUI 4.0.3 fills it)."""
    request = goal.request
    return make_task(system=request.system, initial_conditions=request.initial_condition,
                     goals=request.goal, sm_outcomes=request.sm_outcomes, name=request.name,
                     default_system=default_system, option=selected_option(goal.synthesis_options),
                     timeout=request.timeout, unordered_goals=request.unordered_goals,
                     custom_ltl=request.ltl_specification)


def task_from_flexbe_synthesis(goal, default_system: str) -> SynthesisTask:
    """A FlexBESynthesis goal (CNU's interface); ``synthesis_options`` is YAML."""
    request = goal.request
    if request.specification_file_name:
        raise InvalidRequestError(f'specification_file_name {quoted(request.specification_file_name)}: this server '
                             'compiles specifications itself; leave it empty')
    options = parse_synthesis_options(goal.synthesis_options)
    if options['option'] == 'ltl_synthesis_only':
        raise InvalidRequestError('synthesis option ltl_synthesis_only needs a complete specification, '
                             'which FlexBESynthesis goals cannot carry; send it with BehaviorSynthesis')
    return make_task(system=request.system_name, initial_conditions=list(request.initial_conditions),
                     goals=list(request.goals), sm_outcomes=request.sm_outcomes, name=request.spec_name,
                     default_system=default_system, option=options['option'],
                     timeout=request.synthesis_timeout_s or options['timeout'],
                     unordered_goals=options['unordered_goals'])
