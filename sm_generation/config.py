"""The ``flexbe:`` section of a system configuration, validated.

::

    flexbe:
      sm_outcomes:              # SM-outcome proposition -> outcome of the generated machine
        finished: finished
        failed: failed
      packages:                 # optional: FlexBE packages implementing the classes below
        states: atlas_sim_flexbe_states          # state classes (module: class name in snake_case)
        state_classes: {InputState: flexbe_states}   # classes from another package
        behaviors: atlas_sim_flexbe_behaviors    # the :BEHAVIOR behaviors
      userdata:                 # optional: defaults of keys from outside (source text)
        goal_pose: '[2.0, 0.0, 0.0]'
      states:                   # activation proposition <p>_a (or sensor) -> FlexBE state
        look_down_a:
          class_decl: {name: TiltHeadState, param_names: [desired_tilt], param_values: ['-45.0']}
          output_mapping: {look_down_c: [done], look_down_f: [failed]}
          autonomy: 0           # one level for all outcomes, or a list in outcome order
          userdata_keys: []     # optional, same length as userdata_remapping
          userdata_remapping: []
          writes: []            # optional: the remapped keys the state writes (its output keys)

Userdata: a state reads the keys it remaps and does not list under ``writes``. A synthesized
machine declares the keys its states read and none of its states writes as input keys of its
root container (e.g. ``template_id`` when ``object_template`` held initially, so no InputState
runs); an exported behavior gives them the defaults of ``userdata`` (else ``None``), FlexBE's
behavior userdata. ``writes`` is checked against the real state classes in the test suite.
``class_decl.name`` is a state class, or ``:BEHAVIOR`` together with ``behavior_class``.
A state's outcomes are the values of its ``output_mapping`` in file order; a list-valued
``autonomy`` follows that order. Every problem raises an ``SMGenerationError`` subclass whose ``item``
is the dotted key of the offending entry (e.g. ``flexbe.states.look_down_a.autonomy``).
"""

from __future__ import annotations

from contextlib import contextmanager
from dataclasses import dataclass, field
from typing import Any, Iterator

from respec.vocabulary.naming import activated
from sm_generation.instantiation import StateInstantiation
from respec.robot import RobotSystem
from respec.robot.files import ConfigDirectoryNotFoundError, ConfigFileInvalidError, SystemNotFoundError
from sm_generation.errors import (AutonomyConfigInvalidError, FlexBEConfigInvalidError, NoSystemConfigError,
                                  SMGenerationError, StateConfigInvalidError, SystemConfigNotFoundError,
                                  UserdataConfigInvalidError)

BEHAVIOR_CLASS = StateInstantiation.CLASS_BEHAVIOR
# flexbe_states' state that asks the operator (flexbe/behavior_input); its ``request`` parameter
# is a flexbe_msgs/BehaviorInput request type.
INPUT_STATE_CLASS = 'InputState'
# FlexBE autonomy levels: Off/Inherit 0, Low 1, High 2, Full 3.
AUTONOMY_LEVELS = range(0, 4)


@dataclass(frozen=True)
class StateConfig:
    """How one proposition is implemented: a parametrized FlexBE state and its outcomes."""

    proposition: str
    state_class: str
    behavior_class: str
    parameter_names: tuple[str, ...]
    parameter_values: tuple[str, ...]
    output_mapping: dict[str, tuple[str, ...]]  # outcome proposition -> state outcomes
    autonomy: dict[str, int]                     # state outcome -> autonomy level
    userdata_keys: tuple[str, ...]
    userdata_remapping: tuple[str, ...]
    writes: tuple[str, ...] = ()                 # remapped keys the state writes

    @property
    def reads(self) -> tuple[str, ...]:
        """The remapped keys the state reads."""
        return tuple(key for key in self.userdata_remapping if key not in self.writes)

    @property
    def label(self) -> str:
        """Readable name: the proposition without its activation suffix (``look_down_a`` -> ``look_down``)."""
        return activated(self.proposition) or self.proposition

    @property
    def outcomes(self) -> tuple[str, ...]:
        """All outcomes of the state, in the order of ``output_mapping``."""
        return tuple(o for outcomes in self.output_mapping.values() for o in outcomes)

    def is_behavior(self) -> bool:
        return self.state_class == BEHAVIOR_CLASS


