"""Verified repairs: from "this task cannot be done" to concrete changes that make it possible.

When a task is refused (a pre-check error such as INVALID_GOALS, or an unrealizable
specification), ``propose_repairs`` tries small changes and offers only those it has
re-synthesized and found realizable. A proposal changes one of three things:

the request      goals reordered, in any order, one dropped, a prerequisite goal added,
                 another initial control mode or initial condition, other state-machine outcomes;
the custom LTL   a custom guarantee dropped (the weakest weakening), or an environment
                 assumption added, mined from the environment's winning play: a fairness or
                 stability assumption on an input the environment keeps constant while it wins
                 (counter-strategy-guided assumption mining, after Alur, Moarref and Topcu);
the robot        a missing control-mode transition, a precondition removed, a postcondition a
                 capability may add: a patch of the robot's file, marked as a change of the
                 robot and never applied by us.

Candidates are ranked by how little they change: proposals that keep every goal come first,
request and custom-LTL changes before changes of the robot, then by the number of edits. They
are verified in that order until enough proposals are found or the time budget is spent, so
the first proposal arrives after the few cheapest candidates (a synthesis of an ATLAS task
takes 5-30 ms).

A proposal is exact: its ``request``, ``custom_ltl`` or ``config_patch`` is the whole changed
item, re-run by the same compiler and synthesizer a user would run.
"""

from __future__ import annotations

import contextlib
import copy
import itertools
import re
import time
from dataclasses import dataclass, field, replace
from typing import Any, Callable, Iterable, Iterator, Mapping, NamedTuple, Sequence

import yaml

from respec.vocabulary.errors import CodedError, ErrorCode
from respec.vocabulary.naming import DEFAULT_SM_OUTCOMES, FAILED, activation, memory, parse_names, remembered
from respec.robot import RobotSystem, for_description
from respec.robot.abstraction import RobotAbstraction
from respec.robot.cnu import CapabilitySystem
from respec.robot.state_library import StateClass
from respec.robot.system import robot_system_from_files
from ltl_synthesizer.errors import SynthesisCancelledError
from ltl_synthesizer.interrupt import Limits

from ltl_specification.compiler import compile_task

GUARANTEE_SECTIONS = ('sys_init', 'sys_trans', 'sys_liveness')
UNREALIZABLE = str(ErrorCode.SPEC_UNSYNTHESIZABLE)
# Refusals a change of the task can fix; any other (a malformed file, an unknown name) is
# reported as it is: the user fixes that first.
REPAIRABLE = frozenset({UNREALIZABLE, str(ErrorCode.INVALID_GOALS), str(ErrorCode.ABSTRACTION_CONFIG_INVALID)})
DEFAULT_TIME_BUDGET = 10.0          # seconds for the whole search
DEFAULT_MAX_PROPOSALS = 5
MAX_DROPPED_PAIRS_FROM = 8          # custom guarantees: pairs of them dropped up to this many
MAX_PERMUTED_GOALS = 5              # all orders up to this many goals, adjacent swaps beyond
MAX_PLAY_STEPS = 12                 # of the environment play that guides assumption mining
DIAGNOSIS_SHARE = 0.2               # of the time budget, at most, for the problem's diagnosis
MAX_PER_KIND = 2                    # proposals of one kind, so that different fixes are offered
CustomLTL = Mapping[str, Sequence[str]]   # section -> formulas or names, as compile_task takes it
StateLibrary = Mapping[str, StateClass]   # the capability compiler's state classes, by name

# Kinds of proposals, by what they change.
REORDER, UNORDERED, ADD_GOAL, INITIAL, OUTCOMES, DROP_GOAL = (
    'reorder_goals', 'goals_in_any_order', 'add_prerequisite_goal', 'initial_condition', 'sm_outcomes',
    'drop_goal')
WEAKEN_GUARANTEE, ADD_ASSUMPTION = 'weaken_guarantee', 'add_assumption'
ADD_TRANSITION, REMOVE_PRECONDITION, ADD_POSTCONDITION = (
    'add_transition', 'remove_precondition', 'add_postcondition')
ROBOT_KINDS = (ADD_TRANSITION, REMOVE_PRECONDITION, ADD_POSTCONDITION)


