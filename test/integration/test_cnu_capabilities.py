"""Robots described by CNU's capability YAML (flexbe_synthesis) as robot systems of ours.

CNU's examples come from the pinned snapshot (``flexbe_sources``); each test writes a system
file into tmp_path that points at them, as a user's config/<system>.yaml would. All of CNU's
example pairs (``cnu_example_pairs``, read from CNU's own test) run with CNU's request defaults.
"""

from pathlib import Path

import networkx as nx
import pytest
import yaml

from ltl_specification import compile_task
from ltl_synthesizer import synthesize
from respec.automaton import automaton_from_strategy
from respec.robot import robot_system
from respec.robot.cnu import CapabilityConfigError
from ltl_specification.errors import UnknownPropositionError
from respec.ltl import conj, evaluate, to_infix
from respec.robot.state_library import StateClass, StateClassError, workspace_state_library
from sm_generation import StateMachine, generate_state_machine, validate_state_machine

from cnu_example_pairs import example_pairs, write_system_file
from cnu_systems import EXAMPLES, copied_rover, example_system, write_system

pytestmark = [pytest.mark.ros, pytest.mark.flexbe]

@pytest.fixture
def cnu(flexbe_sources) -> Path:
    return flexbe_sources / 'flexbe_synthesis'


@pytest.fixture
def library(flexbe):
    return workspace_state_library(str(flexbe))


def top_level_states(states):
    return [s for s in states if s.state_path != '/' and s.state_path.count('/') == 1 and s.state_class != ':OUTCOME']


def synthesized(config_dir, name, library):
    example = EXAMPLES[name]
    spec = compile_task(robot_system(name, config_dir),
                        example['initial_conditions'], example['goals'], example['outcomes'], state_library=library)
    result = synthesize(spec)
    assert result.realizable
    automaton = automaton_from_strategy(result.strategy, spec)
    states = generate_state_machine(automaton, robot_system(name, config_dir), state_library=library).to_instantiations()
    return spec, result.strategy, states


def strategy_violations(spec, strategy) -> list[str]:
    """The explicit strategy checked against the specification: initial nodes satisfy the
    initial conditions, every edge both safety sections, every environment move allowed by
    env_trans is answered, and no cycle fair to the environment misses a system liveness."""
    names = strategy['variables']
    n_inputs = len(spec.env_props)
    nodes = {name: dict(zip(names, map(bool, node['state']))) for name, node in strategy['nodes'].items()}
    problems = []
    initial = conj([*spec.env_init, *spec.sys_init])
    if not any(evaluate(initial, values) for values in nodes.values()):
        problems.append('no node satisfies the initial conditions')
    env_trans, sys_trans = conj(spec.env_trans), conj(spec.sys_trans)
    edges = []
    for name, node in strategy['nodes'].items():
        answered = set()
        for successor in node['trans']:
            current, following = nodes[name], nodes[str(successor)]
            edges.append((name, str(successor)))
            if not evaluate(env_trans, current, following) or not evaluate(sys_trans, current, following):
                problems.append(f'edge {name}->{successor} violates a safety formula')
            answered.add(tuple(following[v] for v in spec.env_props))
        for bits in range(2 ** n_inputs):
            inputs = tuple(bool(bits >> k & 1) for k in range(n_inputs))
            following = {**nodes[name], **dict(zip(spec.env_props, inputs))}
            if inputs not in answered and evaluate(env_trans, nodes[name], following):
                problems.append(f'node {name}: environment move {inputs} has no answer')
    for goal in spec.sys_liveness:
        graph = nx.DiGraph((a, b) for a, b in edges if not evaluate(goal, nodes[a], nodes[b]))
        for component in nx.strongly_connected_components(graph):
            inside = list(graph.subgraph(component).edges)
            if inside and all(any(evaluate(fair, nodes[a], nodes[b]) for a, b in inside)
                              for fair in spec.env_liveness):
                problems.append(f'a fair cycle through {sorted(component)} misses a goal')
    return problems


