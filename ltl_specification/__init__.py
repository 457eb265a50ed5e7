"""Compile robot tasks (initial conditions, goals) into GR(1) LTL specifications (ROS-free).

    >>> from respec.robot import robot_system
    >>> spec = compile_task(robot_system('atlas'), ['stand_prep'], ['look_down', 'pickup_object'])
    >>> print(spec.to_structuredslugs())     # or to_slugsin(), to_text_sections()

``ltl_specification.diagnosis`` says in plain words why a task cannot be done, from the
specification and its ``provenance`` alone (``ltl_specification.provenance``, which also
carries it as JSON).

The ATLAS paper's encoding lives here: ``activation_outcomes`` (one function per formula
family, equations (3)-(20)) and ``components`` (the sub-specifications made of them, in
FormulaGroups: the provenance of every formula).
"""

from ltl_specification.compiler import CompiledSpecification, compile_task, explain
from ltl_specification.errors import (
    InvalidAbstractionError, InvalidFormulaError, InvalidGoalsError, InvalidInitialConditionsError,
    InvalidSmOutcomesError, SpecificationError, UnknownPropositionError, UnknownSystemError,
)
from ltl_specification.pertinence import Pertinence, infer_pertinence
from ltl_specification.provenance import Provenance

__all__ = [
    'compile_task', 'explain', 'CompiledSpecification', 'Provenance', 'Pertinence', 'infer_pertinence',
    'SpecificationError', 'UnknownSystemError', 'InvalidAbstractionError', 'InvalidInitialConditionsError',
    'InvalidGoalsError', 'InvalidSmOutcomesError', 'InvalidFormulaError', 'UnknownPropositionError',
]