@dataclass(frozen=True)
class TaskRequest:
    """What a user asks for, as ``behavior-synthesis compile`` and the action take it."""

    system: str
    initial_conditions: tuple[str, ...] = ()
    goals: tuple[str, ...] = ()
    sm_outcomes: tuple[str, ...] = DEFAULT_SM_OUTCOMES
    unordered: bool = False

    def to_dict(self) -> dict[str, Any]:
        return {'system': self.system, 'initial_conditions': list(self.initial_conditions),
                'goals': list(self.goals), 'sm_outcomes': list(self.sm_outcomes), 'unordered': self.unordered}

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> TaskRequest:
        return cls(str(data['system']), tuple(parse_names(data.get('initial_conditions', ()))),
                   tuple(parse_names(data.get('goals', ()))),
                   tuple(parse_names(data.get('sm_outcomes', ()))) or DEFAULT_SM_OUTCOMES,
                   bool(data.get('unordered', False)))


@dataclass(frozen=True)
class ConfigPatch:
    """One change of a robot's file: the value at ``path`` (keys from the file's top) becomes
    ``value`` (``previous`` before; None when the key is new)."""

    file: str
    path: tuple[str, ...]
    value: object
    previous: object = None

    def to_dict(self) -> dict[str, Any]:
        return {'file': self.file, 'path': list(self.path), 'value': self.value, 'previous': self.previous,
                'changes_robot': True}


@dataclass
class Proposal:
    """A change that makes the task possible; ``verified`` once re-synthesized as realizable."""

    kind: str
    summary: str                         # one sentence
    edits: int                           # how much it changes (fewer is better)
    keeps_goals: bool
    request: TaskRequest | None = None   # the whole changed request, when it changes
    custom_ltl: dict[str, list[str]] | None = None   # the whole changed mapping, when it changes
    config_patch: ConfigPatch | None = None
    verified: bool = False
    synthesis_seconds: float = 0.0

    @property
    def changes_robot(self) -> bool:
        return self.config_patch is not None

    def rank(self) -> tuple[bool, bool, int]:
        return (not self.keeps_goals, self.changes_robot, self.edits)

    def to_dict(self) -> dict[str, Any]:
        data = {'kind': self.kind, 'summary': self.summary, 'keeps_goals': self.keeps_goals,
                'changes_robot': self.changes_robot}
        if self.request is not None:
            data['request'] = self.request.to_dict()
        if self.custom_ltl is not None:
            data['custom_ltl'] = self.custom_ltl
        if self.config_patch is not None:
            data['config_patch'] = self.config_patch.to_dict()
        data['verified'] = self.verified
        data['synthesis_seconds'] = round(self.synthesis_seconds, 4)
        return data


@dataclass
class Repairs:
    """The outcome of a search: the task's problem as refused, and the verified proposals."""

    request: TaskRequest
    realizable: bool                     # the task can be done as asked: nothing to repair
    problem: str = ''                    # the refusal: error code and sentence
    proposals: list[Proposal] = field(default_factory=list)
    tried: int = 0
    seconds: float = 0.0
    first_proposal_seconds: float | None = None
    note: str = ''                       # e.g. that the time budget ran out

    def to_dict(self) -> dict[str, Any]:
        return {'request': self.request.to_dict(), 'realizable': self.realizable, 'problem': self.problem,
                'proposals': [p.to_dict() for p in self.proposals], 'tried': self.tried,
                'seconds': round(self.seconds, 3),
                'first_proposal_seconds': None if self.first_proposal_seconds is None
                else round(self.first_proposal_seconds, 3), 'note': self.note}

    def message_lines(self, count: int = 3) -> list[str]:
        """The best proposals as lines for a result's ``messages[]`` or a banner."""
        return [f'Suggested fix {number}: {p.summary}' for number, p in enumerate(self.proposals[:count], start=1)]


# --- checking a candidate --------------------------------------------------------------------

@dataclass(frozen=True)
class Attempt:
    """One verification: the verdict, or the refusal that stopped it before synthesis."""

    realizable: bool
    seconds: float
    problem: str = ''
    code: str = ''
    item: str = ''


def attempt(system: RobotSystem, request: TaskRequest, custom_ltl: CustomLTL | None,
            deadline: float | None = None, honest_environment: bool = False,
            state_library: StateLibrary | None = None) -> Attempt:
    """Compile and synthesize ``request`` on ``system``: realizable or the reason it is not.

    A specification realizable only vacuously (its initial conditions contradict each other)
    does not count: it has no strategy to run. With ``honest_environment`` (for added
    assumptions) neither does one whose controller could win by forcing the environment to
    break its assumptions (not well-separated, ``ltl_synthesizer.well_separation``). A refusal
    before synthesis is not diagnosed here (its sentence suffices to reject a candidate).
    """
    from ltl_synthesizer.synthesizer import solve   # the synthesizer loads only when a repair runs
    from ltl_synthesizer.well_separation import is_well_separated

    start = time.perf_counter()
    try:
        spec = compile_task(system, list(request.initial_conditions), list(request.goals),
                            sm_outcomes=request.sm_outcomes, strict_order=not request.unordered,
                            custom_ltl=custom_ltl, state_library=state_library, explain_refusal=False)
        solved = solve(spec, limits=Limits(deadline=deadline))
        if solved.realizable and not solved.warnings and honest_environment and not is_well_separated(solved.game):
            return Attempt(False, time.perf_counter() - start,
                           'the controller could win by forcing the environment to break its assumptions')
    except CodedError as error:
        return Attempt(False, time.perf_counter() - start, f'{error.code}: {error}', str(error.code),
                       str(error.item or ''))
    if solved.realizable and solved.warnings:
        return Attempt(False, time.perf_counter() - start, solved.warnings[0])
    if solved.realizable:
        return Attempt(True, time.perf_counter() - start)
    return Attempt(False, time.perf_counter() - start, f'{UNREALIZABLE}: the specification is unrealizable',
                   UNREALIZABLE)


