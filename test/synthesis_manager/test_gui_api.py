"""The web GUI's JSON API against the real pipeline (suite in-process), without a browser."""

import json

import pytest
import yaml
from fastapi.testclient import TestClient

from gui_jobs import PAPER_TASK, follow, follow_simulation, gui_args, run_job
from synthesis_manager.programs.gui import ros_backend
from synthesis_manager.web.routes import create_app

pytestmark = pytest.mark.ros

STATE_FIELDS = {'state_path', 'state_class', 'initial_state_name', 'input_keys', 'output_keys',
                'cond_outcome', 'cond_transition', 'behavior_class', 'parameter_names',
                'parameter_values', 'position', 'outcomes', 'transitions', 'autonomy',
                'userdata_keys', 'userdata_remapping'}


def test_systems_and_their_choices(client):
    assert 'atlas' in client.get('/api/systems').json()['systems']
    choices = client.get('/api/systems/atlas').json()
    modes = {m['name']: m['next'] for m in choices['control_modes']}
    actions = {a['name']: a['preconditions'] for a in choices['actions']}
    assert modes['stand_prep'] == ['stand'] and 'walk' in modes['stand']
    assert actions['pickup_object'] == ['object_template', 'manipulate']
    assert 'look_down' in actions
    assert choices['default_initial_conditions'] == ['stand_prep']


def test_paper_task_succeeds_with_progress_states_and_downloads(client):
    progress, job = run_job(client, PAPER_TASK)
    assert job['outcome']['error_name'] == 'SUCCESS', job['outcome']['message']
    statuses = [entry['status'] for entry in job['timeline']]
    assert any(s.startswith('Compiling') for s in statuses)
    assert any(s.startswith('Synthesiz') for s in statuses)
    values = [entry['progress'] for entry in job['timeline']]
    assert values == sorted(values) and values[-1] == pytest.approx(1.0)
    assert progress and progress[0]['state'] in ('queued', 'running')

    summary = job['summary']
    assert summary['realizable'] is True
    assert summary['automaton_states'] == len(job['outcome']['automaton']['states']) > 0
    assert summary['input_propositions'] == len(job['outcome']['ltl_specification']['env_props'])
    names = {s['state_path'].rsplit('/', 1)[-1] for s in job['outcome']['states']}
    assert {'look_down', 'pickup_object', 'stand', 'manipulate'} <= names
    # one count everywhere: without the root and the machine's outcomes, as the timeline says
    states = [s for s in job['outcome']['states'] if s['state_path'] != '/' and s['state_class'] != ':OUTCOME']
    assert summary['state_machine_states'] == len(states)
    assert job['timeline'][-1]['status'] == f'Generated a state machine with {len(states)} states'

    base = f"/api/jobs/{job['id']}/artifacts"
    listing = yaml.safe_load(client.get(f'{base}/state_machine.yaml').text)
    assert listing == job['outcome']['states']
    assert all(set(entry) == STATE_FIELDS for entry in listing)
    assert json.loads(client.get(f'{base}/state_machine.json').text) == listing
    download = client.get(f'{base}/state_machine.yaml')
    assert download.headers['content-disposition'].startswith('attachment')

    from respec.parsing import parse_slugsin, parse_structuredslugs

    sections = job['outcome']['ltl_specification']
    structured = client.get(f'{base}/specification.structuredslugs').text
    assert parse_structuredslugs(structured).to_text_sections() == sections
    slugsin = client.get(f'{base}/specification.slugsin').text
    assert parse_structuredslugs(structured).to_slugsin() == slugsin  # the two files agree
    assert parse_slugsin(slugsin).sys_props == sections['sys_props']

    svg = client.get(f'{base}/state_machine.svg?inline=1')
    assert svg.headers['content-type'].startswith('image/svg+xml')
    assert svg.headers['content-disposition'].startswith('inline')
    assert all(name in svg.text for name in ('look_down', 'pickup_object', 'finished', 'failed'))
    assert client.get(f'{base}/state_machine.png').content.startswith(b'\x89PNG')

    import io
    import zipfile

    download = client.get(f'{base}/flexbe_behavior.zip')
    # saved under the behavior's name (issue 35: it was behavior_flexbe_behavior.zip)
    assert download.headers['content-disposition'] == \
        'attachment; filename="look_down_pickup_object_flexbe_behavior.zip"'
    behavior = zipfile.ZipFile(io.BytesIO(download.content))
    names = behavior.namelist()  # the package export-behavior writes, behavior named after the goals
    assert 'synthesized_flexbe_behaviors/manifest/look_down_pickup_object.xml' in names
    code = behavior.read('synthesized_flexbe_behaviors/synthesized_flexbe_behaviors/look_down_pickup_object_sm.py')
    assert b'class LookDownPickupObjectSM(Behavior):' in code
    assert b"self.use_behavior(PickupObjectSM, 'pickup_object')" in code


