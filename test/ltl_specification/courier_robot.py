"""A capability robot of our own in CNU's format, the courier: it picks a parcel into a bin,
then delivers it; with the one state class (LogState) its capabilities use."""

from pathlib import Path

import yaml

from respec.robot.state_library import StateClass

LIBRARY = {'LogState': StateClass('LogState', 'flexbe_states', ('text',), ('text',), outcomes=('done',))}

# A courier of our own: it picks a parcel into a bin, then delivers it.
COURIER = {
    'name': 'courier',
    'variable_mappings': {'sys_props': {'bin': {0: 'none', 1: 'left', 2: 'right'}}},
    'memory': {'sys_props': {'parcel_m': False, 'signature_m': False}},
    'capabilities': {
        'pick': {'interface': 'LogState', 'parameters': {'text': 'picking'}, 'preconditions': ['!parcel'],
                 'postconditions': ['parcel', 'bin=1']},
        'deliver': {'interface': 'LogState', 'parameters': {'text': 'delivering'}, 'preconditions': ['parcel'],
                    'postconditions': ['deliver', '!parcel']},
    },
}


def courier(config_dir: Path, spec: dict | None = None, **capabilities) -> Path:
    """The courier's files in ``config_dir``, with ``capabilities`` added to its own."""
    files = {**COURIER, 'capabilities': {**COURIER['capabilities'], **capabilities}}
    (config_dir / 'courier_capabilities.yaml').write_text(yaml.safe_dump(files))
    system = ['system: courier', 'cnu_capabilities: courier_capabilities.yaml']
    if spec is not None:
        (config_dir / 'courier_spec.yaml').write_text(yaml.safe_dump({'specs': spec}))
        system.append('cnu_spec: courier_spec.yaml')
    (config_dir / 'courier.yaml').write_text('\n'.join(system) + '\n')
    return config_dir
