"""System files of ours pointing at CNU's example files (paths relative to them, as users write
them), and a copy of the shipped config/delivery_rover in a user's folder for a variant of it."""

from pathlib import Path

# CNU's example files with CNU's request defaults (flexbe_synthesis_examples/request_*.py), for
# the tests of test_cnu_capabilities.py that look into one machine; all of CNU's pairs run in
# test_all_of_cnus_example_pairs_succeed_with_at_most_cnus_state_count. ``top_level`` bounds the
# machine's own states (the capability states, without the root and the outcomes).
EXAMPLES = {
    'coffee_maker': dict(capabilities='coffee_maker/capabilities/coffee_capabilities.yaml',
                         spec='coffee_maker/specs/coffee_demo_capabilities_spec.yaml', mappings='infinite_mappings.yaml',
                         initial_conditions=['bd_a'], goals=['br_c'], outcomes=[], top_level=3),
    'coffee_maker_extended': dict(capabilities='coffee_maker/capabilities/coffee_capabilities_extended.yaml',
                                  spec='coffee_maker/specs/coffee_demo_capabilities_spec.yaml',
                                  mappings='infinite_mappings.yaml', initial_conditions=['bd_a'], goals=['br_c'],
                                  outcomes=[], top_level=3),
    'vending_demo': dict(capabilities='vending_demo/capabilities/vending_capabilities.yaml',
                         spec='vending_demo/specs/vending_demo_capabilities_spec.yaml', mappings='global_mappings.yaml',
                         initial_conditions=['prep_pay_a'], goals=['soda'], outcomes=['finished'], top_level=4),
    'vending_demo_extended': dict(capabilities='vending_demo/capabilities/vending_capabilities_extended.yaml',
                                  spec='vending_demo/specs/vending_demo_capabilities_spec.yaml',
                                  mappings='global_mappings.yaml', initial_conditions=['prep_pay_a'], goals=['soda'],
                                  outcomes=['finished'], top_level=4),
    # CNU's hello_world pair runs a given machine; here its capabilities are synthesized, for a goal.
    'hello_world': dict(capabilities='hello_world/capabilities/hello_world_capabilities.yaml', spec=None,
                        mappings='global_mappings.yaml', initial_conditions=[], goals=['say_world'],
                        outcomes=['finished'], top_level=2),
}


def write_system(config_dir: Path, name: str, cnu: Path, **entries) -> Path:
    """A system file pointing at CNU's files (paths relative to it, as users write them)."""
    config_dir.mkdir(parents=True, exist_ok=True)
    lines = [f'system: {name}'] + [f'{key}: {value}' for key, value in entries.items() if value is not None]
    path = config_dir / f'{name}.yaml'
    path.write_text('\n'.join(lines) + '\n')
    return path


def example_system(config_dir: Path, cnu: Path, name: str) -> dict:
    example = EXAMPLES[name]
    examples = cnu / 'flexbe_synthesis_examples' / 'example'
    write_system(config_dir, name, cnu,
                 cnu_capabilities=examples / example['capabilities'],
                 cnu_spec=examples / example['spec'] if example['spec'] else None,
                 cnu_mappings=cnu / 'flexbe_synthesis_generic' / 'mappings' / example['mappings'])
    return example


def copied_rover(config_dir: Path) -> Path:
    """The shipped config/delivery_rover copied into ``config_dir`` (a user's folder, which shadows
    config/'s), for a variant of it; returns ``config_dir``."""
    import shutil

    shipped = Path(__file__).resolve().parents[2] / 'config'
    config_dir.mkdir(parents=True, exist_ok=True)
    shutil.copy(shipped / 'delivery_rover.yaml', config_dir / 'delivery_rover.yaml')
    shutil.copytree(shipped / 'delivery_rover', config_dir / 'delivery_rover')
    return config_dir