@pytest.mark.flexbe
def test_a_capability_system_exports_its_behavior_package_for_download(tmp_path, flexbe, flexbe_sources, monkeypatch):
    """CNU's vending_demo from a config folder of the user's (added to the shipped systems):
    its job offers the FlexBE behavior package export-behavior writes, with CNU's state classes."""
    import io
    import zipfile

    monkeypatch.setenv('AMENT_PREFIX_PATH', str(flexbe))  # the workspace's state classes
    cnu = flexbe_sources / 'flexbe_synthesis'
    example = cnu / 'flexbe_synthesis_examples' / 'example' / 'vending_demo'
    config = tmp_path / 'config'
    config.mkdir()
    (config / 'vending_demo.yaml').write_text(
        f'cnu_capabilities: {example}/capabilities/vending_capabilities.yaml\n'
        f'cnu_spec: {example}/specs/vending_demo_capabilities_spec.yaml\n'
        f'cnu_mappings: {cnu}/flexbe_synthesis_generic/mappings/global_mappings.yaml\n')
    with ros_backend(gui_args(tmp_path / 'byproducts', '--config-dir', str(config))) as backend, \
            TestClient(create_app(backend)) as client:
        assert {'atlas', 'vending_demo'} <= set(client.get('/api/systems').json()['systems'])
        _, job = run_job(client, {'system': 'vending_demo', 'initial_conditions': ['prep_pay_a'], 'goals': ['soda']})
        assert job['outcome']['error_name'] == 'SUCCESS', job['outcome']['message']
        assert 'flexbe_behavior.zip' in job['artifacts']
        download = client.get(f"/api/jobs/{job['id']}/artifacts/flexbe_behavior.zip")
        assert download.status_code == 200, download.text
    behavior = zipfile.ZipFile(io.BytesIO(download.content))
    assert 'synthesized_flexbe_behaviors/manifest/soda.xml' in behavior.namelist()
    code = behavior.read('synthesized_flexbe_behaviors/synthesized_flexbe_behaviors/soda_sm.py').decode()
    assert 'class SodaSM(Behavior):' in code and 'from flexbe_states.log_state import LogState' in code
    assert "text='Insert Coin'" in code


def test_same_request_gives_byte_identical_downloads(client):
    first = run_job(client, PAPER_TASK)[1]
    second = run_job(client, PAPER_TASK)[1]
    for name in ('state_machine.yaml', 'specification.slugsin'):
        assert (client.get(f"/api/jobs/{first['id']}/artifacts/{name}").content
                == client.get(f"/api/jobs/{second['id']}/artifacts/{name}").content)


def test_compile_only_has_a_specification_and_no_state_machine(client):
    _, job = run_job(client, {**PAPER_TASK, 'option': 'ltl_compilation_only'})
    assert job['outcome']['error_name'] == 'SUCCESS'
    assert job['summary']['realizable'] is None and job['summary']['formulas'] > 0
    assert 'specification.slugsin' in job['artifacts'] and 'state_machine.yaml' not in job['artifacts']
    missing = client.get(f"/api/jobs/{job['id']}/artifacts/state_machine.yaml")
    assert missing.status_code == 409 and missing.json()['item'] == 'state_machine.yaml'


def test_pipeline_errors_come_back_with_their_message(client):
    _, unknown = run_job(client, {**PAPER_TASK, 'goals': ['look_down', 'fly']})
    assert unknown['state'] == 'finished'
    assert unknown['outcome']['error_name'] in ('INVALID_GOALS', 'UNKNOWN_PROPOSITION')
    assert "'fly'" in unknown['outcome']['message']
    assert unknown['artifacts'] == ['result.json']

    _, two_modes = run_job(client, {**PAPER_TASK, 'initial_conditions': ['stand_prep', 'walk']})
    assert two_modes['outcome']['error_name'] == 'INVALID_INITIAL_CONDITIONS'
    assert 'walk' in two_modes['outcome']['message']