@pytest.mark.parametrize('name', list(EXAMPLES))
def test_cnu_example_requests_succeed_with_at_most_cnus_state_count(name, cnu, library, tmp_path):
    example = example_system(tmp_path, cnu, name)
    spec, strategy, states = synthesized(tmp_path, name, library)
    assert strategy_violations(spec, strategy) == []
    # A machine that never exits (CNU's coffee maker) has no outcomes, which our validator flags.
    never_exits = ['/: a container needs outcomes'] if not states[0].outcomes else []
    assert validate_state_machine(states) == never_exits
    assert len(top_level_states(states)) <= example['top_level']
    # Every capability state is the capability's own FlexBE class with its parameters.
    capabilities = robot_system(name, tmp_path).capabilities.capabilities
    for state in top_level_states(states):
        capability = capabilities[state.name]
        assert state.state_class == capability.interface
        assert dict(zip(state.parameter_names, state.parameter_values))['text' if 'text' in capability.parameters
                                                                        else 'hint'] is not None


def test_all_of_cnus_example_pairs_succeed_with_at_most_cnus_state_count(cnu, library, tmp_path):
    """CNU's 11 pairs (its test's list, its request defaults): the capability pipeline, the full
    specifications and hello_world's given machine, each in a config folder of its own under the
    request's system name, as CNU's launch serves it. CNU's count is every StateInstantiation."""
    pairs = example_pairs(cnu)
    assert len(pairs) == 11 and {p.files.get('cnu_pipeline') for p in pairs} == {'capabilities', 'full_spec', None}
    results = {}
    for pair in pairs:
        config_dir = tmp_path / pair.launch
        write_system_file(config_dir, pair)
        request = pair.request
        spec = compile_task(robot_system(request['system_name'], config_dir),
                            request['initial_conditions'], request['goals'],
                            request['outcomes'], state_library=library)
        result = synthesize(spec)
        assert result.realizable, pair.launch
        assert strategy_violations(spec, result.strategy) == [], pair.launch
        automaton = automaton_from_strategy(result.strategy, spec)
        states = generate_state_machine(automaton, robot_system(request['system_name'], config_dir), state_library=library).to_instantiations()
        never_exits = ['/: a container needs outcomes'] if not states[0].outcomes else []
        assert validate_state_machine(states) == never_exits, pair.launch
        assert states[0].outcomes == request['outcomes'], pair.launch
        results[pair.launch] = (len(states), pair.cnu_state_count, [s.name for s in top_level_states(states)])
    assert all(count <= cnu_count for count, cnu_count, _ in results.values()), results
    # The machines do what CNU's do: hello_world is its given machine, the others CNU's sequences.
    assert results['hello_world_example.launch.py'][2] == ['SayHello', 'SayWorld']
    assert results['coffee_full_spec_example.launch.py'][2] == ['bd', 'gr', 'br']
    assert results['vending_full_spec_example.launch.py'][2] == ['prep_pay', 'pay', 'select', 'soda']


def test_a_given_machine_is_generated_as_given(cnu, library, tmp_path):
    """CNU's sm/ file: classes, parameters (Python source), transitions and autonomy unchanged."""
    (pair,) = [p for p in example_pairs(cnu) if 'cnu_state_machine' in p.files]
    write_system_file(tmp_path, pair)
    spec = compile_task(robot_system('hello_world', tmp_path), [], [], state_library=library)
    automaton = automaton_from_strategy(synthesize(spec).strategy, spec)
    states = generate_state_machine(automaton, robot_system('hello_world', tmp_path), state_library=library).to_instantiations()
    given = yaml.safe_load(pair.files['cnu_state_machine'].read_text())
    assert states[0].initial_state_name == given['sm']['initial_state']
    assert [(s.name, s.state_class, dict(zip(s.parameter_names, s.parameter_values)), s.outcomes, s.transitions,
             s.autonomy) for s in top_level_states(states)] == [
        (g['name'], g['state_class'], g['parameters'], g['outcomes'], g['transitions'], g['autonomy'])
        for g in given['states']]


