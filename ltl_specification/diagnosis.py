"""Why a task cannot be done, in plain words: a pre-check and unrealizable cores.

Before synthesis, ``precheck`` looks at the robot abstraction and the request and names
impossible requests directly:

* a goal whose control mode cannot be reached from where the previous goal leaves the robot
  (with goals in strict order), naming the missing transition of ``config/<system>.yaml``;
* a precondition that can never complete because custom LTL forbids activating it;
* custom LTL that contradicts itself or the initial conditions.

After synthesis reports an unrealizable specification, ``diagnose`` adds a minimal
unrealizable core (``ltl_synthesizer.unrealizable_core``) over the specification's formula
groups, each mapped to its paper equation and the configuration entry or request field that
produced it, and a short environment play told in words. ``Diagnosis.message`` leads with one
plain sentence; the details follow.

One diagnosis serves every channel, whichever stage finds the impossibility: the compiler
refuses a goal mode no route reaches (INVALID_GOALS) with ``refusal_diagnosis`` of the
specification it compiled, the synthesis node leads SPEC_UNSYNTHESIZABLE with ``diagnose``
(``explain_unsynthesizable``, the synthesizer's own play left out), and the GUI's form shows
the pre-check's sentence (``goal_findings``, capability robots included). A specification
without provenance is diagnosed by its formulas (``formula_groups``). A realizable one is
checked for winning by cheating (``explain_well_separation``).

The pre-check and the diagnosis read only the specification and its provenance
(``ltl_specification.provenance``: the compiler puts there everything that needs the robot
configuration), so whoever holds a specification diagnoses it with its own settings: the
synthesis node does, in the child process of the synthesis, and returns the diagnosis in its
answer (``explain_unsynthesizable``).
"""

from __future__ import annotations

import itertools
import time
from dataclasses import asdict, dataclass, field
from typing import TYPE_CHECKING, Any, Callable, Iterable, Sequence

from ltl_specification.components import SOURCE_CUSTOM, FormulaGroup
from respec.ltl import Formula, evaluate, mentions_next, to_infix, variables
from respec.vocabulary.naming import activation
from respec.robot import RobotSystem, for_description
from respec.robot.abstraction import RobotAbstraction
from respec.robot.cnu import CapabilitySystem
from respec.spec import FORMULA_SECTIONS, GR1Specification
from ltl_synthesizer.errors import SynthesisCancelledError
from ltl_synthesizer.interrupt import Limits
from ltl_synthesizer.well_separation import check_well_separation

from ltl_specification.capability_precheck import capability_file, unreachable_goals
from ltl_specification.systems import load_task_abstraction
from ltl_specification.provenance import Provenance
from ltl_specification.reachability import Finding, unreachable_goal_modes

if TYPE_CHECKING:
    from ltl_synthesizer.symbolic import SymbolicGame

PLAY_LENGTH = 8
# Seconds the compiler spends diagnosing a task it refuses (the core search is cut there; the
# sentence and the findings are told even then).
REFUSAL_DIAGNOSIS_SECONDS = 5.0
# Custom formulas are checked by enumerating their variables' values: at most this many.
MAX_ENUMERATED_VARIABLES = 14

#: The note of a diagnosis whose core search its limits stopped (the message then depends on
#: how much time it had: a strategy cache keeps no such message).
CORE_NOT_COMPUTED = 'The unrealizable core was not computed'


@dataclass
class CoreEntry:
    """One formula group of an unrealizable core, told as equation, origin and formulas."""

    equation: str
    title: str
    item: str
    origin: str
    formulas: list[str]

    def line(self) -> str:
        return f'{self.name()} ({self.origin}): ' + '; '.join(self.formulas)

    def name(self) -> str:
        if self.equation == 'custom':
            return f'{"custom LTL" if self.title == "custom LTL" else "formula"} {self.item}'
        return f'eq. {self.equation} {self.title}' + (f' for {self.item}' if self.item else '')