@pytest.mark.parametrize('request_body, status, item', [
    ({**PAPER_TASK, 'system': 'nao'}, 404, 'nao'),
    ({**PAPER_TASK, 'goals': []}, 422, 'goals'),
    ({**PAPER_TASK, 'goals': ' , '}, 422, 'goals'),
    ({**PAPER_TASK, 'goal': 'look_down'}, 422, 'goal'),
    ({**PAPER_TASK, 'option': 'ltl_synthesis_only'}, 422, 'ltl_synthesis_only'),
    ({**PAPER_TASK, 'name': '../etc'}, 422, '../etc'),
    ({**PAPER_TASK, 'initial_conditions': ['stand prep!']}, 422, 'prep!'),
    (['look_down'], 422, 'body'),
])
def test_bad_requests_are_4xx_naming_the_item(client, request_body, status, item):
    response = client.post('/api/jobs', json=request_body)
    assert response.status_code == status
    assert response.json()['item'] == item
    assert item in response.json()['message'] or item == 'body'


def test_unknown_names_in_urls_are_404_and_the_server_keeps_serving(client):
    for path, item in (('/api/systems/nao', 'nao'), ('/api/jobs/no-such-job', 'no-such-job'),
                       ('/api/jobs/no-such-job/artifacts/state_machine.yaml', 'no-such-job')):
        response = client.get(path)
        assert response.status_code == 404 and response.json()['item'] == item
    assert client.post('/api/jobs/no-such-job/cancel', json={}).status_code == 404
    _, job = run_job(client, {**PAPER_TASK, 'option': 'ltl_compilation_only'})
    wrong = client.get(f"/api/jobs/{job['id']}/artifacts/state_machine.gif")
    assert wrong.status_code == 404 and wrong.json()['item'] == 'state_machine.gif'
    again = client.post(f"/api/jobs/{job['id']}/cancel", json={})
    assert again.status_code == 409 and 'already finished' in again.json()['message']
    assert client.get('/api/systems').status_code == 200


def test_cancel_a_job_before_it_is_sent(client, backend):
    backend.jobs.gate.clear()  # hold new jobs in the queue
    try:
        job = client.post('/api/jobs', json=PAPER_TASK).json()
        assert client.get(f"/api/jobs/{job['id']}").json()['state'] == 'queued'
        assert client.post(f"/api/jobs/{job['id']}/cancel", json={}).status_code == 202
        _, final = follow(client, job['id'])
    finally:
        backend.jobs.gate.set()
    assert final['outcome']['error_name'] == 'PREEMPTED'
    # nothing reached the pipeline: the timeline holds only the cancel
    assert [entry['status'] for entry in final['timeline']] == ['Cancel requested', 'Cancelled']


def test_cancel_a_running_synthesis(client, runaway_synthesis):
    job = client.post('/api/jobs', json=PAPER_TASK).json()
    with client.stream('GET', f"/api/jobs/{job['id']}/events", timeout=120) as response:
        for line in response.iter_lines():
            if line.startswith('data: ') and 'Synthesizing' in json.loads(line[6:])['status']:
                break
    assert client.post(f"/api/jobs/{job['id']}/cancel", json={}).json()['cancel_requested'] is True
    _, final = follow(client, job['id'])
    assert final['outcome']['error_name'] == 'PREEMPTED'
    assert final['outcome']['seconds'] < 30


# Not 2x faster (issue 50): a synthesis and two simulations, with and without a fault (3.9 s).
def test_simulate_the_synthesized_machine_with_and_without_a_fault(client, backend):
    assert client.get('/api/info').json()['simulation'] is True
    _, job = run_job(client, PAPER_TASK)
    started = client.post(f"/api/jobs/{job['id']}/simulations", json={})
    assert started.status_code == 202
    run = follow_simulation(client, started.json()['id'])
    assert run['state'] == 'finished' and run['error'] is None
    assert run['outcome'] == 'finished' and run['check']['ok'] is True
    assert [step['state'] for step in run['steps']][-1] == '/pickup_object'
    assert len(run['frames']) >= 2
    base = f"/api/simulations/{run['id']}"
    assert client.get(f'{base}/frames/0').content.startswith(b'\x89PNG')
    assert client.get(f'{base}/timeline.png').content.startswith(b'\x89PNG')

    faulty = client.post(f"/api/jobs/{job['id']}/simulations", json={'fail_first': ['pickup_object']}).json()
    run = follow_simulation(client, faulty['id'])
    assert run['outcome'] == 'failed' and run['check']['ok'] is True
    assert any(r == {**r, 'capability': 'pickup_object', 'outcome': 'failed'}
               for step in run['steps'] for r in step['results'])


