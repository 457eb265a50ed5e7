"""The downloads of a finished job, built on demand from its outcome."""

from __future__ import annotations

import json
import tempfile
from dataclasses import dataclass
from pathlib import Path

from respec.parsing import spec_from_text_sections
from sm_generation import StateInstantiation, export
from sm_generation.export import render, to_dot


@dataclass(frozen=True)
class Artifact:
    content: bytes
    media_type: str
    filename: str


def _state_list(outcome):
    return [StateInstantiation.from_dict(s) for s in outcome['states']]


def _export(kind):
    def build(outcome) -> bytes:
        return getattr(export, kind)(_state_list(outcome)).encode()
    return build


def _picture(fmt):
    def build(outcome) -> bytes:
        with tempfile.TemporaryDirectory(prefix='behavior-synthesis-gui-') as directory:
            path = render(to_dot(_state_list(outcome)), Path(directory) / f'state_machine.{fmt}')
            return path.read_bytes()
    return build


def _specification(method):
    def build(outcome) -> bytes:
        return getattr(spec_from_text_sections(outcome['ltl_specification']), method)().encode()
    return build


def _has_states(outcome):
    return bool(outcome.get('states'))


def _has_specification(outcome):
    return bool(outcome.get('ltl_specification'))


def _has_automaton(outcome):
    return bool((outcome.get('automaton') or {}).get('states'))


# name -> (media type, is it there for this outcome?, build bytes from the outcome)
ARTIFACTS = {
    'state_machine.yaml': ('application/yaml', _has_states, _export('to_yaml')),
    'state_machine.json': ('application/json', _has_states, _export('to_json')),
    'state_machine.dot': ('text/vnd.graphviz', _has_states, _export('to_dot')),
    'state_machine.svg': ('image/svg+xml', _has_states, _picture('svg')),
    'state_machine.png': ('image/png', _has_states, _picture('png')),
    'specification.structuredslugs': ('text/plain', _has_specification, _specification('to_structuredslugs')),
    'specification.slugsin': ('text/plain', _has_specification, _specification('to_slugsin')),
    'automaton.json': ('application/json', _has_automaton,
                       lambda outcome: (json.dumps(outcome['automaton'], indent=1) + '\n').encode()),
    'result.json': ('application/json', lambda outcome: True,
                    lambda outcome: (json.dumps(outcome, indent=1) + '\n').encode()),
}


def available_artifacts(outcome: dict) -> list[str]:
    return [name for name, (_, present, _) in ARTIFACTS.items() if present(outcome)]
