"""Errors of specification compilation.

Every error carries ``item`` (the offending system, goal, initial condition, outcome,
formula or proposition) and ``code``, the name of the synthesis_msgs/SynthesisErrorCodes
constant that reports it.
"""

from __future__ import annotations

from typing import Protocol

from respec.vocabulary.errors import CodedError, ErrorCode


class Explained(Protocol):
    """A refusal's whole explanation (``ltl_specification.diagnosis.Diagnosis``, which imports
    this module: named by what the error needs of it)."""

    def message(self) -> str: ...


class SpecificationError(CodedError):
    """Compiling a task specification failed; ``item`` names what was wrong."""

    code = ErrorCode.LTL_SPEC_COMPILATION_FAILED


class UnknownSystemError(SpecificationError):
    """No configuration file exists for the requested system."""

    code = ErrorCode.UNKNOWN_SYSTEM


class InvalidAbstractionError(SpecificationError):
    """The system's configuration file or its ``abstraction:`` section is invalid."""

    code = ErrorCode.ABSTRACTION_CONFIG_INVALID


class InvalidInitialConditionsError(SpecificationError):
    """An initial condition is unknown, or the initial control mode is missing or ambiguous."""

    code = ErrorCode.INVALID_INITIAL_CONDITIONS


class InvalidGoalsError(SpecificationError):
    """No goals, an unknown or repeated goal, or a goal that cannot be reached."""

    code = ErrorCode.INVALID_GOALS


class ImpossibleGoalsError(InvalidGoalsError):
    """A goal the configured mode changes can never reach, refused before synthesis with the
    whole ``diagnosis`` (``ltl_specification.diagnosis.Diagnosis``: sentence, core, play) as its
    message, so the refusal tells what synthesis would have told."""

    def __init__(self, message: str, item: str = '', diagnosis: Explained | None = None) -> None:
        super().__init__(message, item)
        self.diagnosis = diagnosis


class InvalidSmOutcomesError(SpecificationError):
    """The requested state-machine outcomes are not [finished, failed] or [finished]."""

    code = ErrorCode.INVALID_SM_OUTCOMES


class InvalidFormulaError(SpecificationError):
    """A custom LTL formula does not parse or does not fit its GR(1) section."""

    code = ErrorCode.INVALID_FORMULA


class UnknownPropositionError(SpecificationError):
    """A custom LTL formula names a proposition that the task does not define."""

    code = ErrorCode.UNKNOWN_PROPOSITION
