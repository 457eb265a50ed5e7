"""A synthesis result with the counter-strategy too, for tests that check both sides of a game."""

from ltl_synthesizer import SynthesisResult, counter_strategy, explain, explicit_strategy, solve


def synthesize_with_counterstrategy(spec, robotics_semantics: bool = True) -> SynthesisResult:
    """As ``ltl_synthesizer.synthesize``, plus the counter-strategy of an unrealizable ``spec``
    (both made from one solved game, as ``gr1synth --counterStrategy --explain`` does)."""
    solved = solve(spec, robotics_semantics)
    if solved.realizable:
        return SynthesisResult(True, strategy=explicit_strategy(solved))
    return SynthesisResult(False, counterstrategy=counter_strategy(solved), explanation=explain(solved))