@dataclass
class Diagnosis:
    """Why a specification is unrealizable: a plain ``sentence`` first, then the evidence."""

    sentence: str
    findings: list[Finding] = field(default_factory=list)
    core: list[CoreEntry] = field(default_factory=list)
    play: list[str] = field(default_factory=list)
    note: str = ''     # e.g. that the core search ran out of time

    def message(self) -> str:
        """The sentence, then the core and the environment play (one text, for error messages)."""
        lines = [self.sentence]
        for finding in self.findings[1:]:
            lines.append(f'Also: {finding.sentence}')
        if self.core:
            lines.append('')
            lines.append('Unrealizable core (these requirements together cannot be met; '
                         'dropping any one of them would make the task possible):')
            lines += [f'  - {entry.line()}' for entry in self.core]
        if self.play:
            lines.append('')
            lines.append('How the environment wins (the robot does its best):')
            lines += [f'  {number}. {step}' for number, step in enumerate(self.play, start=1)]
        if self.note:
            lines += ['', self.note]
        return '\n'.join(lines)

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


# --- pre-check -------------------------------------------------------------------------------

def precheck(spec: GR1Specification, provenance: Provenance | None = None) -> list[Finding]:
    """Impossible requests that the abstraction and the request alone reveal (see module doc);
    ``provenance`` is what ``spec`` was compiled from (default: its own ``provenance``)."""
    provenance = provenance or getattr(spec, 'provenance', None)
    if provenance is None:  # a specification given whole: nothing to check it against
        return []
    findings = list(provenance.findings)  # what the abstraction shows, found when compiling
    custom = [g for g in provenance.groups if g.source == SOURCE_CUSTOM]
    findings += _forbidden_activations(custom, provenance)
    findings += _contradictory_custom_ltl(custom, provenance.groups)
    return findings


def goal_findings(system: RobotSystem, initial_conditions: Sequence[str], goals: Sequence[str],
                  strict_order: bool = True) -> list[Finding]:
    """The goal part of the pre-check, without compiling (cheap enough to run as a form changes).

    Names that are not actions or modes of ``system`` are skipped (compilation reports them).
    """
    findings_for = for_description(_GOAL_FINDINGS, system, missing=_mode_goal_findings)
    return findings_for(system, initial_conditions, goals, strict_order)


def _capability_goal_findings(system: RobotSystem, initial_conditions: Sequence[str], goals: Sequence[str],
                              strict_order: bool) -> list[Finding]:
    """A goal no capability can make true, as the compiler refuses it."""
    del strict_order  # CNU's goals hold together at the end
    return [Finding(str(error), 'frame axiom', f'postconditions in {capability_file(system)}', str(error.item))
            for error in unreachable_goals(system, initial_conditions, goals)]


def _mode_goal_findings(system: RobotSystem, initial_conditions: Sequence[str], goals: Sequence[str],
                        strict_order: bool) -> list[Finding]:
    """A goal mode no route from the initial mode reaches (as the compiler refuses it)."""
    abstraction = load_task_abstraction(system)
    modes = [i for i in initial_conditions if abstraction.kind_of(i) == 'control_mode']
    initial_mode = modes[0] if modes else abstraction.initial_mode
    if initial_mode is None:
        return []
    known = [g for g in goals if abstraction.kind_of(g) is not None]
    return unreachable_goal_modes(abstraction, known, initial_mode, strict_order, system.config_file)


_GOAL_FINDINGS = {RobotAbstraction: _mode_goal_findings, CapabilitySystem: _capability_goal_findings}


def impossible_next_goals(system: RobotSystem, initial_conditions: Sequence[str], goals: Sequence[str],
                          strict_order: bool = True, candidates: Iterable[str] | None = None) -> dict[str, str]:
    """For every one of ``candidates`` that is not a goal yet (default: the abstraction's actions
    and modes; a capability robot's view gives what its capabilities make true): why it cannot
    be the next goal (if so)."""
    impossible = {}
    if candidates is None:
        candidates = load_task_abstraction(system).items()
    for candidate in candidates:
        if candidate in goals:
            continue
        findings = goal_findings(system, initial_conditions, [*goals, candidate], strict_order)
        last = [f for f in findings if f.item == candidate]
        if last:
            impossible[candidate] = last[0].sentence
    return impossible


