"""Specification compilation: size and time per task (prints a table; not a test).

    python bench/bench_ltl_specification.py [--synthesize]

With --synthesize it also times ltl_synthesizer.synthesize on each compiled specification.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from ltl_specification import compile_task
from respec.spec import FORMULA_SECTIONS
from respec.robot import robot_system

TASKS = [
    ('demo 1 (strict)', 'atlas', ['stand_prep'], ['look_down', 'pickup_object'], ('finished', 'failed'), True),
    ('demo 1 (unordered)', 'atlas', ['stand_prep'], ['look_down', 'pickup_object'], ('finished', 'failed'), False),
    ('demo 1 (retry)', 'atlas', ['stand_prep'], ['look_down', 'pickup_object'], ('finished',), True),
    ('demo 2 footstep', 'atlas', ['manipulate'], ['footstep_execution'], ('finished', 'failed'), True),
    ('demo 2 (retry)', 'atlas', ['manipulate'], ['footstep_execution'], ('finished',), True),
    ('walk', 'atlas', ['stand_prep'], ['walk'], ('finished', 'failed'), True),
    ('step', 'atlas', ['stand_prep'], ['step'], ('finished', 'failed'), True),
    ('pickup, walk', 'atlas', ['stand_prep'], ['pickup_object', 'walk'], ('finished', 'failed'), True),
    ('mm grasp, place', 'mobile_manipulator', [], ['grasp', 'place'], ('finished', 'failed'), True),
    ('mm navigate (retry)', 'mobile_manipulator', [], ['navigate', 'detect_object'], ('finished',), True),
]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    parser.add_argument('--synthesize', action='store_true')
    parser.add_argument('--repeat', type=int, default=20)
    args = parser.parse_args()
    print(f'{"task":22} {"env":>4} {"sys":>4} {"formulas":>8} {"compile ms":>10}'
          + (f' {"synth s":>8} {"real.":>5}' if args.synthesize else ''))
    for name, system, initial, goals, sm_outcomes, strict in TASKS:
        start = time.perf_counter()
        for _ in range(args.repeat):
            spec = compile_task(robot_system(system), initial, goals, sm_outcomes=sm_outcomes, strict_order=strict)
        compile_ms = (time.perf_counter() - start) / args.repeat * 1000
        formulas = sum(len(getattr(spec, s)) for s in FORMULA_SECTIONS)
        line = f'{name:22} {len(spec.env_props):4} {len(spec.sys_props):4} {formulas:8} {compile_ms:10.2f}'
        if args.synthesize:
            from ltl_synthesizer import synthesize
            start = time.perf_counter()
            result = synthesize(spec)
            line += f' {time.perf_counter() - start:8.2f} {"yes" if result.realizable else "NO":>5}'
        print(line, flush=True)


if __name__ == '__main__':
    main()