# --- the search --------------------------------------------------------------------------------

def propose_repairs(system: RobotSystem, request: TaskRequest, custom_ltl: CustomLTL | None = None,
                    time_budget: float = DEFAULT_TIME_BUDGET,
                    max_proposals: int = DEFAULT_MAX_PROPOSALS,
                    on_proposal: Callable[[Proposal], None] | None = None,
                    state_library: StateLibrary | None = None) -> Repairs:
    """Verified proposals that make ``request`` (with ``custom_ltl``) possible on ``system``.

    Candidates are verified cheapest first until ``max_proposals`` are found or four fifths of
    ``time_budget`` are spent (the problem's diagnosis gets the rest: the budget bounds the
    whole); ``on_proposal`` is called with each one as it is verified (to show progress). ``state_library`` is the
    capability compiler's (default: the workspace's FlexBE states).
    """
    start = time.monotonic()
    # The search leaves the diagnosis of the problem its share: the budget bounds the whole.
    deadline = start + time_budget * (1 - DIAGNOSIS_SHARE)
    request = replace(request, system=system.name)
    original = attempt(system, request, custom_ltl, deadline, state_library=state_library)
    repairs = Repairs(request, original.realizable, original.problem)
    if original.realizable:
        return _finish(repairs, start)
    if original.code not in REPAIRABLE and not _names_a_goal_memory(system, original):
        repairs.note = 'Nothing to propose: this refusal is not about what the task asks; correct it first.'
        return _finish(repairs, start)
    seen = set()
    candidates = sorted(_candidates(system, request, custom_ltl), key=Proposal.rank)
    for candidate in candidates:
        if time.monotonic() >= deadline:
            repairs.note = (f'The time budget of {time_budget:g} s ran out after {repairs.tried} of '
                            f'{len(candidates)} candidate changes.')
            break
        identity = _identity(candidate, request, custom_ltl)
        if identity in seen or sum(p.kind == candidate.kind for p in repairs.proposals) >= MAX_PER_KIND:
            continue
        seen.add(identity)
        repairs.tried += 1
        try:
            verdict = attempt(_system_for(system, candidate), candidate.request or request,
                              custom_ltl if candidate.custom_ltl is None else candidate.custom_ltl, deadline,
                              honest_environment=candidate.kind == ADD_ASSUMPTION, state_library=state_library)
        except SynthesisCancelledError:
            continue
        if not verdict.realizable:
            continue
        candidate.verified, candidate.synthesis_seconds = True, verdict.seconds
        repairs.proposals.append(candidate)
        if repairs.first_proposal_seconds is None:
            repairs.first_proposal_seconds = time.monotonic() - start
        if on_proposal:
            on_proposal(candidate)
        if len(repairs.proposals) >= max_proposals:
            break
    if original.code == UNREALIZABLE:   # after the search: proposals first, the core may take long
        diagnosis_deadline = start + time_budget
        repairs.problem = f'{UNREALIZABLE}: ' + _diagnosed_sentence(system, request, custom_ltl, state_library,
                                                                    diagnosis_deadline)
    return _finish(repairs, start)


def _names_a_goal_memory(system: RobotSystem, refusal: Attempt) -> bool:
    """Custom LTL that names the memory of an item that is not a goal (``stand_m``): adding
    that goal is a repair."""
    return refusal.code == str(ErrorCode.UNKNOWN_PROPOSITION) and _memory_owner(system, refusal.item) is not None


def _memory_owner(system: RobotSystem, name: str) -> str | None:
    """The item ``name`` is the goal memory of (eq. (20)): a mode robot's modes and actions have one."""
    return _robot_repairs(system).memory_owner(system, name) if remembered(name) is not None else None