def _forbidden_activations(custom: list[FormulaGroup], provenance: Provenance) -> list[Finding]:
    """A needed item whose activation a custom guarantee forbids at every step."""
    findings = []
    needed = {**provenance.pertinence.reasons}
    for group in custom:
        if group.section not in ('sys_trans', 'sys_init'):
            continue
        formula = group.formulas[0]
        for item, reason in needed.items():
            if item == provenance.pertinence.initial_mode and reason == 'initial mode':
                continue
            if _forces_false(formula, activation(item)):
                findings.append(Finding(
                    f'{item} ({reason}) can never complete: custom LTL {group.item} '
                    f"'{to_infix(formula)}' forbids ever activating it.",
                    'custom', f'custom LTL {group.item}', item))
    return findings


def _contradictory_custom_ltl(custom: list[FormulaGroup], groups: Sequence[FormulaGroup]) -> list[Finding]:
    """Custom formulas that cannot hold together with their section (custom and generated
    initial conditions; custom formulas of one safety section among themselves)."""
    findings = []
    for section in ('env_init', 'sys_init', 'env_trans', 'sys_trans'):
        own = [g.formulas[0] for g in custom if g.section == section]
        if not own:
            continue
        context = [f for g in groups if g.section == section and g.source != SOURCE_CUSTOM
                   for f in g.formulas] if section.endswith('init') else []
        relevant = set().union(*(variables(f) for f in own))
        formulas = own + [f for f in context if variables(f) & relevant]
        if _satisfiable(formulas) is False:
            texts = ', '.join(f"'{to_infix(f)}'" for f in own)
            against = ' and the generated initial conditions' if len(formulas) > len(own) else ''
            findings.append(Finding(f'The custom {section} formulas {texts}{against} contradict each other.',
                                    'custom', f'custom LTL {section}', section))
    return findings


def _forces_false(formula: Formula, name: str) -> bool:
    """Whether ``formula`` holds only when ``name`` is false now (or next, for a next-formula)."""
    def with_name_true(current: dict[str, bool], next_step: dict[str, bool]) -> bool:
        if mentions_next(formula):
            return evaluate(formula, current, {**next_step, name: True})
        return evaluate(formula, {**current, name: True}, next_step)
    return name in variables(formula) and _satisfiable([formula]) is not False and \
        _exists(variables(formula), with_name_true) is False


def _satisfiable(formulas: list[Formula]) -> bool | None:
    """Propositional satisfiability (current and next values free); None when too large."""
    names = set().union(*(variables(f) for f in formulas))
    return _exists(names, lambda current, next_step: all(evaluate(f, current, next_step) for f in formulas))


def _exists(names: set[str], holds: Callable[[dict[str, bool], dict[str, bool]], bool]) -> bool | None:
    ordered = sorted(names)
    if 2 * len(ordered) > MAX_ENUMERATED_VARIABLES:
        return None
    for values in itertools.product((False, True), repeat=2 * len(ordered)):
        current = dict(zip(ordered, values[:len(ordered)]))
        next_step = dict(zip(ordered, values[len(ordered):]))
        if holds(current, next_step):
            return True
    return False


# --- after synthesis: core and play ----------------------------------------------------------

