"""CNU's own action type on /flexbe_synthesis (flexbe_synthesis_msgs/action/FlexBESynthesis).

With CNU's package built by `make flexbe`, an unmodified rclpy ActionClient of that type gets
the same states as /behavior_synthesis, CNU's error codes and a working cancel. Without it, the
server offers our look-alike type there and says once why.
"""

import sys
import time
from argparse import Namespace

import pytest

from sm_generation.instantiation import OutcomeCondition as CoreCondition, StateInstantiation as CoreState
from synthesis_manager.client import SynthesisClient, make_flexbe_goal, make_goal
from synthesis_manager.ros.cnu_interface import (FALLBACK_TYPE, cnu_error_name, copy_message,
                                                 field_mismatches, load_flexbe_synthesis_interface)
from synthesis_manager.ros.conversions import constants, msg_to_state_dict, state_to_msg
from synthesis_manager.suite import suite_node_factories
from synthesis_msgs.msg import SynthesisErrorCodes
from respec.robot import robot_system

pytestmark = pytest.mark.ros

PAPER_TASK = dict(system='atlas', initial_conditions=['stand_prep'], goals=['look_down', 'pickup_object'])
CNU_STAGES = ('BEHAVIOR_SYNTHESIS_FAILED', 'SPEC_COMPILATION_FAILED', 'SYNTHESIS_FAILED',
              'SM_GENERATION_FAILED')


# --- ROS-free mapping and copying ------------------------------------------------------------

@pytest.mark.parametrize('name, expected', [
    ('SUCCESS', 'SUCCESS'), ('PREEMPTED', 'PREEMPTED'), ('INVALID_REQUEST', 'INVALID_REQUEST'),
    ('SPEC_UNSYNTHESIZABLE', 'SPEC_UNSYNTHESIZABLE'), ('AUTOMATON_INVALID', 'AUTOMATON_INVALID'),
    ('BUSY', 'BEHAVIOR_SYNTHESIS_FAILED'), ('TIMEOUT', 'BEHAVIOR_SYNTHESIS_FAILED'),
    ('UNKNOWN_PROPOSITION', 'SPEC_COMPILATION_FAILED'),
    ('LTL_SPEC_COMPILATION_FAILED', 'SPEC_COMPILATION_FAILED'),
    ('SYNTHESIS_TIMEOUT', 'SYNTHESIS_FAILED'), ('FAILURE', 'FAILURE'),
    ('UNKNOWN_SYSTEM', 'NO_SYSTEM_CONFIG'), ('ABSTRACTION_CONFIG_INVALID', 'CONFIG_FILE_INVALID'),
    ('INVALID_SPEC_NAME', 'INVALID_REQUEST'),
])
def test_our_error_names_map_to_cnus_constant_or_their_stages_failure(name, expected):
    cnu_names = {'SUCCESS', 'FAILURE', 'PREEMPTED', 'INVALID_REQUEST', 'SPEC_UNSYNTHESIZABLE',
                 'AUTOMATON_INVALID', 'NO_SYSTEM_CONFIG', 'CONFIG_FILE_INVALID', *CNU_STAGES}
    assert cnu_error_name(name, cnu_names) == expected


def test_field_mismatches_ignore_the_package_of_nested_types_only():
    ours = {'state_path': 'string', 'cond_transition': 'sequence<synthesis_msgs/OutcomeCondition>',
            'position': 'float[2]'}
    theirs = {**ours, 'cond_transition': 'sequence<flexbe_msgs/OutcomeCondition>'}
    assert field_mismatches(ours, theirs) == []
    assert field_mismatches(ours, {**theirs, 'position': 'float[3]', 'extra': 'string'}) == [
        'position: float[2] vs float[3]', 'extra: missing vs string']


def a_concurrency_state() -> CoreState:
    """A state that uses every field, including cond_transition's OutcomeCondition."""
    return CoreState(
        state_path='/Container/parallel', state_class=':CONCURRENCY', initial_state_name='',
        input_keys=['a'], output_keys=['b'], cond_outcome=['done', 'failed'],
        cond_transition=[CoreCondition(['x', 'y'], ['done', 'done']), CoreCondition(['x'], ['failed'])],
        behavior_class='', parameter_names=['p'], parameter_values=['1'], position=[12.5, -3.0],
        outcomes=['done', 'failed'], transitions=['next', 'failed'], autonomy=[0, 3],
        userdata_keys=['a', 'b'], userdata_remapping=['a', 'c'])


