"""YAML / JSON / DOT exports, rendering with Graphviz, and the generate-sm command line."""

import json
from pathlib import Path

import pytest

from sm_generation import generate_state_machine, load_automaton
from sm_generation import export
from sm_generation.state_machine import StateMachine
from sm_generation.cli import main
from sm_generation.export import RenderError, from_text, render, to_dot, to_json, to_yaml
from respec.robot import robot_system

AUTOMATA = Path(__file__).resolve().parents[1] / 'automata'


@pytest.fixture(scope='module')
def concurrent():
    return generate_state_machine(load_automaton(AUTOMATA / 'concurrent.yaml'), robot_system('atlas'))


def test_yaml_and_json_round_trip(concurrent):
    assert from_text(to_yaml(concurrent)) == concurrent.to_instantiations()
    assert from_text(to_json(concurrent)) == concurrent.to_instantiations()
    entries = json.loads(to_json(concurrent))
    assert all(len(entry) == 16 for entry in entries)
    assert entries[0]['state_path'] == '/'


def test_dot_draws_states_containers_outcomes_and_start(concurrent):
    dot = to_dot(concurrent)
    assert dot.startswith('digraph state_machine {') and dot.rstrip().endswith('}')
    assert '"outcome:finished" [id="outcome:finished", class="outcome", label="finished"' in dot
    container = next(line for line in dot.splitlines() if line.startswith('  "state:object_template_and_stand"'))
    # the container box holds its states and shows its own outcomes along the bottom
    assert '(concurrency container)' in container and '<B>object_template</B>' in container
    assert 'PORT="o0"' in container and '>object_template_c__stand_c<' in container
    assert '"start" -> "state:object_template_and_stand":n [id="edge:start", label=" initial"];' in dot
    assert to_dot(concurrent) == dot


def test_dot_merges_parallel_transitions_into_one_outcome_cell_and_arrow(concurrent):
    dot = to_dot(concurrent)
    pregrasp_pose = next(s for s in concurrent.walk() if s.name == 'pregrasp_pose')
    assert pregrasp_pose.transitions.count('failed') == 2  # 'failed' and 'not_available'
    assert '>failed, not_available<' in dot
    arrows = [line for line in dot.splitlines() if line.startswith('  "state:pregrasp_pose":')]
    # coloured by autonomy as in the FlexBE editor (done: Low, the failures: Off), failures dashed
    assert arrows == ['  "state:pregrasp_pose":o0:s -> "outcome:finished" [id="edge:pregrasp_pose->finished", '
                      'class="autonomy-low", color="#5466d8"];',
                      '  "state:pregrasp_pose":o1:s -> "outcome:failed" [id="edge:pregrasp_pose->failed", '
                      'class="autonomy-off", color="#7d7d70", style=dashed];']
    assert pregrasp_pose.autonomy == [1, 0, 0]


TWELVE_GOALS = ['look_down', 'approach_object', 'pregrasp', 'grasp_object', 'pickup_object',
                'footstep_execution', 'object_template', 'pregrasp_pose', 'footstep_plan', 'target_pose',
                'pregrasp_plan', 'footstep_goal']


@pytest.fixture(scope='module')
def twelve_goals():
    from ltl_specification import compile_task
    from ltl_synthesizer import synthesize
    from respec.automaton import automaton_from_strategy

    spec = compile_task(robot_system('atlas'), ['stand_prep'], TWELVE_GOALS)
    automaton = automaton_from_strategy(synthesize(spec).strategy, spec)
    return generate_state_machine(automaton, robot_system('atlas'), initial_conditions=['stand_prep'])


@pytest.mark.external
def test_a_long_machine_wraps_its_main_path_into_columns_with_a_failure_rail(twelve_goals, tmp_path):
    import re
    import xml.etree.ElementTree as ET

    dot = to_dot(twelve_goals)
    top = list(twelve_goals.states)
    assert len(top) > export.WRAP_AFTER
    columns = export._grid(top, twelve_goals.initial_state_name)
    assert len(columns) >= 3 and columns[0][0] == twelve_goals.initial_state_name
    assert sorted(sum(columns, [])) == sorted(s.name for s in top)  # every state once
    # one failure outcome per column, no dashed arrow funnelling into one node
    failed_nodes = re.findall(r'^    "(outcome:failed(?::\d+)?)" \[', dot, flags=re.M)
    assert failed_nodes == ['outcome:failed'] + [f'outcome:failed:{c}' for c in range(1, len(columns))]
    assert 'style=dashed' not in dot and '-> "outcome:failed' not in dot.split('{ rank=sink;')[0]
    assert '>aborted,<BR/>no_connection,<BR/>data_error<' in dot  # long outcome cells wrap
    # the path goes on in the next column through a connector, not an arrow around the grid
    for left, right in zip(columns, columns[1:]):
        assert f'id="continue:{left[-1]}->{right[0]}"' in dot and f'label="→ {right[0]}"' in dot
    # laid out wider than tall, about a page: readable at Fit on a desktop screen
    svg = ET.parse(render(dot, tmp_path / 'twelve.svg')).getroot()
    _, _, width, height = (float(v) for v in svg.get('viewBox').split())
    assert width < 1100 and height < 900 and width > height, (width, height)


