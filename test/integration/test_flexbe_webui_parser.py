"""The FlexBE editor reads our behaviors: the WebUI's own code parser (FLEXBE_SOURCES) on them.

When the WebUI's behavior dashboard opens a behavior, the page parses its Python file with
``IO.CodeParser.parseCode`` (flexbe_webui/app/io/io_codeparser.js) and builds the editor's
model from that reading. These tests run that parser, unmodified, in headless Chromium on the
behavior ``export-behavior`` writes and on atlas_sim's behaviors, and compare its reading
with the state machine: names, classes, transitions, autonomy levels, userdata, containers
and their conditions, positions, and no parser warning.
"""

from pathlib import Path

import pytest

from ltl_specification import compile_task
from ltl_synthesizer import synthesize
from respec.automaton import automaton_from_strategy
from sm_generation import generate_state_machine, load_automaton
from respec.robot import robot_system
from sm_generation.config import flexbe_config
from sm_generation.flexbe_behavior import AUTONOMY_NAMES, behavior_package

import headless_chromium

ROOT = Path(__file__).resolve().parents[2]
AUTOMATA = ROOT / 'test' / 'automata'

pytestmark = [pytest.mark.usefixtures('flexbe'), pytest.mark.browser, pytest.mark.flexbe]

PARSER_SCRIPTS = ('prototype.js', 'io/io.js', 'io/io_codeparser.js')
# The page's terminal, as the parser uses it; warnings are collected.
TERMINAL = "window.warnings = []; window.T = {logInfo() {}, logWarn(m) { warnings.push(m); }, " \
           "logError(m) { warnings.push(m); }};"
PARSE = """code => { window.warnings = [];
    const result = IO.CodeParser.parseCode(code);
    return {result: JSON.parse(JSON.stringify(result)), warnings: window.warnings}; }"""


@pytest.fixture(scope='module')
def parser(flexbe_sources):
    from playwright.sync_api import sync_playwright

    app = flexbe_sources / 'flexbe_webui' / 'flexbe_webui' / 'app'
    with sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=headless_chromium.EXECUTABLE, headless=True,
                                             args=headless_chromium.ARGUMENTS)
        page = browser.new_page()
        errors = []
        page.on('pageerror', lambda error: errors.append(str(error)))
        page.set_content('<html><body></body></html>')
        page.evaluate(TERMINAL)
        for script in PARSER_SCRIPTS:
            page.add_script_tag(path=str(app / script))
        yield lambda code: page.evaluate(PARSE, code)
        browser.close()
        assert errors == []


def reading_of(parsed):
    """container variable -> {state name: parsed state} from the parser's result."""
    return {part['sm_name']: {s['state_name']: s for s in part['sm_states']} for part in parsed['sm_states']}


@pytest.mark.parametrize('automaton', ['concurrent.yaml', 'two_behaviors.yaml'])
def test_the_editor_parser_reads_an_exported_behavior_as_generated(parser, automaton):
    machine = generate_state_machine(load_automaton(AUTOMATA / automaton), robot_system('atlas'))
    package = behavior_package(machine, flexbe_config(robot_system('atlas')), 'Parsed Behavior')
    states = machine.to_instantiations()
    answer = parser(package.files[f'{package.package}/{package.module}.py'])
    assert answer['warnings'] == []
    parsed = answer['result']
    assert parsed['behavior_name'] == 'Parsed Behavior' and parsed['root_sm_name'] == '_state_machine'
    assert parsed['smi_outcomes'] == states[0].outcomes
    assert {d['key'] for d in parsed['default_userdata']} == {k for s in states for k in s.userdata_remapping}
    reading = reading_of(parsed)
    definitions = {d['sm_name']: d for d in parsed['sm_defs']}
    containers = {s.state_path: s for s in states if s.state_class == ':CONCURRENCY'}
    for state in states:
        if state.state_class in (':STATEMACHINE', ':OUTCOME'):
            continue
        parent = containers.get(state.parent_path)
        variable = '_state_machine' if parent is None else \
            next(name for name, d in definitions.items() if d['sm_type'] == 'concurrency'
                 and d['sm_params']['outcomes'] == parent.outcomes)
        seen = reading[variable][state.name]
        assert [(t['outcome'], t['target']) for t in seen['transitions_from']] == \
            list(zip(state.outcomes, state.transitions))
        assert [(a['key'], a['value']) for a in seen['autonomy']] == list(zip(state.outcomes, state.autonomy))
        assert [(r['key'], r['value']) for r in seen['remapping'] if r['value']] == \
            list(zip(state.userdata_keys, state.userdata_remapping)) or state.state_class == ':CONCURRENCY'
        assert (seen['state_pos_x'], seen['state_pos_y']) == tuple(round(v) for v in state.position)
        if state.state_class == ':BEHAVIOR':
            assert seen['state_type'] == 'behavior'
        elif state.state_class != ':CONCURRENCY':
            # the editor qualifies a class with the package it is imported from
            package = flexbe_config(robot_system('atlas')).state_package(state.state_class) or 'flexbe_states'
            assert seen['state_class'] == f'{package}__{state.state_class}'
            assert [(p['key'], p['value']) for p in seen['parameter_values']] == \
                list(zip(state.parameter_names, state.parameter_values))
    for path, container in containers.items():
        definition = next(d for d in parsed['sm_defs'] if d['sm_type'] == 'concurrency'
                          and d['sm_params']['outcomes'] == container.outcomes)
        conditions = definition['sm_params']['conditions']
        assert conditions['outcomes'] == container.cond_outcome
        assert conditions['transitions'] == [[list(pair) for pair in zip(c.state_name, c.state_outcome)]
                                             for c in container.cond_transition]


def test_the_editor_parser_reads_the_paper_task_and_atlas_sim_behaviors(parser):
    spec = compile_task(robot_system('atlas'), ['stand_prep'], ['look_down', 'pickup_object'])
    automaton = automaton_from_strategy(synthesize(spec).strategy, spec)
    machine = generate_state_machine(automaton, robot_system('atlas'), initial_conditions=['stand_prep'])
    package = behavior_package(machine, flexbe_config(robot_system('atlas')), 'Look Down Pickup Object')
    states = machine.to_instantiations()
    answer = parser(package.files[f'{package.package}/{package.module}.py'])
    assert answer['warnings'] == []
    top = [s.name for s in states if s.parent_path == '/' and s.state_class != ':OUTCOME']
    assert sorted(reading_of(answer['result'])['_state_machine']) == sorted(top)
    folder = ROOT / 'atlas_sim' / 'flexbe' / 'atlas_sim_flexbe_behaviors' / 'atlas_sim_flexbe_behaviors'
    for source in sorted(folder.glob('*_sm.py')):
        answer = parser(source.read_text())
        assert answer['warnings'] == [], source.name
        assert answer['result']['smi_outcomes'] == ['finished', 'failed']
    assert set(AUTONOMY_NAMES) == {0, 1, 2, 3}
