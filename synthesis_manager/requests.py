"""Reading behavior synthesis requests: goal strings and option checks (ROS-free)."""

from __future__ import annotations

import re

# The original takes comma-separated names; the FlexBE WebUI may also send a list-like text
# ("['look_down', 'pickup_object']") or space-separated names. Accept all of them.
_SEPARATORS = re.compile(r'[\s,;]+')
_DECORATION = re.compile(r'[\[\]()"\']')
OPTION_NAMES = ('ltl_compilation_only', 'ltl_synthesis_only', 'ltl_steps_only')


class InvalidRequest(ValueError):
    code = 'INVALID_REQUEST'


def parse_names(text) -> list[str]:
    """``'look_down, pickup_object'`` (or a list of names) -> ``['look_down', 'pickup_object']``."""
    if isinstance(text, (list, tuple)):
        text = ','.join(text)
    return [name for name in _SEPARATORS.split(_DECORATION.sub(' ', text or '')) if name]


def selected_option(options) -> str | None:
    """The one SynthesisOptions flag that is set, or None; several flags is an error."""
    chosen = [name for name in OPTION_NAMES if getattr(options, name)]
    if len(chosen) > 1:
        raise InvalidRequest(f'synthesis options are mutually exclusive, got {" and ".join(chosen)}')
    return chosen[0] if chosen else None