def test_full_spec_request_replaces_the_files_initial_literal_and_reads_goals_as_memories(cnu, library, tmp_path):
    (pair,) = [p for p in example_pairs(cnu) if p.launch == 'vending_full_spec_example.launch.py']
    write_system_file(tmp_path, pair)
    spec = compile_task(robot_system('vending_demo', tmp_path), ['prep_pay_a'], ['soda'], state_library=library)
    sys_init = [to_infix(f) for f in spec.sys_init]
    assert 'prep_pay_a' in sys_init and '!prep_pay_a' not in sys_init   # the file says ! prep_pay_a
    assert any("soda_m" in to_infix(f) and "finished" in to_infix(f) for f in spec.sys_trans)
    with pytest.raises(UnknownPropositionError) as unknown:
        compile_task(robot_system('vending_demo', tmp_path), [], ['lemonade'], state_library=library)
    assert unknown.value.item == 'lemonade'


def test_full_spec_goals_recur_without_a_success_outcome(cnu, library, tmp_path):
    (pair,) = [p for p in example_pairs(cnu) if p.launch == 'coffee_full_spec_example.launch.py']
    write_system_file(tmp_path, pair)
    spec = compile_task(robot_system('coffee_maker', tmp_path), ['bd_a'], ['br_c'], state_library=library)
    assert [to_infix(f) for f in spec.sys_liveness] == ['br_c'] and spec.env_liveness   # the file's `bu`
    assert 'bu' in spec.env_props


def test_empty_goals_add_no_success_formula(cnu, library, tmp_path):
    example_system(tmp_path, cnu, 'vending_demo')
    with_goal = compile_task(robot_system('vending_demo', tmp_path), ['prep_pay_a'], ['soda'], state_library=library)
    without = compile_task(robot_system('vending_demo', tmp_path), ['prep_pay_a'], [], state_library=library)
    assert [to_infix(f) for f in with_goal.sys_liveness] == ['finished'] and without.sys_liveness == []
    assert len(with_goal.sys_trans) == len(without.sys_trans) + 1


def test_a_given_state_with_two_targets_for_one_transition_outcome_is_named(library, tmp_path):
    machine = {'sm': {'outcomes': ['finished'], 'initial_state': 'Ask'},
               'states': [{'name': 'Ask', 'state_class': 'LogState', 'parameters': {'text': "'?'"},
                           'outcomes': ['done', 'finished'], 'transitions': ['Ask', 'finished']}]}
    (tmp_path / 'sm.yaml').write_text(yaml.safe_dump(machine))
    write_system(tmp_path, 'robot', None, cnu_state_machine='sm.yaml')
    with pytest.raises(CapabilityConfigError) as error:
        compile_task(robot_system('robot', tmp_path), [], [], state_library=library)
    assert error.value.item == 'states.Ask' and "'completed'" in str(error.value)


