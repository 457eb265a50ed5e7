"""The errors of sm_generation: one class per SynthesisErrorCodes constant it reports.

Each names the offending state, proposition, file or configuration key in ``item``.
"""

from __future__ import annotations

from respec.errors import CodedError


class SMGenerationError(CodedError):
    """State-machine generation failed (the base of this package's errors)."""

    code = 'SM_GENERATION_FAILED'


class NoSystemConfigError(SMGenerationError):
    """The system has no configuration file."""

    code = 'NO_SYSTEM_CONFIG'


class SystemConfigNotFoundError(SMGenerationError):
    """The configuration directory does not exist."""

    code = 'SYSTEM_CONFIG_NOT_FOUND'


class FlexBEConfigInvalidError(SMGenerationError):
    """The ``flexbe:`` section (or its file) is malformed."""

    code = 'CONFIG_FILE_INVALID'


class AutonomyConfigInvalidError(SMGenerationError):
    code = 'CONFIG_AUTONOMY_INVALID'


class StateConfigInvalidError(SMGenerationError):
    """A state entry (class, parameters, output mapping) is invalid or missing."""

    code = 'CONFIG_VARIABLE_CONFIG_INVALID'


class UserdataConfigInvalidError(SMGenerationError):
    code = 'CONFIG_USERDATA_INVALID'


class AutomatonInvalidError(SMGenerationError):
    code = 'AUTOMATON_INVALID'


class NoInitialStateError(SMGenerationError):
    code = 'AUTOMATON_NO_INITIAL_STATE'


class NextStateInvalidError(SMGenerationError):
    code = 'AUTOMATON_NEXT_STATE_INVALID'


class InputValuationInvalidError(SMGenerationError):
    code = 'AUTOMATON_INPUT_VALUATION_INVALID'


class OutputValuationInvalidError(SMGenerationError):
    code = 'AUTOMATON_OUTPUT_VALUATION_INVALID'


class InitialConditionsInvalidError(SMGenerationError):
    code = 'INVALID_INITIAL_CONDITIONS'
