"""The downloads of a finished job, built on demand from its JobOutcome (and request, config dir)."""

from __future__ import annotations

import json
import time
from dataclasses import dataclass
from typing import Callable

from respec.nesting import run_with_deep_stack
from respec.parsing import spec_from_text_sections
from sm_generation import SMGenerationError, export
from sm_generation.flexbe_behavior import (behavior_module_name, behavior_package, check_behavior_name,
                                           default_behavior_name)
from sm_generation.for_system import behavior_flexbe_config
from synthesis_manager.web import picture
from synthesis_manager.web.outcome import JobOutcome


@dataclass(frozen=True)
class Artifact:
    content: bytes
    media_type: str
    filename: str


def _export(kind):
    def build(outcome, *_) -> bytes:
        return getattr(export, kind)(outcome.machine).encode()
    return build


def _picture(fmt):
    def build(outcome, *_) -> bytes:
        draw = picture.render_svg if fmt == 'svg' else picture.render_png
        return draw(picture.picture_dot(outcome.machine))
    return build


def _specification(method):
    def build(outcome, *_) -> bytes:
        def printed():  # the job's formulas may nest MAX_FORMULA_NESTING deep
            return getattr(spec_from_text_sections(outcome.ltl_specification), method)().encode()
        return run_with_deep_stack(printed)
    return build


def behavior_name(request) -> str:
    """The name of the job's behavior: the request's name when it can name one, else the goals'."""
    return request.name if request.name and check_name(request.name) else default_behavior_name(request.goals)


def download_filename(request, artifact: str) -> str:
    """The file name a download is saved under: the behavior package is named after its
    behavior (``look_down_pickup_object_flexbe_behavior.zip``), the others after the request."""
    if artifact == 'flexbe_behavior.zip':
        return f'{behavior_module_name(behavior_name(request))[:-len("_sm")]}_{artifact}'
    return f'{request.name or "behavior"}_{artifact}'


def _flexbe_behavior(outcome, request, systems) -> bytes:
    """The behavior package FlexBE's editor would save (as ``behavior-synthesis export-behavior``)."""
    name = behavior_name(request)
    package = behavior_package(outcome.machine, behavior_flexbe_config(systems.load(request.system)), name,
                               date=time.strftime('%a %b %d %Y'))
    return package.zip_bytes()


def check_name(name: str) -> bool:
    """Whether a request's name can name a behavior (container paths such as '/Container' cannot)."""
    try:
        check_behavior_name(name)
    except SMGenerationError:
        return False
    return True


def _has_machine(outcome: JobOutcome) -> bool:
    return outcome.machine is not None


def _has_specification(outcome: JobOutcome) -> bool:
    return bool(outcome.ltl_specification)


def _has_automaton(outcome: JobOutcome) -> bool:
    return bool(outcome.automaton_states)


def _json_file(data) -> bytes:
    return (json.dumps(data, indent=1) + '\n').encode()


@dataclass(frozen=True)
class ArtifactKind:
    """One download: what the page calls it, its media type, when it exists, how it is built."""

    label: str
    media_type: str
    present: Callable[[JobOutcome], bool]
    build: Callable[..., bytes]  # (outcome, job request, the robot systems' catalog) -> bytes


ARTIFACTS = {
    'state_machine.yaml': ArtifactKind('State machine (StateInstantiation list, YAML)', 'application/yaml',
                                       _has_machine, _export('to_yaml')),
    'state_machine.json': ArtifactKind('State machine (StateInstantiation list, JSON)', 'application/json',
                                       _has_machine, _export('to_json')),
    'state_machine.dot': ArtifactKind('Picture source (Graphviz DOT)', 'text/vnd.graphviz', _has_machine,
                                      lambda outcome, *_: picture.picture_dot(outcome.machine).encode()),
    'state_machine.svg': ArtifactKind('Picture (SVG)', 'image/svg+xml', _has_machine, _picture('svg')),
    'state_machine.png': ArtifactKind('Picture (PNG)', 'image/png', _has_machine, _picture('png')),
    'specification.structuredslugs': ArtifactKind('Specification (.structuredslugs)', 'text/plain',
                                                  _has_specification, _specification('to_structuredslugs')),
    'specification.slugsin': ArtifactKind('Specification (.slugsin)', 'text/plain',
                                          _has_specification, _specification('to_slugsin')),
    'automaton.json': ArtifactKind('Automaton (JSON)', 'application/json', _has_automaton,
                                   lambda outcome, *_: _json_file(outcome.automaton)),
    'result.json': ArtifactKind('Whole result (JSON)', 'application/json', lambda outcome: True,
                                lambda outcome, *_: _json_file(outcome.to_dict())),
    'flexbe_behavior.zip': ArtifactKind('FlexBE behavior package (.zip, as export-behavior writes it)',
                                        'application/zip', _has_machine, _flexbe_behavior),
}


def available_artifacts(outcome: JobOutcome) -> list[str]:
    return [name for name, kind in ARTIFACTS.items() if kind.present(outcome)]


def made_in_page(names: list[str]) -> list[str]:
    """The downloads among ``names`` the page makes from its drawing (the PNG when ``dot`` is missing)."""
    return ['state_machine.png'] if 'state_machine.png' in names and picture.png_in_page() else []


def download_labels(names: list[str]) -> dict[str, str]:
    """What the page calls each download."""
    return {name: ARTIFACTS[name].label for name in names}