def _mode_memory_owner(system: RobotSystem, name: str) -> str | None:
    item = remembered(name)
    assert item is not None  # _memory_owner asks only about a memory's name
    return item if system.required_abstraction().kind_of(item) is not None else None


def _diagnosed_sentence(system: RobotSystem, request: TaskRequest, custom_ltl: CustomLTL | None,
                        state_library: StateLibrary | None,
                        deadline: float) -> str:
    """The diagnosis' leading sentence, as every channel tells the problem (its core search
    stops at ``deadline``: the proposals matter more here)."""
    from ltl_specification.diagnosis import diagnose

    spec = compile_task(system, list(request.initial_conditions), list(request.goals),
                        sm_outcomes=request.sm_outcomes, strict_order=not request.unordered,
                        custom_ltl=custom_ltl, state_library=state_library)
    diagnosis = diagnose(spec, limits=Limits(deadline=deadline))
    return diagnosis.sentence if diagnosis else 'the specification is unrealizable'


def _finish(repairs: Repairs, start: float) -> Repairs:
    repairs.seconds = time.monotonic() - start
    return repairs


def _identity(candidate: Proposal, request: TaskRequest, custom_ltl: CustomLTL | None) -> str:
    """Two candidates that change the task the same way are one proposal."""
    return yaml.safe_dump([(candidate.request or request).to_dict(),
                           custom_ltl if candidate.custom_ltl is None else candidate.custom_ltl,
                           candidate.config_patch.to_dict() if candidate.config_patch else None], sort_keys=True)


def _system_for(system: RobotSystem, candidate: Proposal) -> RobotSystem:
    """``system`` with the candidate's patch applied to its file's text (nothing is written)."""
    patch = candidate.config_patch
    if patch is None:
        return system
    relative = _relative_file(system, patch.file)
    files = {**system.files, relative: patched_text(system.files[relative], patch)}
    return robot_system_from_files(system.name, files, str(system.path))


def patched_text(text: str, patch: ConfigPatch) -> str:
    """A YAML file's ``text`` with ``patch`` applied (comments are not kept)."""
    document = yaml.safe_load(text)
    target = document
    for key in patch.path[:-1]:
        target = target.setdefault(key, {})
    target[patch.path[-1]] = copy.deepcopy(patch.value)
    return yaml.safe_dump(document, sort_keys=False)


def _relative_file(system: RobotSystem, shown: str) -> str:
    return next(relative for relative in system.files if _shown_file(system, relative) == shown)


def _shown_file(system: RobotSystem, relative: str) -> str:
    """A file of the system as users know it (``config/atlas.yaml``, ``config/rover/spec.yaml``)."""
    if relative.startswith('/'):
        return relative
    return f'{system.path.parent.name}/{relative}'


# --- candidates --------------------------------------------------------------------------------

def _candidates(system: RobotSystem, request: TaskRequest, custom_ltl: CustomLTL | None) -> Iterator[Proposal]:
    robot = _robot_repairs(system)
    yield from _goal_order_candidates(system, request)
    yield from robot.prerequisites(system, request, custom_ltl)
    yield from robot.starts(system, request)
    yield from _outcome_candidates(request)
    yield from _drop_goal_candidates(request)
    yield from _custom_ltl_candidates(system, request, custom_ltl)
    yield from robot.changes(system, request)


def _goal_order_candidates(system: RobotSystem, request: TaskRequest) -> Iterator[Proposal]:
    """Goals in another order (fewest swapped pairs first), or in any order (eq. (17) for (20))."""
    goals = request.goals
    if not system.orders_goals or len(goals) < 2 or request.unordered:
        return
    yield Proposal(UNORDERED, 'Let the goals be achieved in any order (--unordered).', 1, True,
                   replace(request, unordered=True))
    orders: Iterable[tuple[str, ...]]
    if len(goals) <= MAX_PERMUTED_GOALS:
        orders = itertools.permutations(goals)
    else:
        orders = (goals[:i] + (goals[i + 1], goals[i]) + goals[i + 2:] for i in range(len(goals) - 1))
    for order in orders:
        swaps = _swapped_pairs(goals, order)
        if swaps:
            yield Proposal(REORDER, f'Achieve the goals in the order {", ".join(order)}.', swaps, True,
                           replace(request, goals=tuple(order)))


def _swapped_pairs(original: Sequence[str], order: Sequence[str]) -> int:
    position = {goal: index for index, goal in enumerate(original)}
    return sum(1 for a, b in itertools.combinations(order, 2) if position[a] > position[b])


