"""The Python names the page needs, served once (``GET /api/vocabulary``) so that app.js keeps no
copies of them: state classes, autonomy levels, result codes, the machine's outcomes, the
specification's sections.

Each entry is built from the constant that defines it (sm_generation.instantiation,
sm_generation.export, respec.vocabulary.errors, respec.vocabulary.naming, respec.spec,
ltl_specification.repair); only the page's own words (section titles) are written here.
"""

from __future__ import annotations

from ltl_specification.repair import REPAIRABLE
from respec.vocabulary.errors import ErrorCode
from respec.vocabulary.naming import FAILED, FINISHED
from respec.spec import SECTIONS
from sm_generation.export import AUTONOMY_NAMES
from sm_generation.instantiation import StateInstantiation
from synthesis_manager.web.errors import NotFoundError

#: The system the page selects first when the server offers it (the paper's humanoid).
PREFERRED_SYSTEM = 'atlas'

#: What the page calls each section of a specification (respec.spec.SECTIONS, in that order).
SECTION_TITLES = dict(zip(SECTIONS, (
    'Environment propositions (inputs)', 'System propositions (outputs)',
    'Environment initial conditions', 'System initial conditions',
    'Environment safety', 'System safety',
    'Environment liveness', 'System liveness'), strict=True))


def vocabulary() -> dict:
    """The JSON of ``GET /api/vocabulary`` (documented in docs/gui.md)."""
    return {
        'state_classes': {'state_machine': StateInstantiation.CLASS_STATEMACHINE,
                          'concurrency': StateInstantiation.CLASS_CONCURRENCY,
                          'priority': StateInstantiation.CLASS_PRIORITY,
                          'behavior': StateInstantiation.CLASS_BEHAVIOR,
                          'outcome': StateInstantiation.CLASS_OUTCOME},
        'autonomy_levels': list(AUTONOMY_NAMES),
        'error_codes': {code.value: code.number for code in ErrorCode},
        'job_results': {'succeeded': ErrorCode.SUCCESS.value, 'cancelled': ErrorCode.PREEMPTED.value},
        'request_errors': {'not_found': NotFoundError.kind},
        'sm_outcomes': {'finished': FINISHED, 'failed': FAILED},
        'specification_sections': [{'name': name, 'title': title} for name, title in SECTION_TITLES.items()],
        'preferred_system': PREFERRED_SYSTEM,
        'repairable': sorted(REPAIRABLE),
    }
