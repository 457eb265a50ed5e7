"""Execution traces and their check against the synthesized GR(1) specification (ROS-free).

A trace is one executed run (one TraceStep per top-level state); check_trace walks its
positions against the specification's safety formulas and the goal order. The trace's JSON
shape, how environment valuations are read and why the check is exact: docs/simulation.md,
"How a run is checked".
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field

from respec.vocabulary.errors import CodedError, ErrorCode
from respec.ltl import Formula, Next, mentions_next, partial_evaluate, to_infix
from respec.vocabulary.naming import (COMPLETED, DEFAULT_SM_OUTCOMES, FINISHED, is_activation, outcome_proposition,
                                      remembered)
from respec.spec import GR1Specification

# Each SM outcome is the system proposition of the same name.
DEFAULT_SM_OUTCOME_PROPOSITIONS = {outcome: outcome for outcome in DEFAULT_SM_OUTCOMES}


class TraceError(CodedError):
    """A trace that cannot be checked (malformed); ``item`` names the offending entry."""

    code = ErrorCode.INVALID_REQUEST


# --- traces -------------------------------------------------------------------------------

@dataclass
class TraceStep:
    """One executed top-level state (see the module docstring for the fields)."""

    index: int
    state: str
    state_class: str = ''
    activated: list[str] = field(default_factory=list)
    capabilities: list[str] = field(default_factory=list)
    entered_at: float = 0.0
    ended_at: float = 0.0
    mode_at_entry: str = ''
    mode_at_exit: str = ''
    outcomes_at_entry: list[str] = field(default_factory=list)
    outcomes_at_exit: list[str] = field(default_factory=list)
    results: list[dict] = field(default_factory=list)
    state_outcome: str = ''
    transition: str = ''
    # The outcome the operator forced on this state ('' none) and the outcome propositions it
    # stands for (a forced 'failed' on look_down: look_down_f): the check reads the forced outcome
    # as the environment's report, so the machine is judged on how it answered it.
    forced: str = ''
    forced_propositions: list[str] = field(default_factory=list)

    @classmethod
    def from_dict(cls, data: dict) -> TraceStep:
        return cls(**data)


@dataclass
class Trace:
    """A run: its steps and the SM outcome it ended in (None if it broke off).

    ``incidents``: what happened physically that should not (dicts with ``kind`` -- ``contact``
    for the robot's body touching furniture, ``fall`` --, the robot ``time`` and a ``message``;
    ``atlas_sim.simulator.atlas_simulator.Incident``). The check reports each as a violation.
    """

    steps: list[TraceStep] = field(default_factory=list)
    outcome: str | None = None
    sm_outcome_propositions: dict[str, str] = field(
        default_factory=lambda: dict(DEFAULT_SM_OUTCOME_PROPOSITIONS))
    incidents: list[dict] = field(default_factory=list)

    def to_dict(self) -> dict:
        return {'outcome': self.outcome, 'sm_outcome_propositions': dict(self.sm_outcome_propositions),
                'steps': [asdict(step) for step in self.steps], 'incidents': [dict(i) for i in self.incidents]}

    @classmethod
    def from_dict(cls, data: dict) -> Trace:
        return cls(steps=[TraceStep.from_dict(s) for s in data.get('steps', [])],
                   outcome=data.get('outcome'),
                   sm_outcome_propositions=dict(data.get('sm_outcome_propositions')
                                                or DEFAULT_SM_OUTCOME_PROPOSITIONS),
                   incidents=[dict(i) for i in data.get('incidents', [])])


class OutcomeTracker:
    """Outcome propositions from activations and reports (activation–outcome semantics)."""

    def __init__(self, control_modes, initial_mode: str, completed_actions=(), sensors=None):
        self.control_modes = set(control_modes)
        self.mode = initial_mode
        # capability -> its last reported outcome, cleared by a new activation (eqs. (5), (6))
        self.reported = {action: COMPLETED for action in completed_actions}
        self.sensors = dict(sensors or {})

    def activate(self, capabilities) -> None:
        for capability in capabilities:
            self.reported.pop(capability, None)

    def report(self, capability: str, outcome: str) -> None:
        self.reported[capability] = outcome
        if capability in self.control_modes and outcome == COMPLETED:
            self.mode = capability

    def read_sensors(self, sensors: dict) -> None:
        self.sensors.update(sensors)

    def true_propositions(self) -> list[str]:
        """The outcome propositions (and sensors) that are true now, sorted."""
        true = {outcome_proposition(self.mode, COMPLETED)}  # eq. (10): the current mode
        for capability, outcome in self.reported.items():
            if capability in self.control_modes and outcome == COMPLETED:
                continue  # only the current mode's completion is true
            true.add(outcome_proposition(capability, outcome))
        true.update(name for name, value in self.sensors.items() if value)
        return sorted(true)


# --- three-valued evaluation ----------------------------------------------------------------

def least_violating_assignments(formulas, current: dict, next_known: dict, unknown: list[str],
                                first_only: bool = False):
    """Assignments of the ``unknown`` next-step variables violating the fewest ``formulas``.

    Branch and bound over the unknown variables with three-valued evaluation, so a
    refuted partial assignment is pruned at once. Returns (cost, assignments) where cost
    is the number of violated formulas (0: the assignments satisfy all of them);
    ``first_only`` stops at the first satisfying assignment (when existence is enough).
    """
    best: list[dict[str, bool]]
    best_cost, best = len(formulas) + 1, []

    def search(depth: int, assignment: dict):
        nonlocal best_cost, best
        if first_only and best_cost == 0:
            return
        step = {**next_known, **assignment}
        cost = sum(partial_evaluate(f, current, step) is False for f in formulas)
        if cost > best_cost:
            return
        if depth == len(unknown):
            if cost < best_cost:
                best_cost, best = cost, []
            best.append(dict(assignment))
            return
        for value in (False, True):
            assignment[unknown[depth]] = value
            search(depth + 1, assignment)
        del assignment[unknown[depth]]

    search(0, {})
    return best_cost, best


# --- the check -------------------------------------------------------------------------------

#: Violations the robot reports (incidents of the run), told with the step they happened in.
INCIDENT_KINDS = ('contact', 'fall')


@dataclass
class Violation:
    kind: str              # env_init, sys_init, env_trans, sys_trans, goal_order, contact, fall
    step: int | None       # trace step during which it happened (None: before the first)
    transition: str        # 'start -> /look_down', '/look_down -> /manipulate', '/x -> finished'
    formulas: list[str]    # the violated formulas (infix)
    message: str


@dataclass
class TraceCheckReport:
    ok: bool
    outcome: str | None
    violations: list[Violation]
    goals: list[str]
    goals_completed_at: dict[str, int | None]
    positions: int

    def to_dict(self) -> dict:
        return {'ok': self.ok, 'outcome': self.outcome, 'positions': self.positions,
                'goals': list(self.goals), 'goals_completed_at': dict(self.goals_completed_at),
                'violations': [asdict(v) for v in self.violations]}

    def summary(self) -> str:
        """The check in words, each violation's message as the GUI shows it."""
        if self.ok:
            return f'trace check: ok ({self.positions} positions, goals {self.goals_completed_at})'
        lines = [f'trace check: {len(self.violations)} violation(s)']
        for v in self.violations:  # an incident's sentence says what, not where (a formula's says both)
            where = f' at step {v.step} ({v.transition})' if v.kind in INCIDENT_KINDS else ''
            lines.append(f'  {v.kind}{where}: {v.message}')
        return '\n'.join(lines)