@dataclass(frozen=True)
class FlexBEConfig:
    """The validated ``flexbe:`` section of one system."""

    system: str
    sm_outcomes: dict[str, str]          # SM-outcome proposition -> machine outcome
    states: dict[str, StateConfig]       # proposition -> state configuration
    states_package: str = ''             # FlexBE package of the state classes ('' unknown)
    state_class_packages: dict[str, str] = field(default_factory=dict)  # exceptions: class -> package
    behavior_package: str = ''           # FlexBE package of the :BEHAVIOR behaviors
    userdata: dict[str, str] = field(default_factory=dict)  # key from outside -> default (source)

    def state_package(self, state_class: str) -> str:
        """The FlexBE package implementing ``state_class`` ('' when the config names none)."""
        return self.state_class_packages.get(state_class, self.states_package)

    def owner_of_outcome(self, outcome_proposition: str) -> StateConfig | None:
        """The state whose ``output_mapping`` contains ``outcome_proposition``."""
        for state in self.states.values():
            if outcome_proposition in state.output_mapping:
                return state
        return None


def input_request_capabilities(config: FlexBEConfig) -> dict[int, str]:
    """BehaviorInput request type -> the capability its InputState implements (e.g. 0 -> object_template)."""
    import ast

    capabilities = {}
    for state in config.states.values():
        if state.state_class == INPUT_STATE_CLASS and 'request' in state.parameter_names:
            value = state.parameter_values[state.parameter_names.index('request')]
            capabilities[int(ast.literal_eval(value))] = state.label
    return capabilities


@contextmanager
def generation_system_errors() -> Iterator[None]:
    """sm_generation's codes for a robot system read in this block that cannot be found or read,
    e.g. ``with generation_system_errors(): system = robot_system(name, config_dir)``."""
    try:
        yield
    except ConfigDirectoryNotFoundError as error:
        raise SystemConfigNotFoundError(str(error), error.item) from error
    except SystemNotFoundError as error:
        raise NoSystemConfigError(str(error), error.item) from error
    except ConfigFileInvalidError as error:
        raise FlexBEConfigInvalidError(str(error), error.item) from error


def flexbe_config(system: RobotSystem) -> FlexBEConfig:
    """The validated ``flexbe:`` section of an abstraction-kind system."""
    try:
        section = system.section('flexbe')
    except ConfigFileInvalidError as error:
        raise FlexBEConfigInvalidError(str(error), error.item) from error
    return parse_flexbe_config(section, system.name)


def parse_flexbe_config(section: object, system: str = '') -> FlexBEConfig:
    """Validate an already-parsed ``flexbe:`` mapping."""
    if not isinstance(section, dict):
        raise FlexBEConfigInvalidError('the flexbe section must be a mapping', 'flexbe')
    sm_outcomes = _sm_outcomes(section.get('sm_outcomes'))
    raw_states = section.get('states')
    if not isinstance(raw_states, dict) or not raw_states:
        raise FlexBEConfigInvalidError('flexbe.states must be a non-empty mapping of propositions to states',
                                       'flexbe.states')
    states = {}
    for proposition, entry in raw_states.items():
        if not isinstance(proposition, str) or not proposition:
            raise StateConfigInvalidError(f'flexbe.states: invalid proposition name {proposition!r}',
                                          f'flexbe.states.{proposition}')
        if proposition in sm_outcomes:
            raise StateConfigInvalidError(f'{proposition!r} is both an SM outcome and a state',
                                          f'flexbe.states.{proposition}')
        states[proposition] = _state_config(proposition, entry)
    _check_unique_outcome_owners(states)
    packages = _packages(section.get('packages'))
    return FlexBEConfig(system=system, sm_outcomes=sm_outcomes, states=states,
                        states_package=packages.get('states', ''),
                        state_class_packages=dict(packages.get('state_classes', {})),
                        behavior_package=packages.get('behaviors', ''),
                        userdata=_userdata(section.get('userdata')))


