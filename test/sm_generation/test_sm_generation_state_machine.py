"""StateMachine: the StateInstantiation list as one validated tree, and back."""

import copy
import json
from pathlib import Path

import pytest

from ltl_specification import compile_task
from ltl_synthesizer import synthesize
from respec.automaton import automaton_from_strategy
from respec.robot.state_library import workspace_state_library
from sm_generation import (OutcomeCondition, SMGenerationError, StateInstantiation, StateMachine,
                           generate_state_machine, load_automaton, validate_state_machine)
from sm_generation.state_machine import State
from respec.robot import robot_system

AUTOMATA = Path(__file__).resolve().parents[1] / 'automata'
GENERATED = [(path.name, reduce) for path in sorted(AUTOMATA.glob('*.yaml')) for reduce in (False, True)]
FIELDS = set(StateInstantiation().to_dict())
PLAIN, CONTAINER = 4, 1  # /pregrasp_pose and /object_template_and_stand of concurrent.yaml


def generated(name: str, reduce: bool = False) -> list[StateInstantiation]:
    return generate_state_machine(load_automaton(AUTOMATA / name), robot_system('atlas'), reduce=reduce).to_instantiations()


@pytest.mark.parametrize('name, reduce', GENERATED)
def test_every_generated_machine_round_trips_exactly(name, reduce):
    states = generated(name, reduce)
    machine = StateMachine.from_instantiations(states)
    assert machine.to_instantiations() == states
    assert all(type(entry) is StateInstantiation for entry in machine.to_instantiations())
    from_dicts = StateMachine.from_instantiations([s.to_dict() for s in states])
    assert from_dicts.to_instantiations() == states
    # the generator builds the tree itself: the same tree as its list read back
    assert generate_state_machine(load_automaton(AUTOMATA / name), robot_system('atlas'), reduce=reduce).to_dict() == machine.to_dict()


@pytest.mark.flexbe
def test_a_cnu_machine_round_trips_exactly(flexbe, flexbe_sources, tmp_path):
    cnu = flexbe_sources / 'flexbe_synthesis'
    examples = cnu / 'flexbe_synthesis_examples' / 'example' / 'vending_demo'
    (tmp_path / 'vending_demo.yaml').write_text(
        'system: vending_demo\n'
        f'cnu_capabilities: {examples / "capabilities" / "vending_capabilities.yaml"}\n'
        f'cnu_spec: {examples / "specs" / "vending_demo_capabilities_spec.yaml"}\n'
        f'cnu_mappings: {cnu / "flexbe_synthesis_generic" / "mappings" / "global_mappings.yaml"}\n')
    library = workspace_state_library(str(flexbe))
    spec = compile_task(robot_system('vending_demo', tmp_path), ['prep_pay_a'], ['soda'], state_library=library)
    automaton = automaton_from_strategy(synthesize(spec).strategy, spec)
    states = generate_state_machine(automaton, robot_system('vending_demo', tmp_path), state_library=library).to_instantiations()
    assert StateMachine.from_instantiations(states).to_instantiations() == states


def test_the_tree_owns_its_states_and_copies_its_entries():
    states = generated('concurrent.yaml')
    machine = StateMachine.from_instantiations(states)
    container = machine.state('object_template_and_stand')
    assert isinstance(machine, StateMachine) and isinstance(container, StateMachine)
    assert [s.name for s in container.states] == ['object_template', 'stand']
    assert [o.name for o in machine.outcome_entries] == machine.outcomes
    assert machine.initial_state().name == machine.initial_state_name
    assert machine.containers() == [container]
    assert container not in machine.primitives() and all(not s.states for s in machine.primitives())
    assert container.conditions[0] == (container.cond_outcome[0],
                                       list(zip(container.cond_transition[0].state_name,
                                                container.cond_transition[0].state_outcome)))
    stand = container.state('stand')
    assert stand.next_target(stand.outcomes[0]) == stand.transitions[0] and stand.next_target('nope') is None
    states[0].outcomes.append('changed later')  # the tree keeps its own copies
    assert 'changed later' not in machine.outcomes


def test_ordered_states_put_the_initial_state_first_then_sort_by_name():
    machine = StateMachine.from_instantiations(generated('initial_decision.yaml'))
    ordered = [s.name for s in machine.ordered_states()]
    assert ordered[0] == machine.initial_state_name and ordered[1:] == sorted(ordered[1:])


