"""CNU's example pairs, read from CNU's own test (flexbe_synthesis_examples/test/test_synthesis_example_pairs.py).

Each pair is a launch of CNU's synthesis server (capability, spec, mappings and processes
pipeline files) with one request client's defaults (``request_*.py``) and the state count CNU
expects. Both are read from the pinned snapshot's source text (``ast``: importing them needs
CNU's ROS packages), so the pairs, the requests and the counts are CNU's, unchanged. A pair
becomes a system file of ours that points at the same files, as a user would write it.

CNU's count is ``len(result.states)``: every StateInstantiation, the root container and the
``:OUTCOME`` entries included (coffee 4 = root + 3 states; vending 6 = root + 4 states + finished).
"""

from __future__ import annotations

import ast
from dataclasses import dataclass
from pathlib import Path

PAIRS_TEST = 'flexbe_synthesis_examples/test/test_synthesis_example_pairs.py'
# CNU's processes pipelines -> ours (the "parsed" ones differ in CNU's activation encoding only).
PIPELINES = {'capability_processes_def.yaml': 'capabilities', 'capability_processes_def_parsed.yaml': 'capabilities',
             'full_spec_processes_def.yaml': 'full_spec'}


@dataclass(frozen=True)
class ExamplePair:
    launch: str               # CNU's launch file: the pair's name
    system: str               # the request's system_name: the name of our system file for it
    files: dict               # our system file's keys -> absolute paths (and cnu_pipeline)
    request: dict             # CNU's request defaults: initial_conditions, goals, outcomes, system_name, spec_name
    cnu_state_count: int      # CNU's expected len(result.states)


def example_pairs(cnu: Path) -> list[ExamplePair]:
    """All pairs of CNU's test, in its order (``cnu``: the flexbe_synthesis snapshot)."""
    tree = ast.parse((cnu / PAIRS_TEST).read_text())
    requests = {alias.asname: _request_defaults(cnu, node.module.rsplit('.', 1)[1])
                for node in tree.body if isinstance(node, ast.ImportFrom) and node.module
                and node.module.startswith('flexbe_synthesis_examples.request_') for alias in node.names}
    (pairs,) = [node.value for node in tree.body if isinstance(node, ast.Assign)
                and any(getattr(t, 'id', '') == 'EXAMPLE_PAIRS' for t in node.targets)]
    examples = cnu / 'flexbe_synthesis_examples' / 'example'
    mappings = cnu / 'flexbe_synthesis_generic' / 'mappings'
    result = []
    for call in pairs.elts:
        launch = ast.literal_eval(call.args[0])
        params = call.args[1]
        count = next(ast.literal_eval(k.value) for k in call.keywords if k.arg == 'expected_state_count')
        request = requests[call.args[2].id]
        if params.func.id == '_hello_world_server_params':
            files = _hello_world_files(cnu, tree, examples, mappings)
        else:
            demo, capabilities, spec, processes, mapping = (ast.literal_eval(a) for a in params.args)
            files = {'cnu_capabilities': examples / demo / 'capabilities' / capabilities,
                     'cnu_spec': examples / demo / 'specs' / spec, 'cnu_mappings': mappings / mapping,
                     'cnu_pipeline': PIPELINES[processes]}
        result.append(ExamplePair(launch, request['system_name'], files, request, count))
    return result


def write_system_file(config_dir: Path, pair: ExamplePair) -> Path:
    """Our system file for ``pair`` in ``config_dir`` (one folder per pair: as CNU's launches,
    several pairs serve the same system name)."""
    config_dir.mkdir(parents=True, exist_ok=True)
    path = config_dir / f'{pair.system}.yaml'
    lines = [f'system: {pair.system}'] + [f'{key}: {value}' for key, value in pair.files.items()]
    path.write_text('\n'.join(lines) + '\n')
    return path


def _request_defaults(cnu: Path, module: str) -> dict:
    source = cnu / 'flexbe_synthesis_examples' / 'flexbe_synthesis_examples' / f'{module}.py'
    tree = ast.parse(source.read_text())
    (value,) = [node.value for node in tree.body if isinstance(node, ast.Assign)
                and any(getattr(t, 'id', '') == '_DEFAULTS' for t in node.targets)]
    return ast.literal_eval(value)


def _hello_world_files(cnu: Path, tree: ast.Module, examples: Path, mappings: Path) -> dict:
    """hello_world's server parameters: its capabilities, its given machine (``automaton_path``)
    and the global mappings, read from CNU's ``_hello_world_server_params``."""
    (function,) = [node for node in tree.body if isinstance(node, ast.FunctionDef)
                   and node.name == '_hello_world_server_params']
    (returned,) = [node.value for node in ast.walk(function) if isinstance(node, ast.Return)]
    params = {}
    for key, value in zip(returned.keys, returned.values):
        if isinstance(value, ast.Call) and value.func.id == '_example_path':
            params[ast.literal_eval(key)] = examples.joinpath(*(ast.literal_eval(a) for a in value.args))
        elif isinstance(value, ast.Call) and value.func.id == '_generic_mapping_path':
            params[ast.literal_eval(key)] = mappings / ast.literal_eval(value.args[0])
    return {'cnu_capabilities': params['capabilities_path'], 'cnu_state_machine': params['automaton_path'],
            'cnu_mappings': params['global_mappings_path']}
