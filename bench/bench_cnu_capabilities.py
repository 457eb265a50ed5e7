"""CNU's capability examples and our ATLAS tasks: state counts before/after reduction, synthesis time.

    FLEXBE_SOURCES=../shared/third_party python bench/bench_cnu_capabilities.py [--markdown FILE]

For each CNU example (their request defaults, run through our pipeline from a system file
pointing at their files): specification size, synthesis time (best of 3), strategy nodes,
machine states without and with our reduction, and the post-reduction count CNU's own test
(test_synthesis_example_pairs.py) expects. ATLAS tasks show what the reduction does on our
own systems. State classes come from the FlexBE packages under AMENT_PREFIX_PATH (default:
the venv's ``flexbe`` prefix that ``make flexbe`` writes).
"""

from __future__ import annotations

import argparse
import os
import shutil
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from ltl_specification import compile_task
from ltl_synthesizer import synthesize
from respec.automaton import automaton_from_strategy
from respec.robot.state_library import workspace_state_library
from sm_generation import generate_state_machine
from respec.robot import robot_system

# name: (capabilities, spec, mappings, initial conditions, goals, CNU's expected post-reduction count)
CNU_EXAMPLES = {
    'coffee_maker': ('coffee_maker/capabilities/coffee_capabilities.yaml',
                     'coffee_maker/specs/coffee_demo_capabilities_spec.yaml', 'infinite_mappings.yaml',
                     ['bd_a'], ['br_c'], 4),
    'coffee_maker_extended': ('coffee_maker/capabilities/coffee_capabilities_extended.yaml',
                              'coffee_maker/specs/coffee_demo_capabilities_spec.yaml', 'infinite_mappings.yaml',
                              ['bd_a'], ['br_c'], 4),
    'vending_demo': ('vending_demo/capabilities/vending_capabilities.yaml',
                     'vending_demo/specs/vending_demo_capabilities_spec.yaml', 'global_mappings.yaml',
                     ['prep_pay_a'], ['soda'], 6),
    'vending_demo_extended': ('vending_demo/capabilities/vending_capabilities_extended.yaml',
                              'vending_demo/specs/vending_demo_capabilities_spec.yaml', 'global_mappings.yaml',
                              ['prep_pay_a'], ['soda'], 6),
    'hello_world': ('hello_world/capabilities/hello_world_capabilities.yaml', None, 'global_mappings.yaml',
                    [], ['say_world'], 4),
}
ATLAS_TASKS = [
    (['stand_prep'], ['look_down', 'pickup_object']),
    (['manipulate'], ['footstep_execution']),
    (['stand_prep'], ['look_down', 'pregrasp', 'grasp_object']),
]


def top_level(machine) -> int:
    return len(machine.states)


def measure(system, initial_conditions, goals, library=None, repeat=3):
    spec = compile_task(system, initial_conditions, goals, state_library=library)
    best, result = float('inf'), None
    for _ in range(repeat):
        start = time.perf_counter()
        result = synthesize(spec)
        best = min(best, time.perf_counter() - start)
    automaton = automaton_from_strategy(result.strategy, spec)
    plain = generate_state_machine(automaton, system, initial_conditions=initial_conditions,
                                   state_library=library)
    reduced = generate_state_machine(automaton, system, initial_conditions=initial_conditions,
                                     reduce=True, state_library=library)
    return (len(spec.env_props), len(spec.sys_props), best, len(result.strategy['nodes']), top_level(plain),
            top_level(reduced))


def write_cnu_systems(config_dir: Path, cnu: Path) -> None:
    """A system file per example in ``config_dir``, with CNU's files copied beside it (a system
    file's references must stay inside its config folder)."""
    examples = cnu / 'flexbe_synthesis_examples' / 'example'

    def beside(source: Path) -> str:
        relative = source.relative_to(cnu)
        (config_dir / 'cnu' / relative).parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(source, config_dir / 'cnu' / relative)
        return f'cnu/{relative.as_posix()}'

    for name, (capabilities, spec, mappings, *_rest) in CNU_EXAMPLES.items():
        lines = [f'system: {name}', f'cnu_capabilities: {beside(examples / capabilities)}',
                 f'cnu_mappings: {beside(cnu / "flexbe_synthesis_generic" / "mappings" / mappings)}']
        if spec:
            lines.append(f'cnu_spec: {beside(examples / spec)}')
        # Reduction is measured both ways here, so the system's own default stays off.
        lines.append('reduce: false')
        (config_dir / f'{name}.yaml').write_text('\n'.join(lines) + '\n')


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--markdown', help='also write the table to this file')
    args = parser.parse_args()
    sources = Path(os.environ.get('FLEXBE_SOURCES', ROOT.parent / 'shared' / 'third_party'))
    prefixes = os.environ.get('AMENT_PREFIX_PATH') or str(Path(sys.prefix) / 'flexbe')
    library = workspace_state_library(prefixes)
    header = ('| task | env / sys props | synthesis (ms) | strategy nodes | states | states reduced | CNU (reduced) |\n'
              '|---|---|---|---|---|---|---|')
    rows = []
    with tempfile.TemporaryDirectory() as directory:
        write_cnu_systems(Path(directory), sources / 'flexbe_synthesis')
        for name, (*_files, initial_conditions, goals, cnu_count) in CNU_EXAMPLES.items():
            env, sys_, seconds, nodes, plain, reduced = measure(robot_system(name, directory), initial_conditions,
                                                                goals, library)
            rows.append(f'| CNU {name}: {",".join(initial_conditions) or "-"} -> {",".join(goals)} | {env} / {sys_} | '
                        f'{seconds * 1000:.1f} | {nodes} | {plain} | {reduced} | {cnu_count} |')
    for initial_conditions, goals in ATLAS_TASKS:
        env, sys_, seconds, nodes, plain, reduced = measure(robot_system('atlas'), initial_conditions, goals)
        rows.append(f'| atlas: {",".join(initial_conditions)} -> {",".join(goals)} | {env} / {sys_} | '
                    f'{seconds * 1000:.1f} | {nodes} | {plain} | {reduced} | - |')
    table = '\n'.join([header, *rows])
    print(table)
    if args.markdown:
        Path(args.markdown).write_text(
            '# CNU capability examples and ATLAS tasks: state counts and synthesis time\n\n'
            'Written by `bench/bench_cnu_capabilities.py` (our builtin GR(1) synthesizer, best of 3; '
            '"states": top-level FlexBE states of the generated machine; "CNU": the post-reduction '
            "count CNU's `test_synthesis_example_pairs.py` expects from their slugs pipeline; CNU "
            'publishes no synthesis times). CNU\'s hello_world is a fixed machine in their examples; '
            'here it is synthesized with the goal `say_world`.\n\n' + table + '\n')


if __name__ == '__main__':
    main()