def test_spec_file_formulas_join_the_capabilities_in_cnus_capability_pipeline(cnu, library, tmp_path):
    """A spec file's SYS_TRANS (CNU's own remedy for a capability that must not restart) is added."""
    example_system(tmp_path / 'plain', cnu, 'vending_demo')
    plain = compile_task(robot_system('vending_demo', tmp_path / 'plain'),
                         ['prep_pay_a'], ['soda'], state_library=library)
    (tmp_path / 'more').mkdir()
    spec_file = tmp_path / 'more' / 'spec.yaml'  # inside the config folder, as every referenced file
    spec_file.write_text(yaml.safe_dump({'specs': {'OUTPUT': ['prep_pay_a', 'item:0...3'],
                                                   'SYS_INIT': ['prep_pay_a', 'item=0'],
                                                   'SYS_TRANS': ["pay_c' -> !prep_pay_a'"]}}))
    examples = cnu / 'flexbe_synthesis_examples' / 'example'
    write_system(tmp_path / 'more', 'vending_demo', cnu,
                 cnu_capabilities=examples / EXAMPLES['vending_demo']['capabilities'], cnu_spec=spec_file,
                 cnu_mappings=cnu / 'flexbe_synthesis_generic' / 'mappings' / 'global_mappings.yaml')
    more = compile_task(robot_system('vending_demo', tmp_path / 'more'),
                        ['prep_pay_a'], ['soda'], state_library=library)
    added = [to_infix(f) for f in more.sys_trans if f not in plain.sys_trans]
    assert added == ['next(pay_c) -> !next(prep_pay_a)'] and synthesize(more).realizable
    spec_file.write_text(yaml.safe_dump({'specs': {'SYS_TRANS': ['ghost -> pay_a']}}))
    with pytest.raises(CapabilityConfigError) as unknown:
        compile_task(robot_system('vending_demo', tmp_path / 'more'), ['prep_pay_a'], ['soda'], state_library=library)
    assert unknown.value.item == 'specs.SYS_TRANS' and 'ghost' in str(unknown.value)


def test_coffee_maker_cycles_button_grind_brew_and_retries_failures(cnu, library, tmp_path):
    example_system(tmp_path, cnu, 'coffee_maker_extended')
    _, _, states = synthesized(tmp_path, 'coffee_maker_extended', library)
    root, by_name = states[0], {s.name: s for s in top_level_states(states)}
    assert root.outcomes == [] and root.initial_state_name == 'bd'   # CNU's coffee machine never exits
    assert dict(zip(by_name['bd'].outcomes, by_name['bd'].transitions)) == {'button': 'gr', 'fail': 'bd'}
    assert dict(zip(by_name['gr'].outcomes, by_name['gr'].transitions)) == {'grind': 'br', 'fail': 'gr'}
    assert dict(zip(by_name['br'].outcomes, by_name['br'].transitions)) == {'brew': 'bd', 'fail': 'br'}
    assert by_name['bd'].autonomy == [2, 3]   # autonomy per outcome, from the capability file
    assert by_name['bd'].parameter_values[0] == "['button', 'fail']"


def test_vending_demo_uses_cnus_proposition_names_and_integer_variable(cnu, library, tmp_path):
    example_system(tmp_path, cnu, 'vending_demo')
    spec, _, states = synthesized(tmp_path, 'vending_demo', library)
    assert {'prep_pay_a', 'soda_a', 'finished', 'soda_m', 'item@0.0.3', 'item@1'} <= set(spec.sys_props)
    assert {'soda_c', 'pay_c'} <= set(spec.env_props)
    path, name = [], states[0].initial_state_name
    by_name = {s.name: s for s in top_level_states(states)}
    while name in by_name:
        path.append(name)
        name = by_name[name].transitions[0]
    assert path == ['prep_pay', 'pay', 'select', 'soda'] and name == 'finished'
    # The same request gives byte-identical specifications and machines.
    again_spec, _, again = synthesized(tmp_path, 'vending_demo', library)
    assert again_spec.to_structuredslugs() == spec.to_structuredslugs()
    assert [s.to_dict() for s in again] == [s.to_dict() for s in states]


def test_at_var_parameters_take_the_value_the_strategy_chose(library, tmp_path):
    capabilities = {
        'name': 'shop',
        'variable_mappings': {'sys_props': {'item': {0: 'None', 1: 'tea', 2: 'cake'}}},
        'capabilities': {
            'choose': {'interface': 'LogState', 'parameters': {'text': 'choose'},
                       'preconditions': ['!choose'], 'postconditions': ['choose', '@item'],
                       'transition_relation': ['give']},
            'give': {'interface': 'LogState', 'parameters': {'text': '@item'},
                     'preconditions': ['choose', 'item!=0'], 'postconditions': ['give']},
        },
    }
    (tmp_path / 'shop_capabilities.yaml').write_text(yaml.safe_dump(capabilities))
    write_system(tmp_path, 'shop', None, cnu_capabilities='shop_capabilities.yaml')
    for goal, value in (('item=2', "'cake'"), ('item=1', "'tea'")):
        spec = compile_task(robot_system('shop', tmp_path), [], ['give', goal], state_library=library)
        automaton = automaton_from_strategy(synthesize(spec).strategy, spec)
        states = generate_state_machine(automaton, robot_system('shop', tmp_path), state_library=library).to_instantiations()
        give = next(s for s in top_level_states(states) if s.state_class == 'LogState' and s.name.startswith('give'))
        assert give.name == f'give_{value.strip(chr(39))}'
        assert dict(zip(give.parameter_names, give.parameter_values)) == {'text': value}