@pytest.mark.mujoco  # the simulation runs in this process
def test_a_simulation_runs_the_system_the_gui_was_served_not_a_local_file(tmp_path):
    """A GUI attached to a suite elsewhere simulates the suite's system: the child rebuilds it
    from the files the GUI holds (here a variant of ATLAS whose walk always fails, under a
    name no local file has)."""
    from ltl_specification import compile_task
    from ltl_synthesizer import synthesize
    from respec.automaton import automaton_from_strategy
    from respec.robot import robot_system, robot_system_from_files
    from sm_generation import generate_state_machine
    from synthesis_manager.web.simulation_process import simulate

    document = yaml.safe_load(robot_system('atlas').files['atlas.yaml'])
    document['simulation']['faults'] = {'walk': {'always': True}}
    files = {'served_atlas.yaml': yaml.safe_dump(document, sort_keys=False)}
    served = robot_system_from_files('served_atlas', files, 'suite/served_atlas.yaml')
    spec = compile_task(served, ['stand_prep'], ['walk'])
    machine = generate_state_machine(automaton_from_strategy(synthesize(spec).strategy, spec), served,
                                     initial_conditions=['stand_prep'])
    final = simulate({'machine': machine, 'ltl_specification': spec.to_text_sections(),
                      'system': served.name, 'files': dict(served.files), 'config_file': served.config_file,
                      'initial_conditions': ['stand_prep'], 'goals': ['walk'], 'ordered': True, 'fail_first': [],
                      'record_dir': str(tmp_path), 'max_robot_time': 300.0, 'max_wall_time': 300.0},
                     lambda update: None)
    assert 'error' not in final, final['error']
    assert final['result']['outcome'] == 'failed' and final['result']['check']['ok'] is True


def test_bad_simulation_requests_name_the_item(client):
    _, compiled = run_job(client, {**PAPER_TASK, 'option': 'ltl_compilation_only'})
    no_machine = client.post(f"/api/jobs/{compiled['id']}/simulations", json={})
    assert no_machine.status_code == 409 and no_machine.json()['item'] == compiled['id']
    wrong_field = client.post(f"/api/jobs/{compiled['id']}/simulations", json={'faults': 'x'})
    assert wrong_field.status_code == 422 and wrong_field.json()['item'] == 'faults'
    assert client.post('/api/jobs/no-such-job/simulations', json={}).status_code == 404
    unknown = client.get('/api/simulations/no-such-run')
    assert unknown.status_code == 404 and unknown.json()['item'] == 'no-such-run'


def test_goal_check_names_impossible_goals_and_refuses_bad_input(client):
    check = client.post('/api/goal-check', json={'system': 'atlas', 'initial_conditions': [],
                                                 'goals': ['look_down', 'stand_prep']}).json()
    assert [f['item'] for f in check['findings']] == ['stand_prep']
    assert 'stand -> stand_prep is not a transition in config/atlas.yaml' in check['findings'][0]['sentence']
    assert check['impossible_next'] == {}  # every other item can still come next
    unknown = client.post('/api/goal-check', json={'system': 'r2d2', 'goals': []})
    assert unknown.status_code == 404 and unknown.json()['item'] == 'r2d2'
    assert client.post('/api/goal-check', json=['atlas']).status_code == 422


def test_choices_say_whether_the_humanoid_can_simulate_the_system(client):
    assert client.get('/api/systems/atlas').json()['simulation']['available'] is True
    mobile = client.get('/api/systems/mobile_manipulator').json()['simulation']
    assert mobile['available'] is False and 'does not model the mobile manipulator' in mobile['note']


def test_a_forgotten_download_is_json_for_programs_and_a_page_for_browsers(client):
    url = '/api/jobs/1-0000dead/artifacts/state_machine.yaml'
    assert client.get(url).json()['error'] == 'NOT_FOUND'
    page = client.get(url, headers={'accept': 'text/html,application/xhtml+xml'})
    assert page.status_code == 404 and 'This download is no longer available' in page.text


