"""The pipeline of one capability-robot request, in a fresh process: bench_capability_scale.py's
"pipeline" column (what export-behavior / the synthesis node does for the request: compile the
task, synthesize with robotics semantics and the explicit strategy, the well-separation check on
the solved game, the automaton, the FlexBE machine), printing its stages as JSON.

    python bench/pipeline_child.py CONFIG_DIR SHAPE N SLUGSIN [RUNS]

A module of its own, so that the measured process loads what the pipeline needs and not the
bench's harness (subprocess, tempfile, argparse: 0.01 s of CPU in a fresh process).
"""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def warm_synthesis_script(clock: str) -> str:
    """A ``python -c`` script: gr1synth's answer to its command line (``sys.argv[1:]``) by the
    resident mode, asked three times in one process; prints the faster of the second and third
    answers' ``time.<clock>()`` seconds and the last answer's stderr as JSON."""
    return f'''
import json, sys, time
from ltl_synthesizer.serve import answer
request = json.dumps(sys.argv[1:])
answer(request)
seconds = []
for _ in range(2):
    start = time.{clock}()
    reply = answer(request)
    seconds.append(time.{clock}() - start)
print(json.dumps({{'warm_seconds': min(seconds), 'stderr': reply['stderr']}}))
'''
sys.path[:0] = [str(ROOT), str(ROOT / 'bench')]

import capability_robots
from respec.robot import robot_system

MEMORY_LIMIT = 2 * 2**30


def pipeline_child(config_dir: str, shape: str, size: int, slugsin: str, runs: int = 1,
                   clock=time.perf_counter) -> None:
    """The pipeline of one request (run in a fresh process): prints its stages as JSON. With
    ``runs`` > 1 the same request is answered that many times in the process, and the seconds
    of the fastest answer after the first are printed too as ``warm_seconds`` (a long-running
    server's cost of a request, its imports done). ``clock``: what the seconds are read from
    (``time.process_time``: the CPU time of the process)."""
    from ltl_specification import compile_task
    from ltl_specification.diagnosis import explain_well_separation
    from ltl_synthesizer.interrupt import Limits
    from ltl_synthesizer.synthesizer import solve, synthesis_result
    from respec.automaton import automaton_from_strategy
    from sm_generation import generate_state_machine

    robot = capability_robots.SHAPES[shape](size)

    def answer() -> tuple[dict, float]:
        """One request's stages and seconds; what it built is released when it returns (as a
        server releases a request's game before the next, instead of solving beside it)."""
        stages = {}
        start = clock()
        spec = compile_task(robot_system(robot.name, config_dir), robot.initial_conditions, robot.goals,
                            sm_outcomes=capability_robots.REQUEST_OUTCOMES,
                            state_library=capability_robots.STATE_LIBRARY)
        text = spec.to_slugsin()
        stages['compile'] = clock() - start
        Path(slugsin).write_text(text)
        mark, began = clock(), time.perf_counter()
        solved = solve(spec, True, Limits(memory_limit=MEMORY_LIMIT))
        result = synthesis_result(solved, None, began)
        stages['synthesize'] = clock() - mark
        report = {'realizable': result.realizable, 'env': len(spec.env_props), 'sys': len(spec.sys_props),
                  'strategy_nodes': result.stats.get('strategy_nodes', 0)}
        if result.realizable:
            mark = clock()
            # On the solved game, as the synthesis node's child checks it (isolated.synthesize_then_check).
            explain_well_separation(spec, None, Limits(memory_limit=MEMORY_LIMIT), solved.game)
            stages['well_separation'] = clock() - mark
            mark = clock()
            automaton = automaton_from_strategy(result.strategy, spec)
            states = generate_state_machine(automaton, robot_system(robot.name, config_dir),
                                            state_library=capability_robots.STATE_LIBRARY)
            stages['generate'] = clock() - mark
            report['machine_states'] = len(states.to_instantiations())
            Path(slugsin + '.strategy.json').write_text(json.dumps(result.strategy))
        report['stages'] = stages
        return report, clock() - start

    warm = []
    for _ in range(runs):
        report, seconds = answer()
        warm.append(seconds)
    if runs > 1:
        report['warm_seconds'] = min(warm[1:])
    print(json.dumps(report))

if __name__ == '__main__':
    pipeline_child(sys.argv[1], sys.argv[2], int(sys.argv[3]), sys.argv[4], int(sys.argv[5]) if len(sys.argv) > 5 else 1)