def _userdata(raw: object) -> dict[str, str]:
    key = 'flexbe.userdata'
    if raw is None:
        return {}
    if not isinstance(raw, dict):
        raise UserdataConfigInvalidError(f'{key} must map userdata keys to default values', key)
    for name, default in raw.items():
        if not isinstance(name, str) or not name.isidentifier():
            raise UserdataConfigInvalidError(f'{key}: {name!r} is not a userdata key (a Python name)', key)
        if isinstance(default, (list, dict)):
            raise UserdataConfigInvalidError(f'{key}.{name}: the default is Python source text, got {default!r}',
                                             f'{key}.{name}')
    # Like parameter values, defaults are source text: None stays None, 0 becomes '0'.
    return {name: 'None' if default is None else str(default) for name, default in raw.items()}


def _packages(raw: object) -> dict[str, Any]:
    key = 'flexbe.packages'
    if raw is None:
        return {}
    if not isinstance(raw, dict) or set(raw) - {'states', 'state_classes', 'behaviors'}:
        raise FlexBEConfigInvalidError(f'{key} may only name states, state_classes and '
                                       f'behaviors, got {raw!r}', key)
    for name in ('states', 'behaviors'):
        if name in raw and (not isinstance(raw[name], str) or not raw[name]):
            raise FlexBEConfigInvalidError(f'{key}.{name} must be a package name', f'{key}.{name}')
    classes = raw.get('state_classes', {})
    if not isinstance(classes, dict) or not all(isinstance(k, str) and isinstance(v, str) and v
                                                for k, v in classes.items()):
        raise FlexBEConfigInvalidError(f'{key}.state_classes must map class names to packages',
                                       f'{key}.state_classes')
    return raw


def _sm_outcomes(raw: object) -> dict[str, str]:
    key = 'flexbe.sm_outcomes'
    if not isinstance(raw, dict) or not raw:
        raise FlexBEConfigInvalidError(f'{key} must map SM-outcome propositions to outcome names', key)
    for proposition, outcome in raw.items():
        if not isinstance(proposition, str) or not isinstance(outcome, str) or not outcome:
            raise FlexBEConfigInvalidError(f'{key}.{proposition}: expected a non-empty outcome name, got {outcome!r}',
                                           f'{key}.{proposition}')
    return dict(raw)


def _string_list(value: object, key: str, error: type[SMGenerationError]) -> tuple[str, ...]:
    if value is None:
        return ()
    if not isinstance(value, list) or any(isinstance(v, (list, dict)) or v is None for v in value):
        raise error(f'{key} must be a list of strings, got {value!r}', key)
    # YAML reads False or 3 as bool/int; FlexBE parameters and keys are source text.
    return tuple(str(v) for v in value)