# --- With CNU's package (built by `make flexbe`) ----------------------------------------------

@pytest.fixture
def cnu_package(flexbe):
    """CNU's flexbe_synthesis_msgs, which `make flexbe` builds with FlexBE: a failure, not a skip."""
    try:
        import flexbe_synthesis_msgs.action  # noqa: F401
    except ImportError as error:
        pytest.fail(f'flexbe_synthesis_msgs is not importable ({error}); run `make flexbe`')


@pytest.mark.flexbe
def test_cnu_type_is_offered_and_states_copy_field_by_field(cnu_package):
    from flexbe_msgs.msg import OutcomeCondition, StateInstantiation
    from flexbe_synthesis_msgs.action import FlexBESynthesis
    from flexbe_synthesis_msgs.msg import SynthesisErrorCode

    interface = load_flexbe_synthesis_interface()
    assert interface.fallback_reason == ''
    assert interface.action_type is FlexBESynthesis
    assert interface.type_name == 'flexbe_synthesis_msgs/action/FlexBESynthesis'
    ours = state_to_msg(a_concurrency_state())
    assert field_mismatches(type(ours).get_fields_and_field_types(),
                            StateInstantiation.get_fields_and_field_types()) == []
    (copied,) = interface.states([ours])
    assert type(copied) is StateInstantiation
    assert all(type(condition) is OutcomeCondition for condition in copied.cond_transition)
    assert msg_to_state_dict(copied) == msg_to_state_dict(ours) == a_concurrency_state().to_dict()
    again = copy_message(ours, StateInstantiation, {'cond_transition': OutcomeCondition})
    assert msg_to_state_dict(again) == msg_to_state_dict(copied)

    # every error of ours becomes one of CNU's constants, with CNU's values
    cnu = constants(SynthesisErrorCode)
    for name in constants(SynthesisErrorCodes):
        code = interface.error_code(name)
        assert type(code) is SynthesisErrorCode and code.value in cnu.values()
        if name in cnu:
            assert code.value == cnu[name]
    assert interface.error_code('UNKNOWN_SYSTEM').value == SynthesisErrorCode.NO_SYSTEM_CONFIG


def start_suite(ros, byproducts_dir):
    """The suite's nodes, as `behavior-synthesis serve` starts them, in ``ros``."""
    args = Namespace(config_dir='', byproducts_dir=str(byproducts_dir), backend='builtin',
                     slugs_executable='slugs', synthesis_timeout=60.0, service_timeout=2.0, default_system='')
    for factory in suite_node_factories(args):
        ros.add_node(factory)
    return ros


@pytest.fixture
def suite(ros, tmp_path):
    return start_suite(ros, tmp_path)


class PlainCnuClient:
    """An unmodified rclpy ActionClient of CNU's type, spun by its own executor in the test's
    thread (as a script would use it): nothing of ours between it and the server."""

    def __init__(self, ros):
        import rclpy
        from rclpy.action import ActionClient
        from rclpy.executors import SingleThreadedExecutor

        from flexbe_synthesis_msgs.action import FlexBESynthesis

        self.action_type = FlexBESynthesis
        self.node = rclpy.create_node('plain_cnu_client', context=ros.context)
        self.executor = SingleThreadedExecutor(context=ros.context)
        self.executor.add_node(self.node)
        self.client = ActionClient(self.node, FlexBESynthesis, 'flexbe_synthesis')
        self.feedback = []
        # The feedback topic as published, goal by goal: rclpy's client drops a goal's feedback
        # that arrives after its result (it removes the goal's feedback callback at the result).
        self.published: dict[bytes, list[str]] = {}
        self.node.create_subscription(FlexBESynthesis.Impl.FeedbackMessage, 'flexbe_synthesis/_action/feedback',
                                      self._on_published_feedback, 10)
        self.last_goal_id = b''

    def close(self):
        self.client.destroy()
        self.executor.shutdown()
        self.node.destroy_node()

    def wait(self, future, timeout: float = 120.0):
        self.executor.spin_until_future_complete(future, timeout_sec=timeout)
        assert future.done(), f'no answer within {timeout} s'
        return future.result()

    def goal(self, initial_conditions, goals, **request):
        goal = self.action_type.Goal()
        goal.request.system_name = 'atlas'
        goal.request.initial_conditions = list(initial_conditions)
        goal.request.goals = list(goals)
        for name, value in request.items():
            setattr(goal.request, name, value)
        return goal

    def send(self, goal):
        assert self.client.wait_for_server(timeout_sec=10.0), 'no /flexbe_synthesis server of CNU\'s type'
        handle = self.wait(self.client.send_goal_async(goal, feedback_callback=self._on_feedback))
        assert handle.accepted
        self.last_goal_id = bytes(handle.goal_id.uuid)
        return handle

    def run(self, goal):
        return self.wait(self.send(goal).get_result_async())

    def _on_feedback(self, message):
        self.feedback.append(message.feedback.status)

    def _on_published_feedback(self, message):
        self.published.setdefault(bytes(message.goal_id.uuid), []).append(message.feedback.status)