@dataclass
class _Position:
    label: str
    step: int | None
    env: dict[str, bool]
    visible_sys: dict[str, bool]   # activations (unless hidden) and SM outcomes
    forced_by: TraceStep | None = None  # the step whose operator-forced outcome set this env


def formula_name(section: str, formulas: list, formula) -> str:
    """A formula of the specification by name: its section and place there, then the formula
    ('sys_trans 7: look_down_a & !look_down_c -> next(look_down_a)'); places count from 1 as
    the GUI's specification lists them."""
    return f'{section} {formulas.index(formula) + 1}: {to_infix(formula)}'


def _names(section: str, formulas: list, chosen) -> str:
    return '; '.join(formula_name(section, formulas, f) for f in chosen)


def forced_outcome_message(step: TraceStep, assumptions: str) -> str:
    """A forced outcome that broke the environment's assumptions, told as the operator's choice."""
    return (f'the operator forced {step.forced} on {step.state.lstrip("/")} at step {step.index}; '
            f'the task assumed {assumptions}')


def broken_guarantee_message(transition: str, guarantees: str) -> str:
    return f'the state machine broke a guarantee of the specification ({transition}): {guarantees}'


def broken_assumption_message(transition: str, assumptions: str) -> str:
    return f'the robot (the environment) broke an assumption of the specification ({transition}): {assumptions}'