def test_missing_state_class_and_unknown_parameter_are_named(cnu, tmp_path):
    example_system(tmp_path, cnu, 'vending_demo')
    log_only = {'LogState': StateClass('LogState', 'flexbe_states', ('text', 'severity'), ('text',),
                                       outcomes=('done',))}
    spec = compile_task(robot_system('vending_demo', tmp_path), ['prep_pay_a'], ['soda'], state_library=log_only)
    assert 'soda_a' in spec.sys_props
    extended = example_system(tmp_path, cnu, 'vending_demo_extended')
    with pytest.raises(StateClassError) as missing:
        compile_task(robot_system('vending_demo_extended', tmp_path),
                     extended['initial_conditions'], extended['goals'], state_library=log_only)
    assert missing.value.item == 'pay.interface' and 'OperatorDecisionState' in str(missing.value)
    no_text = {'LogState': StateClass('LogState', 'flexbe_states', ('message',), (), outcomes=('done',))}
    with pytest.raises(StateClassError) as parameter:
        compile_task(robot_system('vending_demo', tmp_path), ['prep_pay_a'], ['soda'], state_library=no_text)
    assert parameter.value.item == 'prep_pay.parameters.text'  # the first capability of the file


def test_a_missing_flexbe_workspace_says_what_to_set(cnu, tmp_path):
    example_system(tmp_path, cnu, 'vending_demo')
    for library in ({}, workspace_state_library(str(tmp_path))):  # nothing, or no FlexBE package, on the path
        with pytest.raises(StateClassError) as missing:
            compile_task(robot_system('vending_demo', tmp_path), ['prep_pay_a'], ['soda'], state_library=library)
        message = str(missing.value)
        assert 'no FlexBE state package is on AMENT_PREFIX_PATH at all' in message
        assert 'source <workspace>/install/setup.bash' in message and '`make flexbe`' in message


def test_export_without_a_flexbe_workspace_says_what_to_set_before_synthesis(cnu, tmp_path, capsys, monkeypatch):
    from synthesis_manager.programs.cli import main

    example_system(tmp_path, cnu, 'vending_demo')
    monkeypatch.setenv('AMENT_PREFIX_PATH', str(tmp_path))  # no FlexBE state package there
    code = main(['export-behavior', '--system', 'vending_demo', '--config-dir', str(tmp_path),
                 '--initial-conditions', 'prep_pay_a', '--goals', 'soda', '-o', str(tmp_path / 'out')])
    error = capsys.readouterr().err
    # A robot file the workspace cannot serve is refused input: exit 1, as --help and every command say.
    assert code == 1 and 'CONFIG_VARIABLE_CONFIG_INVALID' in error and '`make flexbe`' in error
    assert not (tmp_path / 'out').exists()


def test_the_workspace_library_reads_flexbe_state_packages_without_importing_them(library):
    log = library['LogState']
    assert log.package == 'flexbe_states' and log.outcomes == ('done',) and log.required == ('text',)
    assert library['OperatorDecisionState'].outcomes is None   # given at construction
    assert workspace_state_library('') == {}


