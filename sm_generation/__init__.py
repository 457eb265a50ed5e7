"""sm_generation: synthesized automata -> FlexBE state machines (ROS-free).

    >>> from sm_generation import generate_state_machine, load_automaton, validate_state_machine
    >>> from respec.robot import robot_system
    >>> machine = generate_state_machine(load_automaton('test/automata/look_down.yaml'), robot_system('atlas'))
    >>> validate_state_machine(machine.to_instantiations())
    []

Modules:
    instantiation  StateInstantiation / OutcomeCondition (fields of flexbe_msgs)
    config         the validated ``flexbe:`` section of config/<system>.yaml
    automaton_io   reading and writing automata (our YAML/JSON, slugs strategies)
    abstract_machine  automaton -> AbstractMachine, the automaton-shaped intermediate (observations, exits)
    reduction      merging bisimilar states
    layout         positions for the FlexBE editor
    generator      the engine: automaton + FlexBE mapping -> StateMachine tree
    for_system     generate_state_machine: the front door, the mapping chosen by the system's kind
    capabilities   the FlexBE mapping of a CNU capability system
    state_machine  StateMachine (the FlexBE tree that travels; the list at the wire), validate_state_machine
    export         YAML, JSON, Graphviz DOT, SVG/PNG
    cli            ``behavior-synthesis generate-sm`` / ``python -m sm_generation``
"""

from respec.automaton import Automaton, AutomatonState
from sm_generation.automaton_io import load_automaton
from sm_generation.errors import SMGenerationError
from sm_generation.for_system import generate_state_machine
from sm_generation.instantiation import OutcomeCondition, StateInstantiation, count_states
from sm_generation.state_machine import StateMachine, validate_state_machine

__all__ = ['Automaton', 'AutomatonState', 'OutcomeCondition', 'count_states', 'SMGenerationError', 'StateInstantiation',
           'StateMachine', 'generate_state_machine', 'load_automaton', 'validate_state_machine']
