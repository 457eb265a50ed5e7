"""Writing a state machine as YAML, JSON or a Graphviz drawing.

YAML and JSON hold its StateInstantiation list (the 16 fields of every entry, ``to_dict``, in
list order; ``from_text`` reads the list back), so the same
machine always gives the same bytes. ``to_dot`` draws the machine as the FlexBE editor
shows behaviors (states as boxes with their outcomes along the bottom, containers holding
their states, the machine's outcomes at the bottom); ``render`` runs Graphviz' ``dot``
(Debian/Ubuntu package ``graphviz``) to make SVG or PNG.
"""

from __future__ import annotations

import json
import math
import shutil
import subprocess
from pathlib import Path
from typing import AbstractSet

import yaml

from respec.vocabulary.errors import CodedError, ErrorCode
from respec.vocabulary.naming import FINISHED
from sm_generation.instantiation import StateInstantiation
from sm_generation.state_machine import State, StateMachine

RENDER_FORMATS = ('svg', 'png')
# The machine's success outcome is drawn green, its other outcomes (and arrows to them) red.
GOOD_COLOUR, BAD_COLOUR = '#2e7d32', '#c62828'


class RenderError(CodedError):
    """Rendering failed; ``item`` names the missing program or the output file."""

    code = ErrorCode.SM_GENERATION_FAILED


def to_yaml(machine: StateMachine) -> str:
    """The machine's StateInstantiation list as YAML."""
    return yaml.safe_dump([s.to_dict() for s in machine.to_instantiations()], sort_keys=False, default_flow_style=None,
                          width=100, allow_unicode=True)


def to_json(machine: StateMachine) -> str:
    """The machine's StateInstantiation list as JSON."""
    return json.dumps([s.to_dict() for s in machine.to_instantiations()], indent=2, ensure_ascii=False) + '\n'


def from_text(text: str) -> list[StateInstantiation]:
    """Read a list written by ``to_yaml`` or ``to_json`` (JSON is YAML too)."""
    return [StateInstantiation.from_dict(entry) for entry in yaml.safe_load(text) or []]


def _quote(text: str) -> str:
    return '"' + text.replace('\\', '\\\\').replace('"', '\\"').replace('\n', '\\n') + '"'


def _html(text: str) -> str:
    """Text for a Graphviz HTML-like label."""
    return (text.replace('&', '&amp;').replace('<', '&lt;').replace('>', '&gt;').replace('"', '&quot;'))


def outcome_groups(state: StateInstantiation) -> list[tuple[str, list[str]]]:
    """The state's transitions merged by target: (target, outcomes leading there), first-use order.

    One drawn edge per target keeps parallel transitions (e.g. ``failed`` and ``aborted``
    both to ``failed``) from overlapping.
    """
    targets: dict[str, list[str]] = {}
    for outcome, target in zip(state.outcomes, state.transitions):
        targets.setdefault(target, []).append(outcome)
    return list(targets.items())


