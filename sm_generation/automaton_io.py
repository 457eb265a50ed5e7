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
from typing import Any

import yaml

from respec.automaton import Automaton, AutomatonState, automaton_from_strategy
from respec.parsing import ParseError, parse_structuredslugs
from respec.untrusted import BoundedYamlError, load_bounded_yaml, read_bounded_file
from sm_generation.errors import AutomatonInvalidError


def automaton_from_dict(data: object, source: str = '<dict>') -> Automaton:
    """Build an Automaton from our file format (already parsed)."""
    if not isinstance(data, dict):
        raise AutomatonInvalidError(f'{source}: expected a mapping', source)
    states: Any = data.get('automaton', data.get('states'))  # checked to be a list below
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


def automaton_to_dict(automaton: Automaton) -> dict[str, Any]:
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
    text = _read_text(path)
    try:
        data = json.loads(text) if path.suffix == '.json' else load_bounded_yaml(text, MAX_AUTOMATON_DEPTH)
    except json.JSONDecodeError as error:
        raise AutomatonInvalidError(f'{path}: not valid JSON: {error}', str(path)) from None
    except RecursionError:
        raise AutomatonInvalidError(f'{path}: JSON nested deeper than an automaton is', str(path)) from None
    except BoundedYamlError as error:
        raise AutomatonInvalidError(f'{path}: {error}', str(path)) from None
    if isinstance(data, dict) and 'nodes' in data and 'variables' in data:
        return _automaton_from_strategy_file(data, path, spec_path)
    return automaton_from_dict(data, str(path))


def _automaton_from_strategy_file(strategy: dict[str, Any], path: Path, spec_path: str | Path | None) -> Automaton:
    if spec_path is None:
        raise AutomatonInvalidError(f'{path} is a slugs strategy: give the '
                                    '.structuredslugs specification it was synthesized from', str(path))
    spec_path = Path(spec_path)
    try:
        spec = parse_structuredslugs(_read_text(spec_path), filename=str(spec_path))
    except ParseError as error:
        raise AutomatonInvalidError(str(error), error.item) from error
    return automaton_from_strategy(strategy, spec)


def dump_automaton(automaton: Automaton) -> str:
    """Our YAML text for ``automaton`` (deterministic)."""
    return yaml.safe_dump(automaton_to_dict(automaton), sort_keys=False, default_flow_style=None)


#: The largest automaton or specification file read (a strategy of about 500,000 transitions).
MAX_AUTOMATON_FILE_BYTES = 64 * 2**20
#: An automaton file's nesting (states, their fields, valuations) is a few levels.
MAX_AUTOMATON_DEPTH = 16


def _read_text(path: Path) -> str:
    """The text of an input file within the bounds (``respec.untrusted.read_bounded_file``)."""
    try:
        return read_bounded_file(path, MAX_AUTOMATON_FILE_BYTES)
    except OSError as error:
        raise AutomatonInvalidError(f'cannot read {path}: {error.strerror or error}', str(path)) from None
    except UnicodeDecodeError as error:
        raise AutomatonInvalidError(f'{path}: not UTF-8 text (byte {error.start})', str(path)) from None
