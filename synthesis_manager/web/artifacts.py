"""The downloads of a finished job, built on demand from its outcome (and request, config dir)."""

from __future__ import annotations

import json
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

from respec.parsing import spec_from_text_sections
from sm_generation import SMGenerationError, StateInstantiation, export
from sm_generation.config import load_flexbe_config
from sm_generation.export import render, to_dot
from sm_generation.flexbe_behavior import behavior_package, check_behavior_name, default_behavior_name


@dataclass(frozen=True)
class Artifact:
    content: bytes
    media_type: str
    filename: str


def _state_list(outcome):
    return [StateInstantiation.from_dict(s) for s in outcome['states']]


def _export(kind):
    def build(outcome, *_) -> bytes:
        return getattr(export, kind)(_state_list(outcome)).encode()
    return build


def _picture(fmt):
    def build(outcome, *_) -> bytes:
        with tempfile.TemporaryDirectory(prefix='behavior-synthesis-gui-') as directory:
            path = render(to_dot(_state_list(outcome)), Path(directory) / f'state_machine.{fmt}')
            return path.read_bytes()
    return build


def _specification(method):
    def build(outcome, *_) -> bytes:
        return getattr(spec_from_text_sections(outcome['ltl_specification']), method)().encode()
    return build


def _flexbe_behavior(outcome, request, config_dir) -> bytes:
    """The behavior package FlexBE's editor would save (as ``behavior-synthesis export-behavior``)."""
    name = request.name if request.name and check_name(request.name) else default_behavior_name(request.goals)
    package = behavior_package(_state_list(outcome), load_flexbe_config(request.system, config_dir), name,
                               date=time.strftime('%a %b %d %Y'))
    return package.zip_bytes()


def check_name(name: str) -> bool:
    """Whether a request's name can name a behavior (container paths such as '/Container' cannot)."""
    try:
        check_behavior_name(name)
    except SMGenerationError:
        return False
    return True


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
                       lambda outcome, *_: (json.dumps(outcome['automaton'], indent=1) + '\n').encode()),
    'result.json': ('application/json', lambda outcome: True,
                    lambda outcome, *_: (json.dumps(outcome, indent=1) + '\n').encode()),
    'flexbe_behavior.zip': ('application/zip', _has_states, _flexbe_behavior),
}


def available_artifacts(outcome: dict) -> list[str]:
    return [name for name, (_, present, _) in ARTIFACTS.items() if present(outcome)]