def to_dot(machine: StateMachine) -> str:
    """Graphviz DOT text of the machine, drawn the way the FlexBE editor shows behaviors.

    Every state is a box with its name, its class and, along its bottom edge, its outcomes;
    outcomes that lead to the same target share one cell and one arrow. A concurrency
    container is one box holding its inner states, with the container's outcomes at the
    bottom. The machine's outcomes are boxes at the bottom (``finished`` green, the others
    red). Arrows are coloured by autonomy level as in the FlexBE editor (Off grey, Low blue,
    High green, Full red) and dashed when they end the behavior in failure.

    A machine of more than ``WRAP_AFTER`` states is laid out for reading (``_grid``): its
    main path, from the initial state along success transitions, wraps into side-by-side
    columns, and every column has its own copy of each failure outcome right below it (a
    failure rail): outcome cells that end the behavior in failure are red and need no arrow.
    Outcome cells naming more than two outcomes list them one per line.

    SVG elements get ids ``state:<name>``, ``outcome:<name>`` (copies: ``outcome:<name>:<column>``)
    and ``edge:<state>-><target>``, so a page can find, highlight and explain them.
    """
    top = list(machine.states)
    machine_outcomes = machine.outcomes
    names = {s.name for s in top}
    columns = _grid(top, machine.initial_state_name)
    # A grid is drawn tighter, so that a 12-goal machine fits a 1280x720 window at 11 px text.
    lines = ['digraph state_machine {', '  rankdir=TB;', f'  nodesep={0.2 if columns else 0.35};',
             f'  ranksep={0.2 if columns else 0.55};',
             '  graph [fontname="Helvetica", bgcolor="transparent"];',
             '  node [shape=plain, fontname="Helvetica", fontsize=14];',
             '  edge [fontname="Helvetica", fontsize=12, color="#4a5560", arrowsize=0.8];']
    column_of = {state: index for index, column in enumerate(columns) for state in column}
    for state in top:
        failing = _failing_groups(state, names)
        label = (_container_label(state, failing) if state.states else
                 _state_label(state, failing, padding=4 if columns else 5))
        css = f'state column-{column_of[state.name]}' if columns else 'state'  # its failure outcome's copy
        lines.append(f'  {_quote("state:" + state.name)} [id={_quote("state:" + state.name)}, '
                     f'class="{css}", label=<{label}>];')
    failure_outcomes = [o for o in machine_outcomes if o != FINISHED]
    copies = {o: [_outcome_node(o, c) for c in range(len(columns))] for o in failure_outcomes} if columns else {}
    lines.append('  { rank=sink;')
    for outcome in machine_outcomes:
        for node in copies.get(outcome, [_outcome_node(outcome, 0)]):
            colour = GOOD_COLOUR if outcome == FINISHED else BAD_COLOUR
            lines.append(f'    {_quote(node)} [id={_quote(node)}, class="outcome", '
                         f'label={_quote(outcome)}, shape=box, style="rounded,filled,bold", color="{colour}", '
                         f'fillcolor="{colour}22", margin="0.25,0.08"];')
    lines.append('  }')
    if columns:
        lines += _grid_lines(columns, copies, FINISHED in machine_outcomes)
    lines.append('  "start" [id="start", shape=circle, style=filled, fillcolor="#4a5560", label="", width=0.18];')
    lines.append(f'  "start" -> {_quote("state:" + machine.initial_state_name)}:n [id="edge:start", label=" initial"];')
    for state in top:
        for index, (target, outcomes) in enumerate(outcome_groups(state)):
            head = ('state:' + target if target in names else
                    _outcome_node(target, column_of.get(state.name, 0) if target in copies else 0))
            to_failure = target != FINISHED and target not in names
            if to_failure and columns:
                continue  # the red cell and the column's own failure outcome say it (the rail)
            attributes = [f'id={_quote(f"edge:{state.name}->{target}")}']
            level = _autonomy(state, outcomes)
            if level is not None:
                attributes.append(f'class="autonomy-{AUTONOMY_NAMES[level].lower()}", color="{AUTONOMY_COLOURS[level]}"')
            if to_failure:
                attributes.append('style=dashed' if level is not None else f'color="{BAD_COLOUR}", style=dashed')
            if columns and column_of.get(state.name) != column_of.get(target, column_of.get(state.name)):
                # An arrow across the grid would wind around whole columns: a connector says where
                # the path goes on, as in a printed flow chart.
                head = f'continue:{state.name}->{target}'
                colour = AUTONOMY_COLOURS[level] if level is not None else '#4a5560'
                lines.append(f'  {_quote(head)} [id={_quote(head)}, class="connector", shape=plain, '
                             f'fontcolor="{colour}", label={_quote("→ " + target)}];')
            lines.append(f'  {_quote("state:" + state.name)}:o{index}:s -> {_quote(head)} '
                         f'[{", ".join(attributes)}];')
    lines.append('}')
    return '\n'.join(lines) + '\n'


# FlexBE's autonomy levels (the outcome needs at least this level to be taken without the
# operator) and the colours its editor's convention gives their transitions.
AUTONOMY_NAMES = ('Off', 'Low', 'High', 'Full')
AUTONOMY_COLOURS = ('#7d7d70', '#5466d8', '#2f8a3a', '#d0534a')
# Machines with more top-level states than this wrap their main path into columns.
WRAP_AFTER = 7


def _autonomy(state: StateInstantiation, outcomes: list[str]) -> int | None:
    """The highest autonomy level among ``outcomes`` of ``state`` (None if the state has none)."""
    levels = [state.autonomy[state.outcomes.index(o)] for o in outcomes
              if len(state.autonomy) == len(state.outcomes)]
    levels = [level for level in levels if isinstance(level, int) and 0 <= level < len(AUTONOMY_NAMES)]
    return max(levels) if levels else None


def _failing_groups(state: StateInstantiation, names: set[str]) -> set[int]:
    """Indexes of the state's outcome groups that end the behavior in failure."""
    return {index for index, (target, _) in enumerate(outcome_groups(state))
            if target not in names and target != FINISHED}


def _outcome_node(outcome: str, column: int) -> str:
    return f'outcome:{outcome}' if column == 0 else f'outcome:{outcome}:{column}'


def _grid(top: list[State], initial: str) -> list[list[str]]:
    """The top-level states in reading order (the main path from ``initial`` along each state's
    first transition to another state, then the rest in list order), cut into columns about as
    tall as the grid is wide in boxes; [] for a machine short enough for one column."""
    if len(top) <= WRAP_AFTER:
        return []
    by_name = {s.name: s for s in top}
    current: str | None
    order, current = [], initial if initial in by_name else top[0].name
    while current in by_name and current not in order:
        order.append(current)
        current = next((t for t, _ in outcome_groups(by_name[current]) if t in by_name and t not in order), None)
    order += [s.name for s in top if s.name not in order]
    rows = max(4, math.ceil(math.sqrt(len(order) * 1.4)))
    return [order[i:i + rows] for i in range(0, len(order), rows)]