def _prerequisite_candidates(system: RobotSystem, request: TaskRequest,
                             custom_ltl: CustomLTL | None) -> Iterator[Proposal]:
    """An item added as a goal before a goal: one whose goal memory (``<item>_m``, eq. (20))
    the custom LTL uses first, then a control mode or a precondition of a goal, which with goals
    in order takes the robot where the next goal can be reached from."""
    abstraction = system.required_abstraction()
    used = _custom_names(custom_ltl)
    remembered_items = [i for i in abstraction.items() if memory(i) in used and i not in request.goals]
    preconditions = {p for g in request.goals for p in abstraction.actions.get(g, ())}
    extra = remembered_items + [i for i in abstraction.items() if i not in request.goals
                                and i not in remembered_items and (abstraction.is_mode(i) or i in preconditions)]
    for item in extra:
        for position in range(len(request.goals) + (item in remembered_items)):
            goals = request.goals[:position] + (item,) + request.goals[position:]
            where = (f'before goal {position + 1} ({request.goals[position]})' if position < len(request.goals)
                     else 'after the last goal')
            why = f' (the custom LTL uses {memory(item)}, its goal memory)' if item in remembered_items else ''
            yield Proposal(ADD_GOAL, f'Add the goal {item} {where}{why}.', 1 if item in remembered_items else 2, True,
                           replace(request, goals=goals))


def _custom_names(custom_ltl: CustomLTL | None) -> set[str]:
    """Every word of the custom formulas (names the parser would read as propositions)."""
    return {word for section, entries in (custom_ltl or {}).items() if section not in ('env_props', 'sys_props')
            for text in entries or () for word in re.findall(r'[A-Za-z_][A-Za-z0-9_]*', str(text))}


def _capability_start_candidates(system: RobotSystem, request: TaskRequest) -> Iterator[Proposal]:
    """Start elsewhere: one initial condition more or less (a capability robot's memories)."""
    capabilities = system.required_capabilities()
    for condition in request.initial_conditions:
        rest = tuple(c for c in request.initial_conditions if c != condition)
        yield Proposal(INITIAL, f'Drop the initial condition {condition}.', 2, True,
                       replace(request, initial_conditions=rest))
    for name in capabilities.memory:
        if name not in request.initial_conditions and memory(name) not in request.initial_conditions:
            yield Proposal(INITIAL, f'Start with {name} already true (initial condition {name}).', 2, True,
                           replace(request, initial_conditions=request.initial_conditions + (name,)))


def _mode_start_candidates(system: RobotSystem, request: TaskRequest) -> Iterator[Proposal]:
    """Start elsewhere: another initial control mode."""
    abstraction = system.required_abstraction()
    modes = [c for c in request.initial_conditions if abstraction.is_mode(c)]
    others = tuple(c for c in request.initial_conditions if not abstraction.is_mode(c))
    current = modes[0] if modes else abstraction.initial_mode
    for mode in abstraction.control_modes:
        if mode != current:
            yield Proposal(INITIAL, f'Start the robot in {mode} instead of {current}.', 2, True,
                           replace(request, initial_conditions=(mode,) + others))


def _outcome_candidates(request: TaskRequest) -> Iterator[Proposal]:
    """Retry failures instead of stopping on them, or the other way round (eq. (18b)/(18c))."""
    if FAILED in request.sm_outcomes:
        outcomes = tuple(o for o in request.sm_outcomes if o != FAILED)
        yield Proposal(OUTCOMES, f'Retry failed actions instead of ending in {FAILED} '
                       f'(state-machine outcomes {", ".join(outcomes)}).', 2, True,
                       replace(request, sm_outcomes=outcomes))
    else:
        outcomes = request.sm_outcomes + (FAILED,)
        yield Proposal(OUTCOMES, f'End in {FAILED} when an action fails (state-machine outcomes '
                       f'{", ".join(outcomes)}).', 2, True, replace(request, sm_outcomes=outcomes))


def _drop_goal_candidates(request: TaskRequest) -> Iterator[Proposal]:
    if len(request.goals) < 2:
        return
    for goal in request.goals:
        goals = tuple(g for g in request.goals if g != goal)
        yield Proposal(DROP_GOAL, f'Drop the goal {goal}.', 1, False, replace(request, goals=goals))


# --- custom LTL ------------------------------------------------------------------------------------

