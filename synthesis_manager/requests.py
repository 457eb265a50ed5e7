"""Reading behavior synthesis requests: goal strings and option checks (ROS-free)."""

from __future__ import annotations


OPTION_NAMES = ('ltl_compilation_only', 'ltl_synthesis_only', 'ltl_steps_only')


class InvalidRequest(ValueError):
    code = 'INVALID_REQUEST'


def selected_option(options) -> str | None:
    """The one SynthesisOptions flag that is set, or None; several flags is an error."""
    chosen = [name for name in OPTION_NAMES if getattr(options, name)]
    if len(chosen) > 1:
        raise InvalidRequest(f'synthesis options are mutually exclusive, got {" and ".join(chosen)}')
    return chosen[0] if chosen else None