@pytest.mark.parametrize('capabilities, item', [
    ({'capabilities': {'a': {'parameters': {'text': 'x'}}}}, 'a.interface'),
    ({'capabilities': {'a': {'interface': 'LogState', 'preconditions': ['b=1']}}}, 'a.preconditions'),
    ({'capabilities': {'a': {'interface': 'LogState', 'postconditions': {'sometimes': ['a']}}}},
     'a.postconditions.sometimes'),
    ({'capabilities': {'a': {'interface': 'LogState', 'transition_relation': ['nowhere']}}}, 'a.transition_relation'),
    ({'capabilities': {'a': {'interface': 'LogState', 'autonomy': {'done': 7}}}}, 'a.autonomy.done'),
    ({'capabilities': {'a': {'interface': 'LogState', 'parameters': {'text': '@level'}}}}, 'a.parameters.text'),
    ({'capabilities': {'a': {'interface': 'LogState', 'colour': 'red'}}}, 'a.colour'),
    ({'capabilities': {'a': {'interface': 'LogState', 'parameters': {'text': 'x'}, 'preconditions': ['ghost']}}},
     'ghost'),
    ({'capabilities': {'a': {'interface': 'LogState', 'parameters': {'text': 'x'}, 'autonomy': {'finished': 1}}}},
     'a.autonomy.finished'),
])
def test_bad_capability_files_name_the_capability_and_key(capabilities, item, library, tmp_path):
    (tmp_path / 'bad.yaml').write_text(yaml.safe_dump({'name': 'bad', **capabilities}))
    write_system(tmp_path, 'robot', None, cnu_capabilities='bad.yaml')
    with pytest.raises(CapabilityConfigError) as error:
        compile_task(robot_system('robot', tmp_path), [], ['a'], state_library=library)
    assert error.value.item == item, str(error.value)
    assert error.value.code in ('ABSTRACTION_CONFIG_INVALID', 'CONFIG_VARIABLE_CONFIG_INVALID')


def test_bad_system_files_are_reported_not_raised_as_tracebacks(tmp_path, library):
    write_system(tmp_path, 'robot', None, cnu_capabilities='missing.yaml')
    with pytest.raises(CapabilityConfigError) as missing:
        compile_task(robot_system('robot', tmp_path), [], ['a'], state_library=library)
    assert missing.value.item == 'cnu_capabilities'
    (tmp_path / 'broken.yaml').write_text('capabilities: [unclosed\n')
    write_system(tmp_path, 'robot', None, cnu_capabilities='broken.yaml')
    with pytest.raises(CapabilityConfigError, match='not valid YAML'):
        compile_task(robot_system('robot', tmp_path), [], ['a'], state_library=library)


def test_cnu_behaviors_run_on_the_real_flexbe_engine(cnu, library, tmp_path):
    from sm_generation.flexbe_behavior import behavior_package
    from sm_generation.for_system import behavior_flexbe_config
    from synthesis_manager.ros.flexbe_engine import load_behavior_class
    from synthesis_manager.ros.harness import RosHarness

    for name in ('vending_demo', 'vending_demo_extended', 'hello_world'):
        example_system(tmp_path, cnu, name)
        _, _, states = synthesized(tmp_path, name, library)
        config = behavior_flexbe_config(robot_system(name, tmp_path), library)
        package = behavior_package(StateMachine.from_instantiations(states), config, f'CNU {name.replace("_", " ")}')
        behavior_class, checksum = load_behavior_class(package, tmp_path / name)
        with RosHarness(default_context=True) as ros:  # flexbe_core uses rclpy's global context
            outcome, visited = run_behavior(ros, behavior_class, checksum, name)
        assert outcome == 'finished', name
        expected = ['say_hello', 'say_world'] if name == 'hello_world' else ['prep_pay', 'pay', 'select', 'soda']
        assert visited == expected, name


