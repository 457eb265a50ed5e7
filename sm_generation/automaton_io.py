"""Reading automata from files: our YAML/JSON format, or a slugs strategy plus its spec.

Our format mirrors the FSAutomaton message (``automaton`` may also be spelled ``states``)::

    output_variables: [stand_a, look_down_a, finished, failed]
    input_variables: [stand_prep_c, stand_c, stand_f, look_down_c, look_down_f]
    initial_states: ['0']            # optional; empty means "deduce them"
    automaton:
      - {name: '0', output_valuation: [0, 0, 0, 0], input_valuation: [1, 0, 0, 0, 0],
         transitions: ['1'], rank: 0}
"""

from __future__ import annotations

import json
from pathlib import Path

import yaml

from respec.automaton import Automaton, AutomatonState, automaton_from_strategy
from respec.parsing import ParseError, parse_structuredslugs
from sm_generation.errors import AutomatonInvalidError


def automaton_from_dict(data: dict, source: str = '<dict>') -> Automaton:
    """Build an Automaton from our file format (already parsed)."""
    if not isinstance(data, dict):
        raise AutomatonInvalidError(f'{source}: expected a mapping', source)
    states = data.get('automaton', data.get('states'))
    for key, value in (('output_variables', data.get('output_variables')),
                       ('input_variables', data.get('input_variables')),
                       ('automaton', states)):
        if not isinstance(value, list):
            raise AutomatonInvalidError(f'{source}: {key!r} must be a list', key)
    parsed = []
    for index, entry in enumerate(states):
        if not isinstance(entry, dict) or 'name' not in entry:
            raise AutomatonInvalidError(f'{source}: state #{index} needs a name',
                                        f'automaton[{index}]')
        parsed.append(AutomatonState(
            name=str(entry['name']),
            output_valuation=list(entry.get('output_valuation', [])),
            input_valuation=list(entry.get('input_valuation', [])),
            transitions=[str(t) for t in entry.get('transitions', [])],
            rank=int(entry.get('rank', 0))))
    return Automaton(output_variables=[str(v) for v in data['output_variables']],
                     input_variables=[str(v) for v in data['input_variables']],
                     states=parsed,
                     initial_states=[str(s) for s in data.get('initial_states') or []])


def automaton_to_dict(automaton: Automaton) -> dict:
    """Our file format for ``automaton`` (valuations as 0/1)."""
    return {
        'output_variables': list(automaton.output_variables),
        'input_variables': list(automaton.input_variables),
        'initial_states': list(automaton.initial_states),
        'automaton': [{'name': s.name,
                       'output_valuation': [int(bool(v)) for v in s.output_valuation],
                       'input_valuation': [int(bool(v)) for v in s.input_valuation],
                       'transitions': list(s.transitions), 'rank': int(s.rank)}
                      for s in automaton.states],
    }


def load_automaton(path: str | Path, spec_path: str | Path | None = None) -> Automaton:
    """Load an automaton from our YAML/JSON file, or from a slugs JSON strategy.

    A slugs strategy names its variables but not which are inputs, so it needs the
    ``.structuredslugs`` specification it was synthesized from (``spec_path``).
    """
    path = Path(path)
    try:
        text = path.read_text()
    except OSError as error:
        raise AutomatonInvalidError(f'cannot read {path}: {error}', str(path)) from error
    try:
        data = json.loads(text) if path.suffix == '.json' else yaml.safe_load(text)
    except (json.JSONDecodeError, yaml.YAMLError) as error:
        raise AutomatonInvalidError(f'{path}: not valid YAML/JSON: {error}',
                                    str(path)) from error
    if isinstance(data, dict) and 'nodes' in data and 'variables' in data:
        return _automaton_from_strategy_file(data, path, spec_path)
    return automaton_from_dict(data, str(path))


def _automaton_from_strategy_file(strategy: dict, path: Path, spec_path) -> Automaton:
    if spec_path is None:
        raise AutomatonInvalidError(f'{path} is a slugs strategy: give the '
                                    '.structuredslugs specification it was synthesized from', str(path))
    spec_path = Path(spec_path)
    try:
        spec = parse_structuredslugs(spec_path.read_text(), filename=str(spec_path))
    except OSError as error:
        raise AutomatonInvalidError(f'cannot read {spec_path}: {error}',
                                    str(spec_path)) from error
    except ParseError as error:
        raise AutomatonInvalidError(str(error), error.item) from error
    return automaton_from_strategy(strategy, spec)


def dump_automaton(automaton: Automaton) -> str:
    """Our YAML text for ``automaton`` (deterministic)."""
    return yaml.safe_dump(automaton_to_dict(automaton), sort_keys=False, default_flow_style=None)