@pytest.fixture
def plain_cnu_client(cnu_package, suite):
    client = PlainCnuClient(suite)
    yield client
    client.close()


@pytest.mark.flexbe
def test_unmodified_cnu_client_gets_success_and_the_states_of_behavior_synthesis(plain_cnu_client, suite):
    from action_msgs.msg import GoalStatus
    from flexbe_msgs.msg import StateInstantiation
    from flexbe_synthesis_msgs.msg import SynthesisErrorCode

    from rclpy.node import Node

    goal = plain_cnu_client.goal(PAPER_TASK['initial_conditions'], PAPER_TASK['goals'])
    response = plain_cnu_client.run(goal)
    result = response.result
    assert response.status == GoalStatus.STATUS_SUCCEEDED, list(result.messages)
    assert result.error_code.value == SynthesisErrorCode.SUCCESS == 1 and list(result.messages) == []
    assert result.states and all(type(state) is StateInstantiation for state in result.states)
    # Feedback is a topic of its own: its last message may arrive just after the result, seen
    # while the client's executor spins (as a script's would). rclpy's client then no longer
    # passes it on (it drops a goal's feedback callback at its result), so the client saw the
    # published feedback in order, all of it or all but that last line.
    published = plain_cnu_client.published.setdefault(plain_cnu_client.last_goal_id, [])
    deadline = time.monotonic() + 10.0
    while not (published and published[-1].startswith('Generated a state machine')):
        assert time.monotonic() < deadline, published[-3:]
        plain_cnu_client.executor.spin_once(timeout_sec=0.05)
    assert plain_cnu_client.feedback in (published, published[:-1]), (plain_cnu_client.feedback, published)

    legacy = SynthesisClient(suite.add_node(Node, 'legacy_client'), 'behavior_synthesis')
    assert legacy.wait_for_server(timeout=10.0)
    reference = legacy.run(make_goal(**PAPER_TASK), timeout=120)
    assert reference.succeeded, reference.message
    # field by field, in the same order
    assert [msg_to_state_dict(state) for state in result.states] == reference.states


@pytest.mark.flexbe
def test_bad_goals_get_cnus_error_codes_and_a_message(plain_cnu_client):
    from action_msgs.msg import GoalStatus
    from flexbe_synthesis_msgs.msg import SynthesisErrorCode

    unknown = plain_cnu_client.run(plain_cnu_client.goal(['stand_prep'], ['fly_away']))
    assert unknown.status == GoalStatus.STATUS_ABORTED
    assert unknown.result.error_code.value == SynthesisErrorCode.SPEC_COMPILATION_FAILED == -10
    (message,) = unknown.result.messages
    assert message.startswith('UNKNOWN_PROPOSITION:') and "'fly_away'" in message
    assert list(unknown.result.states) == []

    spec_file = plain_cnu_client.run(plain_cnu_client.goal(['stand_prep'], ['look_down'],
                                                           specification_file_name='mine.yaml'))
    assert spec_file.result.error_code.value == SynthesisErrorCode.INVALID_REQUEST == -2
    (message,) = spec_file.result.messages
    assert message.startswith('INVALID_REQUEST:') and 'mine.yaml' in message


# --- docs/cnu.md's error table, row by row, through the real action server ---------------------

CNU_ERROR_TABLE_HEADING = '## Error codes on /flexbe_synthesis'


def documented_cnu_codes() -> dict[str, str]:
    """docs/cnu.md's table: each of our codes (a row may list several) -> CNU's constant."""
    from pathlib import Path

    text = (Path(__file__).resolve().parents[2] / 'docs' / 'cnu.md').read_text()
    section = text.split(CNU_ERROR_TABLE_HEADING, 1)[1].split('\n## ', 1)[0]
    table = {}
    for line in section.splitlines():
        cells = [cell.strip() for cell in line.strip().strip('|').split('|')]
        if len(cells) >= 2 and cells[0].startswith('`'):
            for ours in cells[0].split('`')[1::2]:
                table[ours] = ours if cells[1].startswith('the same name') else cells[1].split('`')[1]
    return table