def run_behavior(ros, behavior_class, checksum, name):
    """flexbe_onboard's sequence (set_up, prepare_for_execution, confirm, execute) in full
    autonomy; returns the outcome and the top-level states entered, in order."""
    from rclpy.node import Node

    from flexbe_core import set_node
    from synthesis_manager.ros.flexbe_engine import FULL_AUTONOMY, reset_flexbe_proxies

    node = ros.add_node(Node, f'flexbe_{name}')
    set_node(node)
    visited = []
    try:
        behavior = behavior_class(node)
        behavior.set_up(beh_id=checksum, autonomy_level=FULL_AUTONOMY, debug=False)
        behavior.prepare_for_execution({})
        for state in behavior._state_machine._states:
            original = state.execute

            def observed(*args, _state=state, _original=original, **kwargs):
                if not visited or visited[-1] != _state.name:
                    visited.append(_state.name)
                return _original(*args, **kwargs)
            state.execute = observed
        behavior.confirm()
        outcome = behavior.execute()
    finally:
        reset_flexbe_proxies(ros.executor, node)
    return outcome, visited


def test_cnu_examples_through_our_behavior_synthesis_action(cnu, flexbe, tmp_path, ros, monkeypatch):
    """The in-process suite (all four nodes) serves a CNU system from its config_dir."""
    from rclpy.node import Node

    from synthesis_manager.client import SynthesisClient, make_goal
    from synthesis_manager.suite import suite_node_factories
    from suite_settings import suite_args

    monkeypatch.setenv('AMENT_PREFIX_PATH', str(flexbe))   # the nodes read the workspace's state classes
    config_dir = tmp_path / 'config'
    for name in ('vending_demo_extended', 'coffee_maker'):
        example_system(config_dir, cnu, name)
    for factory in suite_node_factories(suite_args(tmp_path, config_dir=str(config_dir))):
        ros.add_node(factory)
    client = SynthesisClient(ros.add_node(Node, 'cnu_client'))
    assert client.wait_for_server(timeout=10.0)
    for name, count in (('vending_demo_extended', 4), ('coffee_maker', 3)):
        example = EXAMPLES[name]
        outcome = client.run(make_goal(system=name, initial_conditions=example['initial_conditions'],
                                       goals=example['goals']), timeout=120)
        assert outcome.error_name == 'SUCCESS', outcome.message
        assert len([s for s in outcome.states if s['state_path'].count('/') == 1
                    and s['state_class'] != ':OUTCOME' and s['state_path'] != '/']) == count
    bad = client.run(make_goal(system='vending_demo_extended', initial_conditions=['prep_pay_a'],
                               goals=['lemonade']), timeout=60)
    assert bad.error_name == 'UNKNOWN_PROPOSITION' and 'lemonade' in bad.message


def test_no_initial_conditions_keep_cnus_meaning_for_capability_systems(cnu, tmp_path):
    """CNU: empty initial conditions come from the specification; our robots read the robot state."""
    from ltl_specification.initial_conditions import reads_robot_state

    example_system(tmp_path, cnu, 'hello_world')
    assert not reads_robot_state([], robot_system('hello_world', tmp_path))
    assert reads_robot_state(['current'], robot_system('hello_world', tmp_path))
    assert reads_robot_state([], robot_system('atlas')) and not reads_robot_state(['stand'], robot_system('atlas'))
    assert reads_robot_state([], None)  # a system that cannot be read: compiling reports why


def rover_machine(library, sm_outcomes, config_dir=None):
    """config/delivery_rover (or its variant in ``config_dir``): deliver, from a battery check."""
    spec = compile_task(robot_system('delivery_rover', config_dir), ['check_battery_a'], ['hand_over'], sm_outcomes,
                        state_library=library)
    result = synthesize(spec)
    assert result.realizable
    assert strategy_violations(spec, result.strategy) == []
    automaton = automaton_from_strategy(result.strategy, spec)
    states = generate_state_machine(automaton, robot_system('delivery_rover', config_dir), state_library=library).to_instantiations()
    assert validate_state_machine(states) == []
    return spec, {s.state_path: s for s in states}


