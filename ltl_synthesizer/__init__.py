"""A GR(1) synthesizer on CUDD (``dd.cudd``) speaking slugs' formats (ROS-free).

    from ltl_synthesizer import synthesize
    result = synthesize(spec)            # spec: respec.spec.GR1Specification
    result.realizable, result.strategy   # slugs --explicitStrategy --jsonOutput shape

Modules: symbolic (formulas to BDDs, enforceable predecessors), gr1 (fixpoints), strategy
(explicit strategies, counter-strategies, slugs JSON), explain (why unrealizable), unrealizable_core
(minimal unrealizable subsets of guarantees, by delta debugging), automaton (FSAutomaton shape),
cli (``gr1synth``).
"""

from ltl_synthesizer.errors import (InvalidFormulaError, SynthesisCancelled, SynthesisError,
                                    UnknownPropositionError)
from ltl_synthesizer.symbolic import Options
from ltl_synthesizer.synthesizer import SynthesisResult, synthesize

__all__ = ['synthesize', 'SynthesisResult', 'SynthesisCancelled', 'SynthesisError',
           'UnknownPropositionError', 'InvalidFormulaError', 'Options']