def check_trace(trace: Trace, spec: GR1Specification, goals: list[str] | None = None,
                ordered: bool = True) -> TraceCheckReport:
    """Check ``trace`` against ``spec`` (see the module docstring).

    ``goals`` default to the goal-memory propositions ``<g>_m`` of the specification, in
    declared order; ``ordered`` says whether the goals had a strict order (eq. (20)).
    """
    checker = _Checker(trace, spec)
    violations = checker.run()
    goals = list(goals) if goals is not None else [
        str(remembered(p)) for p in spec.sys_props if remembered(p)]
    completed_at, goal_violations = check_goal_order(trace, goals, ordered)
    violations.extend(goal_violations)
    violations.extend(incident_violations(trace))
    return TraceCheckReport(ok=not violations, outcome=trace.outcome, violations=violations,
                            goals=goals, goals_completed_at=completed_at,
                            positions=len(checker.positions))


def check_goal_order(trace: Trace, goals: list[str], ordered: bool = True):
    """When each goal counted: its capability, activated in a step, reported ``completed``.

    With ``ordered`` goals a completion counts only once the previous goal has counted in
    an earlier step (eq. (20), where the memory of g_(i-1) must already be true). Returns
    (step of counting per goal, violations): a run ending in ``finished`` must have counted
    every goal.
    """
    completed_at: dict[str, int | None] = {goal: None for goal in goals}
    for step in trace.steps:
        completions = {r['capability'] for r in step.results
                       if r.get('outcome') == COMPLETED and not r.get('abandoned')
                       and r['capability'] in step.capabilities}
        counted_before = dict(completed_at)
        for index, goal in enumerate(goals):
            if completed_at[goal] is not None or goal not in completions:
                continue
            previous = goals[index - 1] if ordered and index > 0 else None
            if previous is None or counted_before[previous] is not None:
                completed_at[goal] = step.index
    violations = []
    finished_prop = trace.sm_outcome_propositions.get(trace.outcome or '', '')
    if trace.outcome is not None and finished_prop == FINISHED:
        missing = [g for g in goals if completed_at[g] is None]
        if missing:
            order = ' in order' if ordered else ''
            # A goal's state whose outcome the operator forced: the robot never reported it completed.
            forced = [f'the operator forced {step.forced} on {step.state.lstrip("/")} at step {step.index}'
                      for step in trace.steps if step.forced and set(step.capabilities) & set(missing)]
            why = f' ({"; ".join(forced)}, not the robot)' if forced else ''
            violations.append(Violation(
                'goal_order', trace.steps[-1].index if trace.steps else None,
                f'{trace.steps[-1].state if trace.steps else "start"} -> {trace.outcome}', [],
                f'the run ended in {trace.outcome!r} but goal(s) {", ".join(missing)} were never '
                f'completed{order}{why}'))
    return completed_at, violations