def _grid_lines(columns: list[list[str]], failure_copies: dict[str, list[str]], has_finished: bool) -> list[str]:
    """Invisible edges holding the grid: each column top to bottom, its failure outcomes below
    it, and the states of one row left to right."""
    lines = []
    for index, column in enumerate(columns):
        chain = [_quote('state:' + name) for name in column]
        below = [_quote(copies[index]) for copies in failure_copies.values()]
        if has_finished and index == len(columns) - 1:
            below.append(_quote('outcome:' + FINISHED))
        lines.append(f'  {" -> ".join(chain)} [style=invis, weight=10];')
        lines += [f'  {chain[-1]} -> {node} [style=invis];' for node in below]
    for row in range(len(columns[0])):
        cells = [_quote('state:' + column[row]) for column in columns if row < len(column)]
        if len(cells) > 1:
            lines.append(f'  {{ rank=same; {" -> ".join(cells)} [style=invis]; }}')
    return lines


def _outcome_cells(state: StateInstantiation, failing: AbstractSet[int] = frozenset()) -> str:
    cells = []
    for index, (_, outcomes) in enumerate(outcome_groups(state)):
        text = (', ' if len(outcomes) <= 2 else ',<BR/>').join(_html(o) for o in outcomes)
        colours = ('#fdecea', f' COLOR="{BAD_COLOUR}"') if index in failing else ('#eef2f6', '')
        cells.append(f'<TD PORT="o{index}" BORDER="1" SIDES="{"T" if index == 0 else "TL"}" CELLPADDING="3" '
                     f'BGCOLOR="{colours[0]}"><FONT POINT-SIZE="12"{colours[1]}>{text}</FONT></TD>')
    return ''.join(cells)


def _state_label(state: StateInstantiation, failing: AbstractSet[int] = frozenset(), padding: int = 5) -> str:
    columns = max(1, len(outcome_groups(state)))
    return (f'<TABLE BORDER="1" CELLBORDER="0" CELLSPACING="0" CELLPADDING="{padding}" STYLE="ROUNDED" BGCOLOR="white">'
            f'<TR><TD COLSPAN="{columns}"><B>{_html(state.name)}</B></TD></TR>'
            f'<TR><TD COLSPAN="{columns}"><FONT POINT-SIZE="11" COLOR="#5a6570">{_html(_class_label(state))}'
            f'</FONT></TD></TR><TR>{_outcome_cells(state, failing)}</TR></TABLE>')


def _container_label(state: State, failing: AbstractSet[int] = frozenset()) -> str:
    columns = max(1, len(outcome_groups(state)))
    boxes = ''.join(
        f'<TD><TABLE BORDER="1" CELLBORDER="0" CELLSPACING="0" CELLPADDING="4" STYLE="ROUNDED" BGCOLOR="white">'
        f'<TR><TD><B>{_html(child.name)}</B></TD></TR><TR><TD><FONT POINT-SIZE="11" COLOR="#5a6570">'
        f'{_html(_class_label(child))}</FONT></TD></TR><TR><TD><FONT POINT-SIZE="10" COLOR="#5a6570">'
        f'{_html(", ".join(child.outcomes))}</FONT></TD></TR></TABLE></TD>' for child in state.states)
    return (f'<TABLE BORDER="1" CELLBORDER="0" CELLSPACING="0" CELLPADDING="5" STYLE="ROUNDED" BGCOLOR="#f4f0fa">'
            f'<TR><TD COLSPAN="{columns}"><B>{_html(state.name)}</B> <FONT POINT-SIZE="11" COLOR="#5a6570">'
            f'(concurrency container)</FONT></TD></TR>'
            f'<TR><TD COLSPAN="{columns}"><TABLE BORDER="0" CELLSPACING="6"><TR>{boxes}</TR></TABLE></TD></TR>'
            f'<TR>{_outcome_cells(state, failing)}</TR></TABLE>')


def _class_label(state: StateInstantiation) -> str:
    if state.state_class == StateInstantiation.CLASS_BEHAVIOR:
        return f'[{state.behavior_class}]'
    return state.state_class


def render(dot_text: str, path: str | Path, fmt: str | None = None) -> Path:
    """Write ``dot_text`` drawn as SVG or PNG (from ``fmt`` or the file suffix) to ``path``."""
    path = Path(path)
    fmt = (fmt or path.suffix.lstrip('.')).lower()
    if fmt not in RENDER_FORMATS:
        raise RenderError(f'cannot render {fmt!r}: use one of {", ".join(RENDER_FORMATS)}', str(path))
    program = shutil.which('dot')
    if program is None:
        raise RenderError("Graphviz' 'dot' program is not installed (apt-get install graphviz)", 'dot')
    result = subprocess.run([program, f'-T{fmt}', '-o', str(path)], input=dot_text.encode(),
                            capture_output=True, check=False, timeout=60)
    if result.returncode != 0:
        raise RenderError(f'dot failed: {result.stderr.decode(errors="replace").strip()}', str(path))
    return path
