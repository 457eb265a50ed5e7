"""Writing a StateInstantiation list as YAML, JSON or a Graphviz drawing.

YAML and JSON hold the 16 fields of every entry (``to_dict``) in list order, so the same
machine always gives the same bytes. ``to_dot`` draws the machine as the FlexBE editor
shows behaviors (states as boxes with their outcomes along the bottom, containers holding
their states, the machine's outcomes at the bottom); ``render`` runs Graphviz' ``dot``
(Debian/Ubuntu package ``graphviz``) to make SVG or PNG.
"""

from __future__ import annotations

import json
import shutil
import subprocess
from pathlib import Path

import yaml

from respec.errors import CodedError
from respec.naming import FINISHED
from sm_generation.instantiation import StateInstantiation

RENDER_FORMATS = ('svg', 'png')
# The machine's success outcome is drawn green, its other outcomes (and arrows to them) red.
GOOD_COLOUR, BAD_COLOUR = '#2e7d32', '#c62828'


class RenderError(CodedError):
    """Rendering failed; ``item`` names the missing program or the output file."""

    code = 'SM_GENERATION_FAILED'


def to_yaml(states: list[StateInstantiation]) -> str:
    return yaml.safe_dump([s.to_dict() for s in states], sort_keys=False, default_flow_style=None,
                          width=100, allow_unicode=True)


def to_json(states: list[StateInstantiation]) -> str:
    return json.dumps([s.to_dict() for s in states], indent=2, ensure_ascii=False) + '\n'


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


def to_dot(states: list[StateInstantiation]) -> str:
    """Graphviz DOT text of the machine, drawn the way the FlexBE editor shows behaviors.

    Every state is a box with its name, its class and, along its bottom edge, its outcomes;
    outcomes that lead to the same target share one cell and one arrow. A concurrency
    container is one box holding its inner states, with the container's outcomes at the
    bottom. The machine's outcomes are ovals at the bottom (``finished`` green, the others
    red). SVG elements get ids ``state:<name>``, ``outcome:<name>`` and
    ``edge:<state>-><target>``, so a page can find, highlight and explain them.
    """
    root = next((s for s in states if s.state_path == '/'), None)
    top = [s for s in states if s.parent_path == '/' and s.state_class != StateInstantiation.CLASS_OUTCOME]
    inner = {s.state_path: [c for c in states if c.parent_path == s.state_path] for s in top}
    machine_outcomes = root.outcomes if root else []
    lines = ['digraph state_machine {', '  rankdir=TB;', '  nodesep=0.35;', '  ranksep=0.55;',
             '  graph [fontname="Helvetica", bgcolor="transparent"];',
             '  node [shape=plain, fontname="Helvetica", fontsize=14];',
             '  edge [fontname="Helvetica", fontsize=12, color="#4a5560", arrowsize=0.8];']
    for state in top:
        label = _container_label(state, inner[state.state_path]) if inner[state.state_path] else _state_label(state)
        lines.append(f'  {_quote("state:" + state.name)} [id={_quote("state:" + state.name)}, '
                     f'class="state", label=<{label}>];')
    lines.append('  { rank=sink;')
    for outcome in machine_outcomes:
        colour = GOOD_COLOUR if outcome == FINISHED else BAD_COLOUR
        lines.append(f'    {_quote("outcome:" + outcome)} [id={_quote("outcome:" + outcome)}, class="outcome", '
                     f'label={_quote(outcome)}, shape=box, style="rounded,filled,bold", color="{colour}", '
                     f'fillcolor="{colour}22", margin="0.25,0.08"];')
    lines.append('  }')
    if root and root.initial_state_name:
        lines.append('  "start" [id="start", shape=circle, style=filled, fillcolor="#4a5560", label="", width=0.18];')
        lines.append(f'  "start" -> {_quote("state:" + root.initial_state_name)}:n [id="edge:start", label=" initial"];')
    names = {s.name for s in top}
    for state in top:
        for index, (target, outcomes) in enumerate(outcome_groups(state)):
            head = 'state:' + target if target in names else 'outcome:' + target
            failing = target != FINISHED and target not in names
            style = f', color="{BAD_COLOUR}", style=dashed' if failing else ''
            lines.append(f'  {_quote("state:" + state.name)}:o{index}:s -> {_quote(head)} '
                         f'[id={_quote(f"edge:{state.name}->{target}")}{style}];')
    lines.append('}')
    return '\n'.join(lines) + '\n'


def _outcome_cells(state: StateInstantiation) -> str:
    return ''.join(f'<TD PORT="o{index}" BORDER="1" SIDES="{"T" if index == 0 else "TL"}" CELLPADDING="3" '
                   f'BGCOLOR="#eef2f6">'
                   f'<FONT POINT-SIZE="12">{_html(", ".join(outcomes))}</FONT></TD>'
                   for index, (_, outcomes) in enumerate(outcome_groups(state)))


def _state_label(state: StateInstantiation) -> str:
    columns = max(1, len(outcome_groups(state)))
    return (f'<TABLE BORDER="1" CELLBORDER="0" CELLSPACING="0" CELLPADDING="5" STYLE="ROUNDED" BGCOLOR="white">'
            f'<TR><TD COLSPAN="{columns}"><B>{_html(state.name)}</B></TD></TR>'
            f'<TR><TD COLSPAN="{columns}"><FONT POINT-SIZE="11" COLOR="#5a6570">{_html(_class_label(state))}'
            f'</FONT></TD></TR><TR>{_outcome_cells(state)}</TR></TABLE>')


def _container_label(state: StateInstantiation, children: list[StateInstantiation]) -> str:
    columns = max(1, len(outcome_groups(state)))
    boxes = ''.join(
        f'<TD><TABLE BORDER="1" CELLBORDER="0" CELLSPACING="0" CELLPADDING="4" STYLE="ROUNDED" BGCOLOR="white">'
        f'<TR><TD><B>{_html(child.name)}</B></TD></TR><TR><TD><FONT POINT-SIZE="11" COLOR="#5a6570">'
        f'{_html(_class_label(child))}</FONT></TD></TR><TR><TD><FONT POINT-SIZE="10" COLOR="#5a6570">'
        f'{_html(", ".join(child.outcomes))}</FONT></TD></TR></TABLE></TD>' for child in children)
    return (f'<TABLE BORDER="1" CELLBORDER="0" CELLSPACING="0" CELLPADDING="5" STYLE="ROUNDED" BGCOLOR="#f4f0fa">'
            f'<TR><TD COLSPAN="{columns}"><B>{_html(state.name)}</B> <FONT POINT-SIZE="11" COLOR="#5a6570">'
            f'(concurrency container)</FONT></TD></TR>'
            f'<TR><TD COLSPAN="{columns}"><TABLE BORDER="0" CELLSPACING="6"><TR>{boxes}</TR></TABLE></TD></TR>'
            f'<TR>{_outcome_cells(state)}</TR></TABLE>')


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
