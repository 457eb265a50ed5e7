"""Data from the operator that capabilities need, checked as the real robot would check it.

On ATLAS the operator does not "complete" ``object_template``: FlexBE's ``InputState`` asks
for a template id and writes it to userdata, and the states that act on the object receive
that id. So the simulator checks the *data that reaches a request*, not the specification's
memory of an input action:

* an action of the ``simulation.actions`` section with ``motion: operator_input`` names what
  it ``provides`` (a data kind below), e.g. ``object_template: {..., provides: template_id}``;
* an action that has such an input action among its preconditions needs that datum: a
  request that carries data (FlexBE's states over ROS) must hold a valid value under the
  datum's key; the precondition is then met whatever ran before on the simulator;
* a request without data (the in-process executive, which runs ``object_template`` on the
  simulator itself) uses what the simulator's own operator answered (``scenario``).

Data kinds:

``template_id``  an object of the scene: ``simulation.scene.objects`` maps template ids to
                 bodies of the model (ATLAS: id 1 is the box in front of the robot, which is
                 what FlexBE's flexbe_input answers by default for an integer). An action on
                 the object also needs it within ``scene.reach`` metres of the pelvis.
``target_pose``  a pose for locomotion: three finite numbers (x, y, yaw).
"""

from __future__ import annotations

import json
import math
import pickle
from typing import Any, Mapping, Optional

from .config import SceneConfig, SimulationConfig, SimulationConfigError

TEMPLATE_ID = "template_id"
TARGET_POSE = "target_pose"
DATA_KINDS = (TEMPLATE_ID, TARGET_POSE)
#: How long a quoted datum may be in a refusal (a request may carry anything).
_QUOTE_LIMIT = 40


def provided_datum(entry: Mapping[str, Any], action: str) -> Optional[str]:
    """The data kind an action entry ``provides`` (None: it provides none)."""
    kind = entry.get("provides")
    if kind is None:
        return None
    if entry.get("motion") != "operator_input":
        raise SimulationConfigError(f"simulation.actions.{action}: only operator_input actions provide data",
                                    item=action)
    if kind not in DATA_KINDS:
        raise SimulationConfigError(f"simulation.actions.{action}.provides: unknown data kind {kind!r}; "
                                    f"known: {', '.join(DATA_KINDS)}", item=action)
    return kind


def operator_answer(settings: SimulationConfig, name: str, kind: str) -> Any:
    """What the simulated operator answers for the input action ``name`` (of data ``kind``).

    ``scenario.operator_answers`` when it names one; else the scene's first object for a
    template and the robot's own place for a pose.
    """
    answers = settings.scenario.operator_answers
    if name in answers:
        return answers[name]
    if kind == TEMPLATE_ID:
        return min(settings.scene.objects, default=None)
    return [0.0, 0.0, 0.0]


def answers_by_request_type(settings: SimulationConfig, request_capabilities: Mapping[int, str]) -> dict:
    """BehaviorInput request type -> the answer, for the input actions behind FlexBE's InputStates."""
    answers = {}
    for request_type, name in request_capabilities.items():
        kind = provided_datum(settings.actions.get(name, {}), name)
        if kind is not None:
            answers[request_type] = operator_answer(settings, name, kind)
    return answers


def quoted(value: Any) -> str:
    """``value`` as the operator sent it, cut short."""
    text = repr(value)
    return text if len(text) <= _QUOTE_LIMIT else text[:_QUOTE_LIMIT - 3] + "..."


def datum_refusal(kind: str, value: Any, scene: SceneConfig) -> Optional[str]:
    """Why ``value`` is no valid datum of ``kind`` (None: it is valid)."""
    if kind == TEMPLATE_ID:
        if isinstance(value, bool) or not isinstance(value, int):
            return f"{TEMPLATE_ID} {quoted(value)} is not an object template id (an integer)"
        if value not in scene.objects:
            known = ", ".join(str(i) for i in sorted(scene.objects)) or "none"
            return f"{TEMPLATE_ID} {value} names no object of the scene (known template ids: {known})"
        return None
    if kind == TARGET_POSE:
        if (not isinstance(value, (list, tuple)) or len(value) != 3
                or not all(isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)
                           for v in value)):
            return f"{TARGET_POSE} {quoted(value)} is not a pose (three numbers: x, y, yaw)"
        return None
    raise ValueError(f"unknown data kind {kind!r}")


def decode_userdata(keys, values) -> Optional[dict]:
    """A request's userdata from its keys and JSON texts; None when it carries no keys.

    A value that is no JSON text stays the text it is, so the check names it.
    """
    if not keys:
        return None
    data = {}
    for key, text in zip(keys, values):
        try:
            data[key] = json.loads(text)
        except ValueError:
            data[key] = text
    for key in keys[len(values):]:
        data[key] = None
    return data


def flexbe_input_data(value: Any) -> str:
    """The ``data`` of a BehaviorInput result, as FlexBE's flexbe_input writes it for InputState."""
    return str(pickle.dumps(value))


def parse_answers(entries, source: str) -> dict:
    """``{request type: answer}`` from a mapping (a scenario file) or ``TYPE=VALUE`` texts.

    Values are YAML (``1``, ``[0.6, 0.0, 0.0]``); request types are BehaviorInput's numbers.
    Raises SimulationConfigError naming the bad entry.
    """
    import yaml  # only the operator's command line reads answers as text

    if isinstance(entries, Mapping):
        items = list(entries.items())
    else:
        items = []
        for text in entries:
            request_type, separator, value = str(text).partition('=')
            if not separator:
                raise SimulationConfigError(f'{source}: expected TYPE=VALUE, got {quoted(text)}', item=str(text))
            try:
                items.append((request_type.strip(), yaml.safe_load(value)))
            except yaml.YAMLError as error:
                raise SimulationConfigError(f'{source}: {quoted(value)} is no YAML value '
                                            f'({error.problem if isinstance(error, yaml.MarkedYAMLError) else error})',
                                            item=str(text)) from None
    answers = {}
    for request_type, value in items:
        try:
            number = int(request_type)
        except (TypeError, ValueError):
            number = -1
        if isinstance(request_type, bool) or not 0 <= number <= 255:
            raise SimulationConfigError(f'{source}: {quoted(request_type)} is no BehaviorInput request type '
                                        '(0-255)', item=str(request_type))
        answers[number] = value
    return answers