def diagnose(spec: GR1Specification, robotics_semantics: bool = True, limits: Limits = Limits(),
             provenance: Provenance | None = None) -> Diagnosis | None:
    """Why ``spec`` is unrealizable; None if it is realizable. ``provenance`` is what it was
    compiled from (default: its own ``provenance``; without one, by its formulas).

    When ``limits`` stop the core search (a cancel, the deadline), the pre-check's findings
    are still returned and the note says the core was not computed.
    """
    # only an unrealizable specification needs them (not the compiler's or a realizable answer's)
    from ltl_synthesizer.unrealizable_core import environment_play, unrealizable_core
    provenance = provenance or getattr(spec, 'provenance', None)
    findings = precheck(spec, provenance) if provenance else []
    groups = provenance.groups if provenance else formula_groups(spec)
    diagnosis = Diagnosis(sentence=findings[0].sentence if findings else '', findings=findings)
    core_groups = []
    try:
        core = unrealizable_core(spec, groups, robotics_semantics, limits)
        if core is None:
            return None
        core_groups = core.groups
        diagnosis.core = [CoreEntry(g.equation, g.title, g.item,
                                    provenance.origin(g) if provenance else 'the specification',
                                    [to_infix(f) for f in g.formulas]) for g in core.groups]
        steps = environment_play(spec, robotics_semantics, PLAY_LENGTH, limits)
        diagnosis.play = play_in_words(steps, provenance.meanings if provenance else {})
    except SynthesisCancelledError as stopped:
        diagnosis.note = f'({CORE_NOT_COMPUTED}: {stopped.reason}.)'
    sensors = unreported_sensors(spec, core_groups)
    diagnosis.findings += sensors
    if not diagnosis.sentence:
        diagnosis.sentence = sensors[0].sentence if sensors else _core_sentence(diagnosis.core)
    return diagnosis


def unreported_sensors(spec: GR1Specification, core_groups: Sequence[FormulaGroup]) -> list[Finding]:
    """The inputs the core reads that no assumption mentions: a sensor nothing reports (no
    ENV_TRANS ties it to anything the robot does, no ENV_LIVENESS says it ever holds), so the
    environment may hold it against the task forever and no behavior can wait it out."""
    assumed = set().union(*(variables(f) for f in (*spec.env_init, *spec.env_trans, *spec.env_liveness)))
    findings = []
    for sensor in (p for p in spec.env_props if p not in assumed):
        readers = [g for g in core_groups if any(sensor in variables(f) for f in g.formulas)]
        if not readers:
            continue
        where = '; '.join(f'{g.item or g.title}: {to_infix(g.formulas[0])}' for g in readers[:2])
        findings.append(Finding(
            f"The task needs the sensor '{sensor}' (an input of the specification), but nothing reports it: "
            f'no assumption ties it to what the robot does or says it ever holds, so the environment may keep '
            f'it against the task forever and no behavior can observe it change. It is read by {where}. '
            f"Report it from a capability's outcome (an ENV_TRANS such as "
            f"\"<capability>_<outcome>' <-> (<capability>_a & {sensor}')\" in the spec file), or assume it "
            f"holds infinitely often (ENV_LIVENESS: {sensor}).", 'assumptions', sensor, sensor))
    return findings


def _core_sentence(core: list[CoreEntry]) -> str:
    """The plain sentence when the pre-check found nothing: the core's configurable causes."""
    if not core:
        return 'The task cannot be done: the specification is unrealizable.'
    causes = [e for e in core if e.equation in ('(8)', '(9)', 'custom')] or core
    named = '; '.join(f'{e.name()} ({e.origin})' for e in causes[:3])
    return f'The task cannot be done as requested; these requirements are what makes it impossible: {named}.'


def formula_groups(spec: GR1Specification) -> list[FormulaGroup]:
    """One group per formula, named by its section and index: the core's units for a
    specification that records no provenance (a CNU capability robot's, one given whole)."""
    return [FormulaGroup(section, 'custom', 'formula', f'{section}[{index}]', SOURCE_CUSTOM, (formula,))
            for section in FORMULA_SECTIONS for index, formula in enumerate(getattr(spec, section))]