def _custom_ltl_candidates(system: RobotSystem, request: TaskRequest,
                           custom_ltl: CustomLTL | None) -> Iterator[Proposal]:
    """Weaken a custom guarantee (drop it), or assume more of the environment (mined)."""
    if not custom_ltl:
        return
    for section in GUARANTEE_SECTIONS:
        for index, text in enumerate(custom_ltl.get(section) or ()):
            weakened = _with_entries(custom_ltl, section, [t for i, t in enumerate(custom_ltl[section]) if i != index])
            yield Proposal(WEAKEN_GUARANTEE, f'Drop the custom guarantee {section}[{index}] {text!r}.', 2, True,
                           custom_ltl=weakened)
    guarantees = [(section, index) for section in GUARANTEE_SECTIONS
                  for index in range(len(custom_ltl.get(section) or ()))]
    for pair in itertools.combinations(guarantees, 2) if len(guarantees) <= MAX_DROPPED_PAIRS_FROM else ():
        weakened = {key: list(value) for key, value in custom_ltl.items()}
        for section, index in sorted(pair, reverse=True):
            del weakened[section][index]
        weakened = {key: value for key, value in weakened.items() if value}
        names = ' and '.join(f'{section}[{index}] {custom_ltl[section][index]!r}' for section, index in pair)
        yield Proposal(WEAKEN_GUARANTEE, f'Drop the custom guarantees {names}.', 4, True, custom_ltl=weakened)
    for section, text, reason in mined_assumptions(system, request, custom_ltl):
        mined = _with_entries(custom_ltl, section, [*(custom_ltl.get(section) or ()), text])
        yield Proposal(ADD_ASSUMPTION, f'Assume of the environment {section} {text!r} ({reason}).', 1, True,
                       custom_ltl=mined)


def _with_entries(custom_ltl: CustomLTL, section: str, entries: list[str]) -> dict[str, list[str]]:
    changed = {key: list(value) for key, value in custom_ltl.items()}
    if entries:
        changed[section] = entries
    else:
        changed.pop(section, None)
    return changed


def mined_assumptions(system: RobotSystem, request: TaskRequest, custom_ltl: CustomLTL) -> list[tuple[str, str, str]]:
    """Environment assumptions on the inputs the custom LTL adds, guided by the environment's
    winning play: an input that stays at one value through the end of the play is what the
    environment wins with, so assuming it changes infinitely often (fairness) or, once it has
    the good value, keeps it (stability) is tried first. Returns (section, formula, why)."""
    inputs = [str(name) for name in custom_ltl.get('env_props') or ()]
    # a capability robot's sensors are bound by its capabilities instead (_sensor_candidates)
    inputs += [s for s in _robot_repairs(system).assumed_sensors(system) if s not in inputs]
    if not inputs:
        return []
    held = _held_inputs(system, request, custom_ltl, inputs)
    ordered = [name for name in inputs if name in held] + [name for name in inputs if name not in held]
    mined = []
    for name in ordered:
        stuck = held.get(name)
        if stuck is not None:
            good = f'!{name}' if stuck else name
            why = f'the environment wins by keeping {name} {"true" if stuck else "false"}'
            mined.append(('env_liveness', good, why))
            mined.append(('env_trans', f'{good} -> next({good})', why))
        else:
            for good in (name, f'!{name}'):
                mined.append(('env_liveness', good, f'{good} holds infinitely often'))
    return mined