def _state_config(proposition: str, entry: object) -> StateConfig:
    where = f'flexbe.states.{proposition}'
    invalid = StateConfigInvalidError
    if not isinstance(entry, dict):
        raise invalid(f'{where} must be a mapping', where)
    for required in ('class_decl', 'output_mapping'):
        if required not in entry:
            raise invalid(f'{where} lacks {required!r}', f'{where}.{required}')

    decl = entry['class_decl']
    if not isinstance(decl, dict) or not isinstance(decl.get('name'), str) or not decl['name']:
        raise invalid(f'{where}.class_decl needs a class name', f'{where}.class_decl.name')
    behavior_class = decl.get('behavior_class', '')
    if decl['name'] == BEHAVIOR_CLASS and (not isinstance(behavior_class, str) or not behavior_class):
        raise invalid(f'{where}.class_decl: a {BEHAVIOR_CLASS} needs behavior_class',
                      f'{where}.class_decl.behavior_class')
    names = _string_list(decl.get('param_names'), f'{where}.class_decl.param_names', invalid)
    values = _string_list(decl.get('param_values'), f'{where}.class_decl.param_values', invalid)
    if len(names) != len(values):
        raise invalid(f'{where}.class_decl: {len(names)} param_names but '
                      f'{len(values)} param_values', f'{where}.class_decl.param_values')

    output_mapping = _output_mapping(entry['output_mapping'], f'{where}.output_mapping')
    outcomes = [o for os in output_mapping.values() for o in os]
    autonomy = _autonomy(entry.get('autonomy', 0), outcomes, f'{where}.autonomy')

    keys = _string_list(entry.get('userdata_keys'), f'{where}.userdata_keys', UserdataConfigInvalidError)
    remapping = _string_list(entry.get('userdata_remapping'), f'{where}.userdata_remapping',
                             UserdataConfigInvalidError)
    if len(keys) != len(remapping):
        raise UserdataConfigInvalidError(f'{where}: {len(keys)} userdata_keys but '
                                         f'{len(remapping)} userdata_remapping', f'{where}.userdata_remapping')
    if len(set(keys)) != len(keys):
        raise UserdataConfigInvalidError(f'{where}.userdata_keys lists a key twice',
                                         f'{where}.userdata_keys')
    writes = _string_list(entry.get('writes'), f'{where}.writes', UserdataConfigInvalidError)
    if set(writes) - set(remapping):
        raise UserdataConfigInvalidError(f'{where}.writes names {sorted(set(writes) - set(remapping))[0]!r}, '
                                         'which is none of its userdata_remapping', f'{where}.writes')
    return StateConfig(proposition=proposition, state_class=decl['name'],
                       behavior_class=behavior_class if decl['name'] == BEHAVIOR_CLASS else '',
                       parameter_names=names, parameter_values=values,
                       output_mapping=output_mapping, autonomy=autonomy,
                       userdata_keys=keys, userdata_remapping=remapping, writes=writes)


def _output_mapping(raw: object, where: str) -> dict[str, tuple[str, ...]]:
    invalid = StateConfigInvalidError
    if not isinstance(raw, dict) or not raw:
        raise invalid(f'{where} must map outcome propositions to state outcomes', where)
    mapping: dict[str, tuple[str, ...]] = {}
    seen: dict[str, object] = {}
    for proposition, outcomes in raw.items():
        if isinstance(outcomes, str):
            outcomes = [outcomes]
        if not isinstance(outcomes, list) or not outcomes or not all(isinstance(o, str) and o for o in outcomes):
            raise invalid(f'{where}.{proposition}: expected a non-empty list of outcomes',
                          f'{where}.{proposition}')
        for outcome in outcomes:
            if outcome in seen:
                raise invalid(f'{where}: outcome {outcome!r} means both '
                              f'{seen[outcome]!r} and {proposition!r}', f'{where}.{proposition}')
            seen[outcome] = proposition
        mapping[str(proposition)] = tuple(outcomes)
    return mapping


def _autonomy(raw: object, outcomes: list[str], where: str) -> dict[str, int]:
    def level(value: object) -> int:
        if isinstance(value, bool) or not isinstance(value, int) or value not in AUTONOMY_LEVELS:
            raise AutonomyConfigInvalidError(f'{where}: autonomy must be an integer 0..3, got {value!r}', where)
        return value

    if isinstance(raw, list):
        if len(raw) != len(outcomes):
            raise AutonomyConfigInvalidError(f'{where}: {len(raw)} levels for '
                                             f'{len(outcomes)} outcomes {outcomes}', where)
        return {outcome: level(value) for outcome, value in zip(outcomes, raw)}
    return {outcome: level(raw) for outcome in outcomes}


def _check_unique_outcome_owners(states: dict[str, StateConfig]) -> None:
    owners: dict[str, str] = {}
    for state in states.values():
        for proposition in state.output_mapping:
            if proposition in owners:
                raise StateConfigInvalidError(f'outcome proposition {proposition!r} is mapped by both '
                                              f'{owners[proposition]!r} and {state.proposition!r}',
                                              f'flexbe.states.{state.proposition}.output_mapping.{proposition}')
            owners[proposition] = state.proposition
