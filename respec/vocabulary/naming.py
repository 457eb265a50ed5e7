"""The naming rules shared by every package: proposition names, SM outcomes, name lists.

Every action or control mode ``p`` has a system proposition ``p_a`` (p is being activated)
and one environment proposition per outcome, ``p_<first letter>`` (``p_c`` completed,
``p_f`` failed); goal memories ``g_m`` are system propositions, and so are the state
machine's outcomes (by default ``finished`` and ``failed``).
"""

from __future__ import annotations

import re
from typing import Iterable

ACTIVATION_SUFFIX = '_a'
MEMORY_SUFFIX = '_m'
COMPLETED = 'completed'
FINISHED, FAILED = 'finished', 'failed'
#: The state machine's outcomes when a request names none.
DEFAULT_SM_OUTCOMES = (FINISHED, FAILED)
#: FlexBE's StateInstantiation ``state_class`` markers of what is not a state class: the
#: containers, an embedded behavior (its class is ``behavior_class``) and an outcome.
STATEMACHINE_CLASS, CONCURRENCY_CLASS, PRIORITY_CLASS = ':STATEMACHINE', ':CONCURRENCY', ':PRIORITY'
BEHAVIOR_CLASS, OUTCOME_CLASS = ':BEHAVIOR', ':OUTCOME'

# The original takes comma-separated names; the FlexBE WebUI may also send a list-like text
# ("['look_down', 'pickup_object']") or space-separated names. Accept all of them.
_SEPARATORS = re.compile(r'[\s,;]+')
_DECORATION = re.compile(r'[\[\]()"\']')


def activation(item: str) -> str:
    """The activation proposition π_p of an action or control mode."""
    return f'{item}{ACTIVATION_SUFFIX}'


def outcome_proposition(item: str, outcome: str) -> str:
    """The outcome proposition π_p^o, suffixed with the outcome's first letter ('stand_c')."""
    return f'{item}_{outcome[0]}'


def memory(goal: str) -> str:
    """The memory proposition μ_g of having achieved goal g."""
    return f'{goal}{MEMORY_SUFFIX}'


def activated(proposition: str) -> str | None:
    """The action or control mode ``p`` an activation proposition ``p_a`` names (None: not one)."""
    return _strip(proposition, ACTIVATION_SUFFIX)


def is_activation(proposition: str) -> bool:
    return activated(proposition) is not None


def remembered(proposition: str) -> str | None:
    """The goal ``g`` a memory proposition ``g_m`` names (None: not one)."""
    return _strip(proposition, MEMORY_SUFFIX)


def is_memory(proposition: str) -> bool:
    return remembered(proposition) is not None


def _strip(proposition: str, suffix: str) -> str | None:
    if proposition.endswith(suffix) and len(proposition) > len(suffix):
        return proposition[:-len(suffix)]
    return None


def parse_names(text: str | list[str] | tuple[str, ...] | None) -> list[str]:
    """``'look_down, pickup_object'`` (or a list of such texts) -> ``['look_down', 'pickup_object']``."""
    if isinstance(text, (list, tuple)):
        text = ','.join(text)
    return [name for name in _SEPARATORS.split(_DECORATION.sub(' ', text or '')) if name]


def did_you_mean(name: str, known: Iterable[str]) -> str:
    """``'; did you mean look_down?'`` for a misspelled ``name`` close to one of ``known``, else ''."""
    import difflib  # only for a misspelled name (3 ms of a fresh process's start-up, with heapq)
    close = difflib.get_close_matches(name, list(known), n=2, cutoff=0.7)
    return f'; did you mean {" or ".join(close)}?' if close else ''