def test_dot_labels_behaviours_and_escapes_quotes():
    states = generate_state_machine(load_automaton(AUTOMATA / 'two_behaviors.yaml'), robot_system('atlas')).to_instantiations()
    states[2].state_path = '/say "hi"'
    states[1].transitions = ['say "hi"', 'failed']
    dot = to_dot(StateMachine.from_instantiations(states))
    assert '[Grasp Object]' in dot
    assert '"state:say \\"hi\\""' in dot and '<B>say &quot;hi&quot;</B>' in dot


@pytest.mark.external
@pytest.mark.parametrize('fmt, magic', [('svg', b'<svg'), ('png', b'\x89PNG')])
def test_render(concurrent, tmp_path, fmt, magic):
    path = render(to_dot(concurrent), tmp_path / f'machine.{fmt}')
    assert magic in path.read_bytes()[:400]


def test_render_without_graphviz(concurrent, tmp_path, monkeypatch):
    monkeypatch.setattr(export.shutil, 'which', lambda name: None)
    with pytest.raises(RenderError, match='apt-get install graphviz') as caught:
        render(to_dot(concurrent), tmp_path / 'machine.svg')
    assert caught.value.item == 'dot'


def test_render_rejects_other_formats(concurrent, tmp_path):
    with pytest.raises(RenderError, match='pdf'):
        render(to_dot(concurrent), tmp_path / 'machine.pdf')


def test_cli_writes_yaml_to_stdout(capsys):
    assert main(['--system', 'atlas', '--automaton', str(AUTOMATA / 'look_down.yaml')]) == 0
    out = capsys.readouterr().out
    assert from_text(out) == generate_state_machine(load_automaton(AUTOMATA / 'look_down.yaml'), robot_system('atlas')).to_instantiations()


@pytest.mark.external
def test_cli_formats_from_suffix_and_flag(tmp_path):
    automaton = str(AUTOMATA / 'sensors.yaml')
    assert main(['--automaton', automaton, '-o', str(tmp_path / 'm.json'), '--reduce']) == 0
    assert json.loads((tmp_path / 'm.json').read_text())[0]['state_path'] == '/'
    assert main(['--automaton', automaton, '--format', 'dot', '-o', str(tmp_path / 'm.txt')]) == 0
    assert (tmp_path / 'm.txt').read_text().startswith('digraph')
    assert main(['--automaton', automaton, '-o', str(tmp_path / 'm.svg')]) == 0  # needs Graphviz
    assert b'<svg' in (tmp_path / 'm.svg').read_bytes()


def test_cli_initial_conditions(capsys):
    assert main(['--automaton', str(AUTOMATA / 'no_initial_states.yaml'), '--initial-conditions', 'stand']) == 0
    assert from_text(capsys.readouterr().out)[0].initial_state_name == 'look_down'


def test_cli_reports_errors(capsys):
    assert main(['--automaton', str(AUTOMATA / 'invalid' / 'bad_next_state.yaml')]) == 1
    err = capsys.readouterr().err
    assert 'AUTOMATON_NEXT_STATE_INVALID' in err and "'7'" in err
    assert main(['--automaton', str(AUTOMATA / 'look_down.yaml'), '--format', 'svg']) == 2
    assert 'needs -o' in capsys.readouterr().err


def test_cli_subcommand_of_behavior_synthesis(tmp_path):
    from synthesis_manager.programs.cli import main as suite_main
    out = tmp_path / 'm.yaml'
    assert suite_main(['generate-sm', '--system', 'atlas', '--automaton', str(AUTOMATA / 'look_down.yaml'),
                       '-o', str(out)]) == 0
    assert from_text(out.read_text())[0].initial_state_name == 'stand'