def _held_inputs(system: RobotSystem, request: TaskRequest, custom_ltl: CustomLTL | None, inputs: list[str]
                 ) -> dict[str, bool]:
    """The inputs the environment holds constant in the second half of its winning play."""
    from ltl_synthesizer.unrealizable_core import environment_play

    try:
        spec = compile_task(system, list(request.initial_conditions), list(request.goals),
                            sm_outcomes=request.sm_outcomes, strict_order=not request.unordered,
                            custom_ltl=custom_ltl, explain_refusal=False)
        steps = environment_play(spec, length=MAX_PLAY_STEPS)
    except CodedError:
        return {}
    tail = steps[len(steps) // 2:]
    held = {}
    for name in inputs:
        values = {step.get(name) for step in tail}
        if len(values) == 1 and None not in values:
            held[name] = bool(values.pop())
    return held


# --- the robot ---------------------------------------------------------------------------------------

def _capability_robot_candidates(system: RobotSystem, request: TaskRequest) -> Iterator[Proposal]:
    yield from _sensor_candidates(system)
    yield from _capability_candidates(system, request)


def _abstraction_candidates(system: RobotSystem, request: TaskRequest) -> Iterator[Proposal]:
    """A missing mode change into a mode a goal needs, or a goal's precondition removed."""
    from ltl_specification.reachability import modes_needed_by

    abstraction = system.required_abstraction()
    file = system.config_file
    needed = list(dict.fromkeys(m for g in request.goals for m in modes_needed_by(abstraction, g)))
    for target in needed:
        for mode, successors in abstraction.control_modes.items():
            if mode == target or target in successors:
                continue
            patch = ConfigPatch(file, ('abstraction', 'control_modes', mode), [*successors, target], list(successors))
            yield Proposal(ADD_TRANSITION, f'Change the robot: add the control-mode transition {mode} -> {target} '
                           f'(abstraction.control_modes.{mode} in {file}).', 1, True, config_patch=patch)
    for goal in request.goals:
        preconditions = abstraction.actions.get(goal, ())
        for precondition in preconditions:
            remaining = [p for p in preconditions if p != precondition]
            patch = ConfigPatch(file, ('abstraction', 'actions', goal), remaining, list(preconditions))
            yield Proposal(REMOVE_PRECONDITION, f'Change the robot: {goal} no longer needs {precondition} '
                           f'(abstraction.actions.{goal} in {file}).', 2, True, config_patch=patch)


def _capability_candidates(system: RobotSystem, request: TaskRequest) -> Iterator[Proposal]:
    """A goal's memory set by a capability's successful outcome, or a precondition removed."""
    capabilities = system.required_capabilities()
    if capabilities.full_spec:
        return
    relative = _capability_file(system)
    if relative is None:
        return
    file = _shown_file(system, relative)
    entries = (yaml.safe_load(system.files[relative]) or {}).get('capabilities') or {}
    entries = {name: entry for name, entry in entries.items() if isinstance(entry, dict)}
    success = capabilities.transition_outcomes[0] if capabilities.transition_outcomes else 'completed'
    set_somewhere = {term.name for capability in capabilities.capabilities.values()
                     for terms in capability.postconditions.values() for term in terms if not term.negated}
    for goal in request.goals:
        if goal in set_somewhere or not goal.isidentifier():
            continue
        # The capability of the goal's name first: CNU's convention for what achieves it.
        for name, entry in sorted(entries.items(), key=lambda item: item[0] != goal):
            path, before = _success_postconditions(entry, name, success)
            patch = ConfigPatch(file, path, [*before, goal], before or None)
            yield Proposal(ADD_POSTCONDITION, f'Change the robot: when {name} is {success}, {goal} holds '
                           f'(capabilities.{".".join(path[1:])} in {file}).', 1, True, config_patch=patch)
    for name, entry in entries.items():
        preconditions = entry.get('preconditions')
        for precondition in preconditions if isinstance(preconditions, list) else ():
            remaining = [p for p in preconditions if p != precondition]
            patch = ConfigPatch(file, ('capabilities', name, 'preconditions'), remaining, preconditions)
            yield Proposal(REMOVE_PRECONDITION, f'Change the robot: {name} no longer needs {precondition!r} '
                           f'(capabilities.{name}.preconditions in {file}).', 2, True, config_patch=patch)


def unreported_spec_inputs(capabilities: CapabilitySystem) -> list[str]:
    """The spec file's INPUTs that none of its environment formulas mentions: sensors nothing
    reports (``ltl_specification.diagnosis.unreported_sensors`` names them in a diagnosis)."""
    environment = ' '.join(text for section, text in capabilities.spec_formulas if section.startswith('env_'))
    environment += ' ' + ' '.join(capabilities.spec_initial)
    mentioned = set(re.findall(r'[A-Za-z_][A-Za-z0-9_]*', environment))
    return [name for name in capabilities.spec_inputs if name not in mentioned]


def _sensor_candidates(system: RobotSystem) -> Iterator[Proposal]:
    """For a sensor nothing reports: an outcome pair of a capability whose outcomes report
    nothing yet, bound to it (the missing binding), or the assumption that it holds infinitely
    often; both are environment assumptions, so both are checked well-separated."""
    from respec.robot.cnu import SPEC_KEY

    capabilities = system.required_capabilities()
    relative = system.sections.get(SPEC_KEY)
    if capabilities.full_spec or not isinstance(relative, str) or relative not in system.files:
        return
    sensors = unreported_spec_inputs(capabilities)
    if not sensors:
        return
    file = _shown_file(system, relative)
    specs = (yaml.safe_load(system.files[relative]) or {}).get('specs') or {}
    environment = ' '.join(text for section, text in capabilities.spec_formulas if section.startswith('env_'))
    for sensor in sensors:
        for name, pair in _unbound_outcome_pairs(capabilities, environment):
            a, b = (capabilities.outcome_proposition(name, outcome) for outcome in pair)
            binding = [f"{a}' <-> ({activation(name)} & {sensor}')", f"{b}' <-> ({activation(name)} & !{sensor}')"]
            before = list(specs.get('ENV_TRANS') or [])
            patch = ConfigPatch(file, ('specs', 'ENV_TRANS'), [*before, *binding], before or None)
            yield Proposal(ADD_ASSUMPTION, f'Change the robot: {name} reports the sensor {sensor} ({pair[0]} when it '
                           f'holds, {pair[1]} when not; specs.ENV_TRANS in {file}).', 2, True, config_patch=patch)
        liveness = [*(specs.get('ENV_LIVENESS') or []), sensor]
        patch = ConfigPatch(file, ('specs', 'ENV_LIVENESS'), liveness, specs.get('ENV_LIVENESS'))
        yield Proposal(ADD_ASSUMPTION, f'Assume the sensor {sensor}, which nothing reports, holds infinitely often '
                       f'(specs.ENV_LIVENESS in {file}).', 1, True, config_patch=patch)
        # A robot that runs one capability at a time cannot wait for a moment: once it holds, it stays.
        stable = {**specs, 'ENV_TRANS': [*(specs.get('ENV_TRANS') or []), f"{sensor} -> {sensor}'"],
                  'ENV_LIVENESS': liveness}
        patch = ConfigPatch(file, ('specs',), stable, dict(specs))
        yield Proposal(ADD_ASSUMPTION, f'Assume the sensor {sensor}, which nothing reports, eventually holds and then '
                       f"stays so (specs.ENV_LIVENESS {sensor!r} and specs.ENV_TRANS \"{sensor} -> {sensor}'\" in "
                       f'{file}).', 2, True, config_patch=patch)


def _unbound_outcome_pairs(capabilities: CapabilitySystem, environment: str) -> Iterator[tuple[str, tuple[str, str]]]:
    """(capability, two of its transition outcomes) for capabilities whose outcomes no
    environment formula mentions yet, failures left out: what could report a sensor."""
    failure = capabilities.state_outcomes.get(FAILED)
    for name, capability in sorted(capabilities.capabilities.items()):
        outcomes = []
        for flexbe_outcome in capability.declared_outcomes:
            with contextlib.suppress(Exception):
                outcome = capabilities.transition_outcome(name, flexbe_outcome)
                if outcome != failure and outcome not in outcomes:
                    outcomes.append(outcome)
        if len(outcomes) < 2 or any(re.search(rf'\b{re.escape(capabilities.outcome_proposition(name, o))}\b',
                                              environment) for o in outcomes):
            continue
        yield name, (outcomes[0], outcomes[1])


def _success_postconditions(entry: dict[str, Any], name: str, success: str) -> tuple[tuple[str, ...], list[Any]]:
    """Where a capability's file entry lists what its success sets, and what it lists: CNU's
    files give either one list (the success's) or a mapping by transition outcome."""
    post = entry.get('postconditions')
    if isinstance(post, dict):
        return ('capabilities', name, 'postconditions', success), list(post.get(success) or [])
    return ('capabilities', name, 'postconditions'), list(post or [])


def _capability_file(system: RobotSystem) -> str | None:
    from respec.robot.cnu import CAPABILITIES_KEY

    relative = system.sections.get(CAPABILITIES_KEY)
    return relative if isinstance(relative, str) and relative in system.files else None


# --- what each robot format offers to repair ---------------------------------------------------------

class _RobotRepairs(NamedTuple):
    """The candidates a robot format adds, in their place among the others (``_candidates``)."""

    prerequisites: Callable[..., Iterator[Proposal]]   # (system, request, custom_ltl): goals added before goals
    starts: Callable[..., Iterator[Proposal]]          # (system, request): other initial conditions
    changes: Callable[..., Iterator[Proposal]]         # (system, request): changes to the robot's files
    assumed_sensors: Callable[[RobotSystem], Sequence[str]]   # inputs mined_assumptions may assume of
    memory_owner: Callable[[RobotSystem, str], str | None]    # the goal whose memory a name (``x_m``) is


def _nothing(*arguments: object) -> Iterator[Proposal]:
    del arguments
    yield from ()


_ROBOT_REPAIRS = {
    RobotAbstraction: _RobotRepairs(_prerequisite_candidates, _mode_start_candidates, _abstraction_candidates,
                                    lambda system: system.required_abstraction().sensors, _mode_memory_owner),
    # a capability robot's sensors are bound by its capabilities instead (_sensor_candidates)
    # (and its memories are its own propositions, no goal's)
    CapabilitySystem: _RobotRepairs(_nothing, _capability_start_candidates, _capability_robot_candidates,
                                    lambda system: (), lambda system, name: None),
}
# a file without a description: nothing of the robot to change
_NO_ROBOT_REPAIRS = _RobotRepairs(_nothing, _nothing, _nothing, lambda system: (), lambda system, name: None)


def _robot_repairs(system: RobotSystem) -> _RobotRepairs:
    return for_description(_ROBOT_REPAIRS, system, missing=_NO_ROBOT_REPAIRS)
