"""The one exception of sm_generation, carrying a SynthesisErrorCodes constant name."""

from __future__ import annotations

from respec.errors import CodedError

# The SynthesisErrorCodes constants this package reports (name -> value, for reference).
ERROR_CODES = {
    'SM_GENERATION_FAILED': -30,
    'NO_SYSTEM_CONFIG': -32,
    'SYSTEM_CONFIG_NOT_FOUND': -33,
    'CONFIG_FILE_INVALID': -34,
    'CONFIG_AUTONOMY_INVALID': -35,
    'CONFIG_VARIABLE_CONFIG_INVALID': -36,
    'AUTOMATON_INVALID': -37,
    'AUTOMATON_NO_INITIAL_STATE': -38,
    'AUTOMATON_NEXT_STATE_INVALID': -39,
    'AUTOMATON_INPUT_VALUATION_INVALID': -40,
    'AUTOMATON_OUTPUT_VALUATION_INVALID': -41,
    'CONFIG_USERDATA_INVALID': -42,
    'INVALID_INITIAL_CONDITIONS': -13,
}


class SMGenerationError(CodedError):
    """State-machine generation failed.

    ``code`` is the name of a synthesis_msgs/SynthesisErrorCodes constant and ``item``
    names the offending state, proposition, file or configuration key.
    """

    def __init__(self, code: str, message: str, item: str = ''):
        if code not in ERROR_CODES:
            raise ValueError(f'unknown error code {code!r}')
        super().__init__(message, item)
        self.code = code
        self.message = message

    @property
    def value(self) -> int:
        """The numeric SynthesisErrorCodes value of ``code``."""
        return ERROR_CODES[self.code]