@pytest.mark.flexbe
def test_docs_table_gives_every_code_of_ours_its_cnu_code(cnu_package):
    from flexbe_synthesis_msgs.msg import SynthesisErrorCode

    interface = load_flexbe_synthesis_interface()
    cnu = constants(SynthesisErrorCode)
    table = documented_cnu_codes()
    assert sorted(table) == sorted(constants(SynthesisErrorCodes))
    assert {ours: interface.error_code(ours).value for ours in table} == {ours: cnu[name] for ours, name in table.items()}


@pytest.fixture(scope='module')
def broken_robots(tmp_path_factory):
    """A config folder with a malformed system file and a system whose CNU capability file is malformed."""
    folder = tmp_path_factory.mktemp('broken_robots')
    (folder / 'broken.yaml').write_text('system: broken\nabstraction: [unclosed\n')
    (folder / 'capabilities').mkdir()
    (folder / 'capabilities' / 'bad.yaml').write_text('capabilities: [oops\n')
    (folder / 'bad_capabilities.yaml').write_text('system: bad_capabilities\ncnu_capabilities: capabilities/bad.yaml\n')
    return folder


@pytest.fixture(scope='module')
def broken_robots_suite(broken_robots, tmp_path_factory):
    from synthesis_manager.ros.harness import RosHarness

    with RosHarness() as ros:
        args = Namespace(config_dir=str(broken_robots), byproducts_dir=str(tmp_path_factory.mktemp('byproducts')),
                         backend='builtin', slugs_executable='slugs', synthesis_timeout=60.0, service_timeout=2.0,
                         default_system='')
        for factory in suite_node_factories(args):
            ros.add_node(factory)
        yield ros


@pytest.fixture
def broken_robots_client(cnu_package, broken_robots_suite):
    client = PlainCnuClient(broken_robots_suite)
    yield client
    client.close()


def refused(client, goal, cnu_name: str, our_name: str, *words: str):
    """Runs ``goal``; asserts it is aborted with CNU's ``cnu_name`` and ``OUR_NAME: ...`` naming ``words``."""
    from action_msgs.msg import GoalStatus
    from flexbe_synthesis_msgs.msg import SynthesisErrorCode

    response = client.run(goal)
    messages = list(response.result.messages)
    assert response.status == GoalStatus.STATUS_ABORTED, messages
    assert response.result.error_code.value == getattr(SynthesisErrorCode, cnu_name), messages
    assert messages and messages[0].startswith(f'{our_name}: '), messages
    assert all(word in messages[0] for word in words), messages
    assert list(response.result.states) == []
    assert documented_cnu_codes()[our_name] == cnu_name


@pytest.mark.flexbe
def test_row_unknown_system_is_no_system_config(broken_robots_client):
    refused(broken_robots_client, broken_robots_client.goal(['stand_prep'], ['look_down'], system_name='r2d2'),
            'NO_SYSTEM_CONFIG', 'UNKNOWN_SYSTEM', "'r2d2'")


@pytest.mark.flexbe
def test_row_malformed_system_file_is_config_file_invalid(broken_robots_client):
    # A file that is not YAML is our CONFIG_FILE_INVALID too (every command and both actions say so).
    refused(broken_robots_client, broken_robots_client.goal(['stand_prep'], ['look_down'], system_name='broken'),
            'CONFIG_FILE_INVALID', 'CONFIG_FILE_INVALID', 'broken.yaml', 'not valid YAML')
    refused(broken_robots_client, broken_robots_client.goal(['x'], ['x'], system_name='bad_capabilities'),
            'CONFIG_FILE_INVALID', 'ABSTRACTION_CONFIG_INVALID', 'capabilities/bad.yaml', 'not valid YAML')


@pytest.mark.flexbe
def test_row_same_names_keep_their_code(broken_robots_client):
    refused(broken_robots_client, broken_robots_client.goal(['stand_prep'], ['look_down'],
                                                           specification_file_name='mine.yaml'),
            'INVALID_REQUEST', 'INVALID_REQUEST', 'mine.yaml')


@pytest.mark.flexbe
def test_row_compilation_refusals_are_spec_compilation_failed(broken_robots_client):
    refused(broken_robots_client, broken_robots_client.goal(['stand_prep'], ['fly_away']),
            'SPEC_COMPILATION_FAILED', 'UNKNOWN_PROPOSITION', "'fly_away'")