def incident_violations(trace: Trace) -> list[Violation]:
    """Each physical incident of the run (the robot's body in furniture, a fall) as a violation
    at the step that was running then: the specification speaks of outcomes only, so a run
    through a table would pass it; the robot's physics must answer for what the formulas cannot."""
    violations = []
    for incident in trace.incidents:
        step = step_at(trace, float(incident.get('time', 0.0)))
        violations.append(Violation(str(incident.get('kind', 'incident')), step.index if step else None,
                                    step.state if step else 'start', [], str(incident.get('message', ''))))
    return violations


def step_at(trace: Trace, time: float) -> TraceStep | None:
    """The step running at robot ``time`` (the last one entered by then; None: before the first)."""
    running = None
    for step in trace.steps:
        if step.entered_at <= time + 1e-9:
            running = step
    return running


class _Checker:
    def __init__(self, trace: Trace, spec: GR1Specification):
        self.trace, self.spec = trace, spec
        self.sm_props = {prop for prop in trace.sm_outcome_propositions.values() if prop in spec.sys_props}
        self.activation_props = [p for p in spec.sys_props if is_activation(p)]
        self.memory_props = [p for p in spec.sys_props
                             if p not in self.sm_props and p not in self.activation_props]
        self.positions = self._positions()
        # Each position must satisfy the formulas without next() itself (the last one too), so
        # they are also checked on the target of every step, as next-step formulas.
        self.sys_checks = _with_invariants(spec.sys_trans)
        self.env_checks = _with_invariants(spec.env_trans)

    # positions of the run -----------------------------------------------------------------

    def _env(self, true_props: list[str]) -> dict[str, bool]:
        true = set(true_props)
        return {p: p in true for p in self.spec.env_props}

    def _sys(self, activated, outcome_prop: str | None = None) -> dict[str, bool]:
        values = {p: False for p in self.sm_props}
        if outcome_prop is not None:
            values[outcome_prop] = True
        if activated is not None:
            active = set(activated)
            values.update({p: p in active for p in self.activation_props})
        return values

    def _positions(self) -> list[_Position]:
        steps = self.trace.steps
        if not steps:
            return []
        for before, after in zip(steps, steps[1:]):
            if sorted(before.outcomes_at_exit) != sorted(after.outcomes_at_entry):
                raise TraceError(f'step {after.index} was entered with outcomes {after.outcomes_at_entry} '
                                 f'but step {before.index} ended with {before.outcomes_at_exit}',
                                 item=after.state)
            if before.index + 1 != after.index:
                raise TraceError(f'step {after.index} follows step {before.index}', item=after.state)
        for step in steps:
            unknown = [p for p in step.activated if p not in self.spec.sys_props]
            if unknown:
                raise TraceError(f'step {step.index} activates {unknown[0]!r}, which is not a system '
                                 'proposition of the specification', item=unknown[0])
        positions = [_Position('start', None, self._env(steps[0].outcomes_at_entry), self._sys([]))]
        previous = None
        for s in steps:
            positions.append(self._entered(s.state, s.index, s.outcomes_at_entry, self._sys(s.activated), previous))
            previous = s
        last = steps[-1]
        if self.trace.outcome is not None:
            prop = self.trace.sm_outcome_propositions.get(self.trace.outcome, self.trace.outcome)
            if prop not in self.sm_props:
                raise TraceError(f'the run ended in {self.trace.outcome!r}, whose proposition {prop!r} '
                                 'is not a system proposition of the specification', item=self.trace.outcome)
            positions.append(self._entered(self.trace.outcome, last.index, last.outcomes_at_exit,
                                           self._sys(None, prop), last))
        elif last.transition:  # broke off after the last state ended: its outcomes are still known
            positions.append(self._entered(last.transition, last.index, last.outcomes_at_exit,
                                           self._sys(None), last))
        return positions

    def _entered(self, label, index, outcomes, visible_sys, after: TraceStep | None) -> _Position:
        """The position entered with ``outcomes`` true after step ``after``; when the operator forced
        that step's outcome, what it forced counts as reported (the other outcomes of the same
        capabilities as not)."""
        env = self._env(outcomes)
        if after is None or not after.forced_propositions:
            return _Position(label, index, env, visible_sys)
        forced = set(after.forced_propositions)
        capabilities = {p.rsplit('_', 1)[0] for p in forced}
        for p in env:
            if p.rsplit('_', 1)[0] in capabilities and p not in forced:
                env[p] = False
        env.update({p: True for p in forced if p in env})
        return _Position(label, index, env, visible_sys, forced_by=after)

    def _hidden(self, position: _Position) -> list[str]:
        return [p for p in self.spec.sys_props if p not in position.visible_sys]

    # the walk ------------------------------------------------------------------------------

    def run(self) -> list[Violation]:
        if not self.positions:
            return []
        violations = []
        first = self.positions[0]
        current = {**first.env, **first.visible_sys}
        false_env = [f for f in self.spec.env_init if partial_evaluate(f, current, {}) is False]
        if false_env:
            violations.append(self._violation('env_init', first, first, false_env,
                                              'the robot did not start as the specification assumes: '
                                              + _names('env_init', self.spec.env_init, false_env)))
        # The hidden variables are current-step ones here: evaluate SYS_INIT as a next step.
        cost, assignments = least_violating_assignments(
            [Next(f) for f in self.spec.sys_init], {}, current, self._hidden(first))
        if cost:
            starts: list[tuple[dict[str, bool], dict[str, bool]]] = [({**current, **a}, {}) for a in assignments]
            blamed = self._blame([(f, f) for f in self.spec.sys_init], starts)
            violations.append(self._violation('sys_init', first, first, blamed,
                                              'the state machine did not start as the specification requires: '
                                              + _names('sys_init', self.spec.sys_init, blamed)))
        hidden = [{**current, **a} for a in assignments]  # full valuations of the current position
        for source, target in zip(self.positions, self.positions[1:]):
            violations.extend(self._unknown_forced(source, target))
            violations.extend(self._env_violations(source, target, hidden))
            hidden, violation = self._advance(source, target, hidden, last=target is self.positions[-1])
            if violation:
                violations.append(violation)
        return violations

    def _unknown_forced(self, source, target) -> list[Violation]:
        """A forced outcome whose proposition the specification does not have: the task assumed
        that outcome never happens."""
        forced = target.forced_by
        if forced is None or source.forced_by is forced:
            return []
        unknown = [p for p in forced.forced_propositions if p not in self.spec.env_props]
        if not unknown:
            return []
        return [self._violation('forced_outcome', source, target, [], forced_outcome_message(
            forced, f'it never happens ({", ".join(unknown)} is no proposition of the specification)'))]

    def _env_violations(self, source, target, valuations) -> list[Violation]:
        false_everywhere = None
        for valuation in valuations:
            false = {shown for checked, shown in self.env_checks
                     if partial_evaluate(checked, valuation, target.env) is False}
            false_everywhere = false if false_everywhere is None else false_everywhere & false
        if not false_everywhere:
            return []
        formulas = [f for f in self.spec.env_trans if f in false_everywhere]
        assumptions = _names('env_trans', self.spec.env_trans, formulas)
        forced = target.forced_by or source.forced_by
        if forced is not None:  # the operator's choice, not the robot's nor the machine's
            return [self._violation('forced_outcome', source, target, formulas,
                                    forced_outcome_message(forced, assumptions))]
        return [self._violation('env_trans', source, target, formulas,
                                broken_assumption_message(_transition(source, target), assumptions))]

    def _successors(self, valuations, target: _Position, first_only: bool = False):
        """Cost and full valuations of ``target`` reachable from ``valuations`` under SYS_TRANS."""
        known = {**target.env, **target.visible_sys}
        unknown = self._hidden(target)
        checks = [checked for checked, _ in self.sys_checks]
        found: dict[tuple[tuple[str, bool], ...], dict[str, bool]]
        best_cost, found = len(checks) + 1, {}
        for valuation in valuations:
            cost, assignments = least_violating_assignments(checks, valuation, known, unknown, first_only)
            if cost < best_cost:
                best_cost, found = cost, {}
            if cost == best_cost:
                for assignment in assignments:
                    full = {**known, **assignment}
                    found.setdefault(tuple(sorted(full.items())), full)
        return best_cost, list(found.values())

    def _advance(self, source: _Position, target: _Position, valuations, last: bool):
        # After the last position only existence matters: no need to collect every valuation.
        cost, reached = self._successors(valuations, target, first_only=last)
        if cost == 0:
            if not last:
                reached = self._merge(reached, self._via_idle(valuations, target))
            return reached, None
        via_idle = self._via_idle(valuations, target)
        if via_idle:
            return via_idle, None
        pairs = [(v, r) for v in valuations for r in reached]
        blamed = self._blame(self.sys_checks, pairs)
        return reached, self._violation('sys_trans', source, target, blamed, broken_guarantee_message(
            _transition(source, target), _names('sys_trans', self.spec.sys_trans, blamed)))

    def _via_idle(self, valuations, target: _Position):
        """Valuations of ``target`` reached through idle positions (nothing activated)."""
        idle = _Position('idle', target.step, target.env, self._sys([]))
        seen: dict[tuple[tuple[str, bool], ...], dict[str, bool]]
        frontier, seen = valuations, {}
        for _ in range(len(self.memory_props) + 2):  # the hidden part can change that often at most
            cost, reached = self._successors(frontier, idle)
            fresh = [r for r in reached if tuple(sorted(r.items())) not in seen] if cost == 0 else []
            if not fresh:
                break
            seen.update((tuple(sorted(r.items())), r) for r in fresh)
            frontier = fresh
        if not seen:
            return []
        cost, reached = self._successors(list(seen.values()), target)
        return reached if cost == 0 else []

    @staticmethod
    def _merge(first, second):
        merged = {tuple(sorted(v.items())): v for v in first}
        for v in second:
            merged.setdefault(tuple(sorted(v.items())), v)
        return list(merged.values())

    @staticmethod
    def _blame(checks, pairs) -> list[Formula]:
        """The formulas violated on the least violating (current, next) pair."""
        best = None
        for current, next_step in pairs:
            false = [shown for checked, shown in checks if partial_evaluate(checked, current, next_step) is False]
            if best is None or len(false) < len(best):
                best = false
        return list(dict.fromkeys(best or []))

    @staticmethod
    def _violation(kind, source: _Position, target: _Position, formulas, message) -> Violation:
        transition = _transition(source, target)
        step = target.step if kind.endswith('init') else (source.step if source.step is not None else target.step)
        return Violation(kind, step, transition, [to_infix(f) for f in formulas], message)


def _transition(source: _Position, target: _Position) -> str:
    return source.label if source is target else f'{source.label} -> {target.label}'


def _with_invariants(formulas) -> list[tuple[Formula, Formula]]:
    """(formula to evaluate, formula to report): each formula, plus next(f) for those without next."""
    checks = [(f, f) for f in formulas]
    checks += [(Next(f), f) for f in formulas if not mentions_next(f)]
    return checks


def valuations_of_trace(trace: Trace, spec: GR1Specification) -> list[dict[str, bool]]:
    """The observable valuation of each position (for display and tests)."""
    return [{**p.env, **p.visible_sys} for p in _Checker(trace, spec).positions]


__all__ = ['Trace', 'TraceStep', 'OutcomeTracker', 'TraceError', 'TraceCheckReport', 'Violation',
           'check_trace', 'check_goal_order', 'formula_name', 'forced_outcome_message',
           'broken_guarantee_message', 'broken_assumption_message', 'incident_violations', 'step_at', 'partial_evaluate', 'least_violating_assignments',
           'valuations_of_trace']
