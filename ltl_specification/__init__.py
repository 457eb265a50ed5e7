"""Compile robot tasks (initial conditions, goals) into GR(1) LTL specifications (ROS-free).

    >>> spec = compile_task('atlas', ['stand_prep'], ['look_down', 'pickup_object'])
    >>> print(spec.to_structuredslugs())     # or to_slugsin(), to_text_sections()

``ltl_specification.diagnosis`` says in plain words why a task cannot be done.
"""

from ltl_specification.compiler import CompiledSpecification, Provenance, compile_task, explain
from ltl_specification.errors import (
    InvalidAbstractionError, InvalidFormulaError, InvalidGoalsError, InvalidInitialConditionsError,
    InvalidSmOutcomesError, SpecificationError, UnknownPropositionError, UnknownSystemError,
)
from ltl_specification.pertinence import Pertinence, infer_pertinence

__all__ = [
    'compile_task', 'explain', 'CompiledSpecification', 'Provenance', 'Pertinence', 'infer_pertinence',
    'SpecificationError', 'UnknownSystemError', 'InvalidAbstractionError', 'InvalidInitialConditionsError',
    'InvalidGoalsError', 'InvalidSmOutcomesError', 'InvalidFormulaError', 'UnknownPropositionError',
]
