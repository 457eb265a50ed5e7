"""The errors of sm_generation: one class per SynthesisErrorCodes constant it reports.

Each names the offending state, proposition, file or configuration key in ``item``.
"""

from __future__ import annotations

from respec.vocabulary.errors import CodedError, ErrorCode


class SMGenerationError(CodedError):
    """State-machine generation failed (the base of this package's errors)."""

    code = ErrorCode.SM_GENERATION_FAILED


class NoSystemConfigError(SMGenerationError):
    """The system has no configuration file."""

    code = ErrorCode.NO_SYSTEM_CONFIG


class SystemConfigNotFoundError(SMGenerationError):
    """The configuration directory does not exist."""

    code = ErrorCode.SYSTEM_CONFIG_NOT_FOUND


class FlexBEConfigInvalidError(SMGenerationError):
    """The ``flexbe:`` section (or its file) is malformed."""

    code = ErrorCode.CONFIG_FILE_INVALID


class AutonomyConfigInvalidError(SMGenerationError):
    code = ErrorCode.CONFIG_AUTONOMY_INVALID


class StateConfigInvalidError(SMGenerationError):
    """A state entry (class, parameters, output mapping) is invalid or missing."""

    code = ErrorCode.CONFIG_VARIABLE_CONFIG_INVALID


class UserdataConfigInvalidError(SMGenerationError):
    code = ErrorCode.CONFIG_USERDATA_INVALID


class AutomatonInvalidError(SMGenerationError):
    code = ErrorCode.AUTOMATON_INVALID


class NoInitialStateError(SMGenerationError):
    code = ErrorCode.AUTOMATON_NO_INITIAL_STATE


class NextStateInvalidError(SMGenerationError):
    code = ErrorCode.AUTOMATON_NEXT_STATE_INVALID


class InputValuationInvalidError(SMGenerationError):
    code = ErrorCode.AUTOMATON_INPUT_VALUATION_INVALID


class OutputValuationInvalidError(SMGenerationError):
    code = ErrorCode.AUTOMATON_OUTPUT_VALUATION_INVALID


class InitialConditionsInvalidError(SMGenerationError):
    code = ErrorCode.INVALID_INITIAL_CONDITIONS