@pytest.mark.flexbe
def test_row_synthesis_timeout_is_synthesis_failed(broken_robots_client, runaway_synthesis):
    refused(broken_robots_client, broken_robots_client.goal(['stand_prep'], ['look_down'], synthesis_timeout_s=1.0),
            'SYNTHESIS_FAILED', 'SYNTHESIS_TIMEOUT')


@pytest.mark.flexbe
def test_row_a_missing_pipeline_node_is_behavior_synthesis_failed(cnu_package, tmp_path):
    """Only the server runs: the compilation service never appears."""
    from synthesis_manager.ros.harness import RosHarness

    with RosHarness() as ros:
        args = Namespace(config_dir='', byproducts_dir=str(tmp_path), backend='builtin', slugs_executable='slugs',
                         synthesis_timeout=60.0, service_timeout=0.5, default_system='')
        for factory in suite_node_factories(args, ['behavior_synthesis_server']):
            ros.add_node(factory)
        client = PlainCnuClient(ros)
        try:
            refused(client, client.goal(['stand_prep'], ['look_down']), 'BEHAVIOR_SYNTHESIS_FAILED',
                    'SERVICE_UNAVAILABLE')
        finally:
            client.close()


@pytest.mark.flexbe
def test_cancel_from_an_unmodified_cnu_client(plain_cnu_client, runaway_synthesis):
    from action_msgs.msg import GoalStatus
    from flexbe_synthesis_msgs.msg import SynthesisErrorCode

    handle = plain_cnu_client.send(plain_cnu_client.goal(['stand_prep'], ['look_down']))
    deadline = time.monotonic() + 30.0
    while not any(status.startswith('Synthesizing') for status in plain_cnu_client.feedback):
        assert time.monotonic() < deadline, plain_cnu_client.feedback
        plain_cnu_client.executor.spin_once(timeout_sec=0.1)
    cancelled_at = time.monotonic()
    plain_cnu_client.wait(handle.cancel_goal_async(), timeout=10.0)
    response = plain_cnu_client.wait(handle.get_result_async(), timeout=10.0)
    assert time.monotonic() - cancelled_at < 5.0
    assert response.status == GoalStatus.STATUS_CANCELED
    assert response.result.error_code.value == SynthesisErrorCode.PREEMPTED == -9
    assert response.result.messages[-1].startswith('PREEMPTED:')


@pytest.mark.flexbe
def test_all_of_cnus_example_pairs_through_an_unmodified_cnu_client(cnu_package, flexbe, flexbe_sources, tmp_path,
                                                                    monkeypatch):
    """CNU's 11 pairs, each served as CNU's launch serves it (its own config folder, the system
    under the request's name) and requested with CNU's request defaults unchanged, on
    /flexbe_synthesis: SUCCESS with at most CNU's count of StateInstantiations."""
    from flexbe_synthesis_msgs.msg import SynthesisErrorCode

    from cnu_example_pairs import example_pairs, write_system_file
    from synthesis_manager.ros.harness import RosHarness

    monkeypatch.setenv('AMENT_PREFIX_PATH', str(flexbe))   # the nodes read the workspace's state classes
    pairs = example_pairs(flexbe_sources / 'flexbe_synthesis')
    assert len(pairs) == 11
    counts = {}
    for pair in pairs:
        config_dir = tmp_path / pair.launch
        write_system_file(config_dir, pair)
        with RosHarness() as ros:
            args = Namespace(config_dir=str(config_dir), byproducts_dir=str(tmp_path / 'byproducts'),
                             backend='builtin', slugs_executable='slugs', synthesis_timeout=60.0,
                             service_timeout=2.0, default_system='')
            for factory in suite_node_factories(args):
                ros.add_node(factory)
            client = PlainCnuClient(ros)
            try:
                request = pair.request
                goal = client.goal(request['initial_conditions'], request['goals'],
                                   system_name=request['system_name'], spec_name=request['spec_name'],
                                   sm_outcomes=request['outcomes'])
                result = client.run(goal).result
            finally:
                client.close()
        assert result.error_code.value == SynthesisErrorCode.SUCCESS, (pair.launch, list(result.messages))
        counts[pair.launch] = (len(result.states), pair.cnu_state_count)
    assert all(0 < ours <= cnu for ours, cnu in counts.values()), counts


