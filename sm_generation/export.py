"""Writing a StateInstantiation list as YAML, JSON or a Graphviz drawing.

YAML and JSON hold the 16 fields of every entry (``to_dict``) in list order, so the same
machine always gives the same bytes. ``to_dot`` draws states as boxes, concurrency
containers as clusters, transitions labelled by their outcomes, the machine's outcomes
as double circles and the initial state with an arrow from a dot; ``render`` runs
Graphviz' ``dot`` (Debian/Ubuntu package ``graphviz``) to make SVG or PNG.
"""

from __future__ import annotations

import json
import shutil
import subprocess
from pathlib import Path

import yaml

from sm_generation.instantiation import StateInstantiation

RENDER_FORMATS = ('svg', 'png')


class RenderError(RuntimeError):
    """Rendering failed; ``item`` names the missing program or the output file."""

    def __init__(self, message: str, item: str):
        super().__init__(message)
        self.item = item


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


def to_dot(states: list[StateInstantiation]) -> str:
    """Graphviz DOT text of the machine (top level and one level of containers)."""
    root = next((s for s in states if s.state_path == '/'), None)
    top = [s for s in states if s.parent_path == '/' and s.state_class != StateInstantiation.CLASS_OUTCOME]
    inner = {s.state_path: [c for c in states if c.parent_path == s.state_path] for s in top}
    machine_outcomes = root.outcomes if root else []
    lines = ['digraph state_machine {', '  compound=true;', '  rankdir=TB;',
             '  graph [fontname="Helvetica"];',
             '  node [shape=box, style=rounded, fontname="Helvetica"];',
             '  edge [fontname="Helvetica", fontsize=10];']
    for outcome in machine_outcomes:
        lines.append(f'  {_quote("outcome:" + outcome)} [label={_quote(outcome)}, shape=doublecircle];')
    anchor = {}  # top-level state -> node that edges attach to
    for index, state in enumerate(top):
        node_id = 'state:' + state.name
        if inner[state.state_path]:
            lines.append(f'  subgraph {_quote("cluster_" + str(index))} {{')
            lines.append(f'    label={_quote(state.name + " (concurrent)")}; style=rounded;')
            for child in inner[state.state_path]:
                lines.append(f'    {_quote(node_id + "/" + child.name)} '
                             f'[label={_quote(child.name + chr(10) + _class_label(child))}];')
            lines.append('  }')
            anchor[state.name] = (node_id + '/' + inner[state.state_path][0].name, f'cluster_{index}')
        else:
            lines.append(f'  {_quote(node_id)} [label={_quote(state.name + chr(10) + _class_label(state))}];')
            anchor[state.name] = (node_id, None)
    if root and root.initial_state_name in anchor:
        node, cluster = anchor[root.initial_state_name]
        head = f', lhead={_quote(cluster)}' if cluster else ''
        lines.append('  "start" [shape=point, width=0.15];')
        lines.append(f'  "start" -> {_quote(node)} [label="initial"{head}];')
    for state in top:
        tail, tail_cluster = anchor[state.name]
        for outcome, target in zip(state.outcomes, state.transitions):
            attributes = [f'label={_quote(outcome)}']
            if tail_cluster:
                attributes.append(f'ltail={_quote(tail_cluster)}')
            if target in anchor:
                head, head_cluster = anchor[target]
                if head_cluster and head_cluster != tail_cluster:
                    attributes.append(f'lhead={_quote(head_cluster)}')
            else:
                head = 'outcome:' + target
            lines.append(f'  {_quote(tail)} -> {_quote(head)} [{", ".join(attributes)}];')
    lines.append('}')
    return '\n'.join(lines) + '\n'


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