def test_vocabulary_is_served_from_the_python_constants(client):
    from respec.spec import SECTIONS
    from sm_generation.export import AUTONOMY_NAMES
    from sm_generation.instantiation import StateInstantiation

    names = client.get('/api/vocabulary').json()
    assert names['state_classes']['outcome'] == StateInstantiation.CLASS_OUTCOME
    assert names['state_classes']['concurrency'] == StateInstantiation.CLASS_CONCURRENCY
    assert names['autonomy_levels'] == list(AUTONOMY_NAMES)
    assert names['job_results'] == {'succeeded': 'SUCCESS', 'cancelled': 'PREEMPTED'}
    assert names['error_codes']['SPEC_UNSYNTHESIZABLE'] == -21
    assert [section['name'] for section in names['specification_sections']] == list(SECTIONS)
    assert names['sm_outcomes'] == {'finished': 'finished', 'failed': 'failed'}


def walk(node):
    """The tree's nodes, parents first."""
    yield node
    for child in node['children']:
        yield from walk(child)


def test_the_state_machine_is_served_as_a_tree_of_the_listed_states(client):
    _, job = run_job(client, PAPER_TASK)
    tree = client.get(f"/api/jobs/{job['id']}/state-machine").json()
    assert tree['name'] == '/' and tree['state_path'] == '/'
    flat = [{key: value for key, value in node.items() if key not in ('name', 'children')} for node in walk(tree)]
    assert sorted(flat, key=lambda s: s['state_path']) == sorted(job['outcome']['states'], key=lambda s: s['state_path'])
    kinds = [child['state_class'] == ':OUTCOME' for child in tree['children']]
    assert kinds == sorted(kinds) and kinds[-2:] == [True, True]  # the states, then the machine's outcomes
    assert all(node['name'] == node['state_path'].rsplit('/', 1)[-1] for node in walk(tree) if node is not tree)

    _, compiled = run_job(client, {**PAPER_TASK, 'option': 'ltl_compilation_only'})
    missing = client.get(f"/api/jobs/{compiled['id']}/state-machine")
    assert missing.status_code == 409 and missing.json()['item'] == compiled['id']


def test_drawings_and_plays_read_the_tree_the_job_holds_without_rebuilding_it(client, backend, monkeypatch):
    """The result's list becomes the tree once, when it arrives; drawings and play steps reuse it."""
    from sm_generation.state_machine import StateMachine

    _, job = run_job(client, PAPER_TASK)
    held = backend.jobs.job(job['id']).outcome.machine
    builds = []
    real = StateMachine.from_instantiations.__func__
    monkeypatch.setattr(StateMachine, 'from_instantiations',
                        classmethod(lambda cls, states: builds.append(len(states)) or real(cls, states)))
    first = client.get(f"/api/jobs/{job['id']}/state-machine").json()
    assert client.get(f"/api/jobs/{job['id']}/state-machine").json() == first == held.to_dict()
    start = client.post(f"/api/jobs/{job['id']}/play", json={'moves': []}).json()
    step = client.post(f"/api/jobs/{job['id']}/play", json={'moves': [start['outcomes'][0]]})
    assert step.status_code == 200, step.text
    assert backend.jobs.state_machine(job['id']) is held
    assert builds == []


def test_the_page_is_es_modules_served_as_javascript(client):
    from synthesis_manager.web.routes import STATIC_DIR

    assert '<script type="module" src="/static/app.js"></script>' in client.get('/').text
    modules = sorted(path.name for path in STATIC_DIR.glob('*.js'))
    assert 'app.js' in modules and 'drawing.js' in modules
    for name in modules:
        response = client.get(f'/static/{name}')
        assert response.status_code == 200 and response.headers['content-type'].startswith('text/javascript')


def test_the_page_keeps_no_copies_of_the_served_vocabulary(client):
    from synthesis_manager.web.routes import STATIC_DIR

    names = client.get('/api/vocabulary').json()
    served = [*names['state_classes'].values(), *names['autonomy_levels'], *names['error_codes'],
              *(section['name'] for section in names['specification_sections']), names['preferred_system']]
    copies = [f'{path.name}: {name}' for path in sorted(STATIC_DIR.glob('*.js')) for name in served
              for quote in '\'"`' if f'{quote}{name}{quote}' in path.read_text()]
    assert copies == []