def play_in_words(steps: list[dict[str, bool | None]], meaning: dict[str, str]) -> list[str]:
    """Each step of an environment play as a sentence about what changed (``meaning``: what a
    proposition turning true means, e.g. ``Provenance.meanings``; others are named as they are)."""
    words = []
    previous: dict[str, bool | None] = {}
    for index, step in enumerate(steps):
        if any(value is None for value in step.values()):
            words.append('the environment answers so that no allowed move remains (deadlock)')
            break
        turned_on = [meaning.get(name, name) for name, value in step.items() if value and not previous.get(name)]
        if index == 0:
            words.append('start: ' + (', '.join(turned_on) or 'nothing holds'))
        else:
            words.append(', '.join(turned_on) or 'no outcome yet (the environment waits)')
        previous = step
    if words:
        words.append('from here no move the robot may make leads to an outcome of the state machine, '
                     'and the environment never has to report a failure')
    return words


# --- for the pipeline -------------------------------------------------------------------------

def refusal_diagnosis(spec: GR1Specification, sentence: str,
                      seconds: float = REFUSAL_DIAGNOSIS_SECONDS) -> Diagnosis:
    """The diagnosis of a compiled task that the compiler refuses (a mode no route reaches): the
    sentence, core and play that synthesis would lead with, within ``seconds``; ``sentence``
    leads when the pre-check names nothing. ``seconds`` 0: the pre-check alone (no core, no play)."""
    sentence = sentence[0].upper() + sentence[1:] + '.'
    if seconds > 0:
        diagnosis = diagnose(spec, limits=Limits(deadline=time.monotonic() + seconds))
        if diagnosis is None:  # realizable all the same (a mode only custom LTL names): the refusal stands
            return Diagnosis(sentence)
    else:
        findings = precheck(spec)
        diagnosis = Diagnosis(findings[0].sentence if findings else '', findings)
    if not diagnosis.findings:
        diagnosis.sentence = sentence
    return diagnosis


def explain_well_separation(spec: GR1Specification, provenance: Provenance | None = None,
                            limits: Limits = Limits(), game: SymbolicGame | None = None) -> str:
    """The warning for a realizable ``spec`` whose controller can win by forcing the environment
    to break its assumptions ('' when it cannot; ``ltl_synthesizer.well_separation``), naming each
    assumption as the core names a requirement (paper equation, configuration entry, formula)
    when ``provenance`` (default: the spec's own) records it; ``game``: the game of ``spec``, if
    one is built already (the one synthesis solved)."""
    report = check_well_separation(spec, limits, game)
    provenance = provenance or getattr(spec, 'provenance', None)
    if report.well_separated or provenance is None:
        return report.warning()
    return report.warning([_assumption_line(spec, provenance, section, index) for section, index in report.involved])


def _assumption_line(spec: GR1Specification, provenance: Provenance, section: str, index: int) -> str:
    formula = getattr(spec, section)[index]
    group = next((g for g in provenance.groups if g.section == section and formula in g.formulas), None)
    if group is None:
        return f'{section} #{index}: {to_infix(formula)}'
    return CoreEntry(group.equation, group.title, group.item, provenance.origin(group), [to_infix(formula)]).line()


def explain_unsynthesizable(details: str, spec: GR1Specification, provenance: Provenance | None,
                            robotics_semantics: bool = True, limits: Limits = Limits()) -> str:
    """The SPEC_UNSYNTHESIZABLE message for ``spec``: the diagnosis first, then ``details``
    (the synthesizer's own explanation). Without a provenance (a specification given whole, a
    CNU capability robot's) the core is told by section and index (``formula_groups``). Never
    raises: if it cannot be diagnosed, ``details`` are returned unchanged."""
    try:
        diagnosis = diagnose(spec, robotics_semantics, limits, provenance)
    except Exception:  # noqa: BLE001 - the diagnosis is a help; the synthesizer's verdict stands without it
        return details
    if diagnosis is None:
        return details
    if diagnosis.play:  # one play in the message: the diagnosis' is a play of the same counter-strategy
        from ltl_synthesizer.explanation import without_play
        details = without_play(details)
    return f'{diagnosis.message()}\n\nDetails from the synthesizer:\n{details}'