def test_a_sensor_reaches_the_machine_through_the_state_that_observes_it(library):
    """The rover's spec INPUT battery_low is an environment proposition; its ENV_TRANS binds it to
    the battery check's outcomes, so the check's `low` outcome is where the machine reacts."""
    spec, states = rover_machine(library, ['finished'])
    assert 'battery_low' in spec.env_props
    check = states['/check_battery']
    assert dict(zip(check.outcomes, check.transitions)) == {'ok': 'drive', 'low': 'charge'}
    assert dict(zip(states['/charge'].outcomes, states['/charge'].transitions)) == {'done': 'drive'}


def test_a_requested_failed_outcome_ends_the_failures_no_transition_relation_handles(library):
    _, retried = rover_machine(library, ['finished'])
    assert retried['/'].outcomes == ['finished']
    assert dict(zip(retried['/drive'].outcomes, retried['/drive'].transitions)) == {'done': 'hand_over',
                                                                                   'failed': 'drive'}
    _, ended = rover_machine(library, ['finished', 'failed'])
    assert ended['/'].outcomes == ['finished', 'failed']
    assert dict(zip(ended['/drive'].outcomes, ended['/drive'].transitions)) == {'done': 'hand_over',
                                                                               'failed': 'failed'}


def test_a_requested_outcome_the_mappings_do_not_name_is_refused(library):
    from ltl_specification.errors import InvalidSmOutcomesError

    with pytest.raises(InvalidSmOutcomesError, match="'delivered' is not one of its mappings' sm_outcome_mappings"):
        compile_task(robot_system('delivery_rover'), [], ['hand_over'], ['delivered', 'failed'], state_library=library)


def test_a_strategy_that_reacts_to_an_input_no_state_observes_is_refused(library, tmp_path):
    """Without the battery check's binding, a SYS_TRANS that reads the sensor after a charge would
    make FlexBE choose blindly: the machine is refused, naming the input."""
    from sm_generation.errors import StateConfigInvalidError

    copied_rover(tmp_path)
    spec_file = tmp_path / 'delivery_rover' / 'spec.yaml'
    spec = yaml.safe_load(spec_file.read_text())
    spec['specs']['ENV_TRANS'].remove("charge_c' -> !battery_low'")
    spec['specs']['SYS_TRANS'] = ["(charge_c' & battery_low') -> hand_over_a'",
                                  "(charge_c' & !battery_low') -> drive_a'"]
    spec_file.write_text(yaml.safe_dump(spec))
    capabilities_file = tmp_path / 'delivery_rover' / 'capabilities.yaml'
    capabilities = yaml.safe_load(capabilities_file.read_text())
    capabilities['capabilities']['hand_over']['preconditions'] = []
    capabilities_file.write_text(yaml.safe_dump(capabilities))
    with pytest.raises(StateConfigInvalidError, match="reacts to input 'battery_low', which no state reports"):
        rover_machine(library, ['finished'], tmp_path)


def test_a_sensor_starts_as_env_init_says_or_free(library, tmp_path):
    """slugs' meaning: ENV_INIT constrains a spec INPUT's initial value; without it, it is free."""
    free = compile_task(robot_system('delivery_rover'), [], ['hand_over'], ['finished'], state_library=library)
    assert not any('battery_low' in to_infix(f) for f in free.env_init)
    copied_rover(tmp_path)
    spec_file = tmp_path / 'delivery_rover' / 'spec.yaml'
    spec = yaml.safe_load(spec_file.read_text())
    spec['specs']['ENV_INIT'] = ['battery_low']
    spec_file.write_text(yaml.safe_dump(spec))
    low = compile_task(robot_system('delivery_rover', tmp_path), [], ['hand_over'], ['finished'], state_library=library)
    assert 'battery_low' in [to_infix(f) for f in low.env_init]
    _, states = rover_machine(library, ['finished'], tmp_path)
    assert dict(zip(states['/check_battery'].outcomes, states['/check_battery'].transitions))['low'] == 'charge'