@pytest.mark.flexbe
def test_the_capability_precheck_sentence_reaches_both_actions(cnu_package, flexbe, flexbe_sources, tmp_path,
                                                                monkeypatch):
    """A goal no capability can make true (CNU's coffee maker sets no memory: `br`, not its outcome
    `br_c`) is refused before synthesis with the pre-check's sentence, the same on
    /behavior_synthesis (error_code.message, after the stage's words) and on CNU's /flexbe_synthesis (messages)."""
    from flexbe_synthesis_msgs.msg import SynthesisErrorCode
    from rclpy.node import Node

    from cnu_example_pairs import example_pairs, write_system_file
    from ltl_specification import InvalidGoalsError, compile_task
    from respec.robot.state_library import workspace_state_library
    from synthesis_manager.ros.harness import RosHarness

    monkeypatch.setenv('AMENT_PREFIX_PATH', str(flexbe))
    (pair,) = [p for p in example_pairs(flexbe_sources / 'flexbe_synthesis')
               if p.launch == 'coffee_capabilities_example.launch.py']
    write_system_file(tmp_path, pair)
    with pytest.raises(InvalidGoalsError) as refused:
        compile_task(robot_system('coffee_maker', tmp_path), ['bd_a'], ['br'],
                     state_library=workspace_state_library(str(flexbe)))
    sentence = str(refused.value)
    assert sentence.startswith("Goal 'br' can never be reached: no capability sets br_m true")
    with RosHarness() as ros:
        args = Namespace(config_dir=str(tmp_path), byproducts_dir=str(tmp_path / 'byproducts'), backend='builtin',
                         slugs_executable='slugs', synthesis_timeout=60.0, service_timeout=2.0, default_system='',
                         repair_time_budget=8.0)  # the default 3 s ended before the first fix at load 8
        for factory in suite_node_factories(args):
            ros.add_node(factory)
        ours = SynthesisClient(ros.add_node(Node, 'precheck_client'), 'behavior_synthesis')
        assert ours.wait_for_server(timeout=10.0)
        outcome = ours.run(make_goal('coffee_maker', ['bd_a'], ['br']), timeout=120)
        refusal, _, fixes = outcome.message.partition('\n\nVerified fixes')
        assert (outcome.error_name, refusal) == ('INVALID_GOALS', f'LTL compilation failed: {sentence}')
        # the robot change that makes it possible follows (test_suggested_fixes.py)
        assert 'Suggested fix 1: Change the robot: when br is completed, br holds' in fixes
        client = PlainCnuClient(ros)
        try:
            result = client.run(client.goal(['bd_a'], ['br'], system_name='coffee_maker')).result
        finally:
            client.close()
    assert result.error_code.value == SynthesisErrorCode.SPEC_COMPILATION_FAILED
    assert list(result.messages)[0] == f'INVALID_GOALS: LTL compilation failed: {sentence}'
    assert all(message.startswith('Suggested fix ') for message in list(result.messages)[1:])


# --- Without CNU's package ---------------------------------------------------------------------

@pytest.fixture
def without_cnu_package(monkeypatch):
    """Make flexbe_synthesis_msgs (and its submodules, if already imported) unimportable."""
    names = {'flexbe_synthesis_msgs', 'flexbe_synthesis_msgs.action', 'flexbe_synthesis_msgs.msg'}
    names |= {name for name in sys.modules if name.startswith('flexbe_synthesis_msgs.')}
    for name in names:
        monkeypatch.setitem(sys.modules, name, None)


def test_without_cnu_package_our_type_is_served_and_the_reason_logged_once(
        without_cnu_package, ros, tmp_path, capfd):
    from rclpy.node import Node

    from synthesis_msgs.action import FlexBESynthesis

    interface = load_flexbe_synthesis_interface()
    assert interface.action_type is FlexBESynthesis
    assert interface.fallback_reason.startswith('flexbe_synthesis_msgs not importable (')
    assert interface.fallback_reason.endswith(f'/flexbe_synthesis offers {FALLBACK_TYPE} instead')

    start_suite(ros, tmp_path)
    client = SynthesisClient(ros.add_node(Node, 'fallback_client'), 'flexbe_synthesis')
    assert client.wait_for_server(timeout=10.0)
    outcome = client.run(make_flexbe_goal(**PAPER_TASK), timeout=120)
    assert outcome.succeeded and outcome.states, outcome.message
    services = dict(client.node.get_service_names_and_types())
    offered = services['/flexbe_synthesis/_action/send_goal']
    assert offered == ['synthesis_msgs/action/FlexBESynthesis_SendGoal']
    assert capfd.readouterr().err.count('flexbe_synthesis_msgs not importable') == 1
