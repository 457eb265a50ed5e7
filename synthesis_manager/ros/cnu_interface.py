"""The action type on ``/flexbe_synthesis``: CNU's ``flexbe_synthesis_msgs/action/FlexBESynthesis``.

CNU's package (built by `make flexbe`, or from the user's FlexBE workspace) is offered whenever
it is importable: an unmodified client of that type finds the server. Its result carries
``flexbe_msgs/StateInstantiation[]``, to which our states are copied field by field, and its
``SynthesisErrorCode`` constants. Without it, ``/flexbe_synthesis`` offers our look-alike
``synthesis_msgs/action/FlexBESynthesis`` (same fields and codes) and ``fallback_reason`` says why.
Server and client load the same way, so a client in the server's environment uses its type.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Any, Sequence

from respec.vocabulary.errors import ErrorCode
from synthesis_manager.ros.conversions import constants
from synthesis_msgs.msg import OutcomeCondition, StateInstantiation

CNU_PACKAGE = 'flexbe_synthesis_msgs'
FALLBACK_TYPE = 'synthesis_msgs/FlexBESynthesis'

# Our codes that CNU's SynthesisErrorCode has under another name: the same meaning, CNU's
# constant (docs/cnu.md, "Error codes on /flexbe_synthesis").
CNU_EQUIVALENTS = {
    'LTL_SPEC_COMPILATION_FAILED': 'SPEC_COMPILATION_FAILED',
    'UNKNOWN_SYSTEM': 'NO_SYSTEM_CONFIG',             # the system has no configuration
    'ABSTRACTION_CONFIG_INVALID': 'CONFIG_FILE_INVALID',  # a system's file is malformed or contradicts itself
    'INVALID_SPEC_NAME': 'INVALID_REQUEST',           # the request's name cannot name byproducts
}

# Our error names without a constant of the same meaning in CNU's SynthesisErrorCode go to the
# generic failure of their stage (the result's messages keep the precise name): (lowest value
# of the stage's range in our SynthesisErrorCodes, CNU's constant).
_STAGE_FAILURES = ((-9, 'BEHAVIOR_SYNTHESIS_FAILED'), (-19, 'SPEC_COMPILATION_FAILED'),
                   (-29, 'SYNTHESIS_FAILED'), (-49, 'SM_GENERATION_FAILED'))


def cnu_error_name(code: ErrorCode, cnu_names) -> str:
    """The CNU constant for our error ``code``: the same-named one when CNU has it, else the one
    of the same meaning (CNU_EQUIVALENTS), else its stage's generic failure."""
    code = ErrorCode(code)  # type: ignore[call-arg]  # a lookup by value (mypy: a constructor)
    if code.name in cnu_names:
        return code.name
    if CNU_EQUIVALENTS.get(code.name) in cnu_names:
        return CNU_EQUIVALENTS[code.name]
    return next((failure for lowest, failure in _STAGE_FAILURES if code.number >= lowest), 'FAILURE')


_PACKAGE_PREFIX = re.compile(r'[A-Za-z0-9_]+/')


def field_mismatches(source_fields: dict[str, str], target_fields: dict[str, str]) -> list[str]:
    """Why messages with ``source_fields`` cannot be copied field by field into ones with
    ``target_fields`` (field name -> rosidl type; nested types compare without their package)."""
    def plain(fields):
        return {name: _PACKAGE_PREFIX.sub('', kind) for name, kind in fields.items()}
    source, target = plain(source_fields), plain(target_fields)
    return [f'{name}: {source.get(name, "missing")} vs {kind}'
            for name, kind in target.items() if source.get(name) != kind]


def copy_message(message, target_type, nested: dict[str, type] | None = None):
    """``message`` as a ``target_type`` with the same fields, field by field; the sequence
    fields named in ``nested`` hold messages, copied into the given type."""
    nested = nested or {}
    values = {}
    for name in target_type.get_fields_and_field_types():
        value = getattr(message, name)
        values[name] = [copy_message(item, nested[name]) for item in value] if name in nested else value
    return target_type(**values)


@dataclass(frozen=True)
class FlexBESynthesisInterface:
    """The FlexBESynthesis action type offered, with the message types its results hold."""

    action_type: type[Any]      # a generated action class (its Goal, Result, Feedback)
    request_type: type
    error_code_type: type
    state_type: type
    condition_type: type
    fallback_reason: str = ''   # why CNU's type is not offered; '' when it is

    @property
    def type_name(self) -> str:
        """e.g. ``flexbe_synthesis_msgs/action/FlexBESynthesis``."""
        return f'{self.action_type.__module__.split(".")[0]}/action/{self.action_type.__name__}'

    def error_code(self, code: ErrorCode):
        """Our error code -> this type's SynthesisErrorCode."""
        codes = constants(self.error_code_type)
        return self.error_code_type(value=codes[cnu_error_name(code, codes)])

    def states(self, states: list) -> list:
        """Our StateInstantiation messages as this type's (flexbe_msgs' for CNU's type)."""
        if not states or isinstance(states[0], self.state_type):
            return list(states)
        return [copy_message(state, self.state_type, {'cond_transition': self.condition_type})
                for state in states]

    def result(self, code: ErrorCode, message: str, states: list, notes: list, fixes: Sequence[str] = ()):
        """The action's result: CNU's code, the states, and on failure ``NAME: message`` followed
        by the suggested ``fixes`` (one message each; the FlexBE WebUI shows them in its dialog)."""
        failure = [] if code == ErrorCode.SUCCESS else [f'{code}: {message}', *fixes]
        return self.action_type.Result(error_code=self.error_code(code), states=self.states(states),
                                       messages=list(notes) + failure)


def load_flexbe_synthesis_interface() -> FlexBESynthesisInterface:
    """CNU's type when its package is importable and usable, else ours with the reason."""
    try:
        from flexbe_msgs.msg import OutcomeCondition as CnuCondition, StateInstantiation as CnuState
        from flexbe_synthesis_msgs.action import FlexBESynthesis
        from flexbe_synthesis_msgs.msg import FlexBESynthesisRequest, SynthesisErrorCode
        from rclpy.type_support import check_for_type_support

        check_for_type_support(FlexBESynthesis)  # a package built without its C libraries fails here
        mismatches = field_mismatches(StateInstantiation.get_fields_and_field_types(),
                                      CnuState.get_fields_and_field_types())
        if mismatches:
            raise TypeError(f'flexbe_msgs/StateInstantiation differs from ours: {"; ".join(mismatches)}')
    except Exception as error:  # noqa: BLE001 - whatever makes it unusable: say it once, serve our type
        from synthesis_msgs.action import FlexBESynthesis
        from synthesis_msgs.msg import FlexBESynthesisRequest, SynthesisErrorCode

        problem = 'not importable' if isinstance(error, ImportError) else 'not usable'
        reason = (f'{CNU_PACKAGE} {problem} ({type(error).__name__}: {error}): '
                  f'/flexbe_synthesis offers {FALLBACK_TYPE} instead')
        return FlexBESynthesisInterface(FlexBESynthesis, FlexBESynthesisRequest, SynthesisErrorCode,
                                        StateInstantiation, OutcomeCondition, fallback_reason=reason)
    return FlexBESynthesisInterface(FlexBESynthesis, FlexBESynthesisRequest, SynthesisErrorCode,
                                    CnuState, CnuCondition)
