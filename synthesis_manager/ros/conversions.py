"""Conversions between the ROS-free cores and synthesis_msgs messages, in one place.

Nodes stay thin: they call a core function and use these helpers on the way in and out.
"""

from __future__ import annotations

from respec.automaton import Automaton, AutomatonState as CoreState
from respec.vocabulary.errors import ErrorCode
from synthesis_msgs.msg import (AutomatonState, FSAutomaton, LTLSpecification, OutcomeCondition,
                                StateInstantiation, SynthesisErrorCodes)

LTL_SECTIONS = ('sys_props', 'env_props', 'sys_init', 'env_init', 'sys_trans', 'env_trans',
                'sys_liveness', 'env_liveness')


def error_code(code: ErrorCode | str = ErrorCode.SUCCESS, message: str = '') -> SynthesisErrorCodes:
    """The SynthesisErrorCodes message of ``code`` (an ErrorCode or its name; any other name
    is a programming error: ValueError)."""
    return SynthesisErrorCodes(value=ErrorCode(code).number, message=message)  # type: ignore[call-arg]  # a lookup by value (mypy: a constructor)


def constants(message_type) -> dict[str, int]:
    """A message type's integer constants, name -> value (e.g. an error code's)."""
    return {name: value for name, value in vars(message_type).items()
            if name.isupper() and isinstance(value, int) and not isinstance(value, bool)}


def error_name(value: int, codes=None) -> str:
    """The constant name of an error code value, e.g. -21 -> 'SPEC_UNSYNTHESIZABLE' (ours, or
    of the message type ``codes``, such as CNU's); an unknown value is shown as its number."""
    if codes is None:
        return ErrorCode.name_of(value)
    return next((name for name, constant in constants(codes).items() if constant == value), str(value))


def spec_to_msg(spec) -> LTLSpecification:
    """respec GR1Specification -> LTLSpecification."""
    return sections_to_msg(spec.to_text_sections())


def sections_to_msg(sections: dict) -> LTLSpecification:
    return LTLSpecification(**{name: list(sections.get(name, [])) for name in LTL_SECTIONS})


def msg_to_sections(message: LTLSpecification) -> dict[str, list[str]]:
    """LTLSpecification -> dict of section name -> list of strings (empty sections dropped)."""
    return {name: list(getattr(message, name)) for name in LTL_SECTIONS if getattr(message, name)}


def is_empty_spec(message: LTLSpecification) -> bool:
    return not any(getattr(message, name) for name in LTL_SECTIONS)


def automaton_to_msg(automaton: Automaton) -> FSAutomaton:
    """respec Automaton -> FSAutomaton."""
    return FSAutomaton(
        output_variables=list(automaton.output_variables),
        input_variables=list(automaton.input_variables),
        automaton=[AutomatonState(name=s.name, output_valuation=[bool(v) for v in s.output_valuation],
                                  input_valuation=[bool(v) for v in s.input_valuation],
                                  transitions=list(s.transitions), rank=int(s.rank))
                   for s in automaton.states],
        initial_states=list(automaton.initial_states))


def msg_to_automaton(message: FSAutomaton) -> Automaton:
    """FSAutomaton -> respec Automaton."""
    return Automaton(
        output_variables=list(message.output_variables),
        input_variables=list(message.input_variables),
        states=[CoreState(name=s.name, output_valuation=list(s.output_valuation),
                          input_valuation=list(s.input_valuation),
                          transitions=list(s.transitions), rank=int(s.rank))
                for s in message.automaton],
        initial_states=list(message.initial_states))


def state_to_msg(state) -> StateInstantiation:
    """sm_generation StateInstantiation (dataclass) -> StateInstantiation message."""
    fields = state.to_dict()
    fields['cond_transition'] = [OutcomeCondition(state_name=list(c['state_name']),
                                                  state_outcome=list(c['state_outcome']))
                                 for c in fields['cond_transition']]
    fields['position'] = [float(x) for x in fields['position']]
    fields['autonomy'] = [int(a) for a in fields['autonomy']]
    return StateInstantiation(**fields)


def msg_to_state_dict(message: StateInstantiation) -> dict:
    """StateInstantiation message -> plain dict of its 16 fields (JSON/YAML friendly)."""
    result = {}
    for name in message.get_fields_and_field_types():
        value = getattr(message, name)
        if name == 'cond_transition':
            value = [{'state_name': list(c.state_name), 'state_outcome': list(c.state_outcome)}
                     for c in value]
        elif name == 'position':
            value = [float(x) for x in value]
        elif name == 'autonomy':
            value = [int(x) for x in value]
        elif not isinstance(value, str):
            value = list(value)
        result[name] = value
    return result