def test_to_dict_is_the_entries_with_name_and_children():
    states = generated('concurrent.yaml')
    tree = StateMachine.from_instantiations(states).to_dict()
    json.dumps(tree)  # JSON-able as it is

    def nodes(node):
        yield node
        for child in node['children']:
            yield from nodes(child)

    flat = list(nodes(tree))
    assert [{k: v for k, v in n.items() if k not in ('name', 'children')} for n in flat] == [s.to_dict() for s in states]
    assert all(set(n) == FIELDS | {'name', 'children'} for n in flat)
    assert tree['name'] == '/' and tree['state_path'] == '/'
    top = [s for s in states if s.parent_path == '/' and s.state_class != ':OUTCOME']
    outcomes = [s for s in states if s.state_class == ':OUTCOME']
    assert [c['state_path'] for c in tree['children']] == [s.state_path for s in top + outcomes]
    container = next(c for c in tree['children'] if c['state_class'] == ':CONCURRENCY')
    assert [c['name'] for c in container['children']] == ['object_template', 'stand']
    assert all(c['children'] == [] for c in container['children'])
    assert all(n['name'] == n['state_path'].rsplit('/', 1)[-1] for n in flat[1:])


def test_validation_lists_what_the_tree_refuses_and_what_only_the_editor_minds():
    states = generated('concurrent.yaml')
    assert validate_state_machine(states) == []
    editor_only = copy.deepcopy(states)
    editor_only[PLAIN].autonomy = []  # FlexBE's editor minds, the tree does not
    assert validate_state_machine(editor_only) == [f'/pregrasp_pose: {len(editor_only[PLAIN].outcomes)} outcomes '
                                                   'but 0 autonomy levels']
    assert StateMachine.from_instantiations(editor_only).to_instantiations() == editor_only


@pytest.mark.parametrize('change, item, text', [
    (lambda s: s.pop(0), '/', 'root container'),
    (lambda s: setattr(s[0], 'initial_state_name', 'nowhere'), 'nowhere', "initial_state_name 'nowhere'"),
    (lambda s: setattr(s[PLAIN], 'transitions', ['nowhere'] * len(s[PLAIN].outcomes)), '/pregrasp_pose',
     "transition 'nowhere'"),
    (lambda s: setattr(s[PLAIN], 'transitions', []), '/pregrasp_pose', 'outcomes but 0 transitions'),
    (lambda s: s.append(copy.deepcopy(s[PLAIN])), '/pregrasp_pose', 'duplicate state_path'),
    (lambda s: s.append(StateInstantiation('/ghost/x', 'LogState')), '/ghost/x', "parent '/ghost' is not a container"),
    (lambda s: s.append(StateInstantiation('/inner', ':STATEMACHINE', 'x', outcomes=['done'], transitions=['done'])),
     '/inner', 'containers inside the machine are not supported'),
    (lambda s: setattr(s[PLAIN], 'outcomes', 'done'), '/pregrasp_pose', 'outcomes must be a list of strings'),
    (lambda s: setattr(s[CONTAINER], 'cond_transition',
                       [OutcomeCondition(['ghost'], ['done'])] * len(s[CONTAINER].cond_outcome)),
     '/object_template_and_stand', "unknown inner state 'ghost'"),
])
def test_a_list_that_is_no_tree_is_refused_naming_the_path(change, item, text):
    states = copy.deepcopy(generated('concurrent.yaml'))
    assert (states[PLAIN].state_path, states[CONTAINER].state_class) == ('/pregrasp_pose', ':CONCURRENCY')
    change(states)
    with pytest.raises(SMGenerationError) as error:
        StateMachine.from_instantiations(states)
    assert error.value.item == item and text in str(error.value)
    assert error.value.code == 'SM_GENERATION_FAILED'
    assert any(text in problem for problem in validate_state_machine(states))


def test_dicts_with_unknown_fields_and_other_objects_are_refused():
    with pytest.raises(SMGenerationError) as error:
        StateMachine.from_instantiations([{'state_path': '/', 'colour': 'red'}])
    assert error.value.item == '/' and 'colour' in str(error.value)
    with pytest.raises(SMGenerationError) as error:
        StateMachine.from_instantiations([42])
    assert error.value.item == 'entry #0'
    with pytest.raises(SMGenerationError):
        StateMachine.from_instantiations([])


def test_nodes_read_as_their_state_instantiation():
    machine = StateMachine.from_instantiations(generated('look_down.yaml'))
    for node, entry in zip(machine.walk(), generated('look_down.yaml')):
        assert isinstance(node, State) and node.to_instantiation() == entry
