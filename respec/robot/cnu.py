"""Robots described by capabilities, in the format of CNU's flexbe_synthesis (ROS-free).

A system file of ours may point at CNU's files instead of describing the robot itself::

    system: vending_demo
    cnu_capabilities: vending/vending_capabilities.yaml   # required
    cnu_spec: vending/vending_demo_capabilities_spec.yaml # optional: extra propositions, initial values
    cnu_mappings: mappings/global_mappings.yaml           # optional: outcome names, SM outcomes
    cnu_pipeline: capabilities                            # optional: or full_spec (see below)
    cnu_state_machine: hello_world/sm/hello_world_sm.yaml # optional: a given machine (see below)

Paths are relative to the system file. Without ``cnu_mappings`` the meaning of CNU's global
mappings applies (``done``/``finished``/``received``/``true`` complete, the usual failure
names fail; the machine ends in ``finished``).

A capability names its FlexBE ``interface`` class, its ``parameters`` (constants, or ``@var``:
the value the strategy gives integer variable ``var`` while the capability runs),
``preconditions`` (a list of conjuncts, each ``a | b | ...``), ``postconditions`` and
``transition_relation`` per outcome (a plain list means the completion outcome) and
``autonomy`` per FlexBE outcome. Inside conditions a capability name or a ``memory:`` name
means its memory proposition ``<name>_m``; ``x=3`` / ``x!=3`` compare an integer variable;
``@x`` (postconditions only) lets the system choose ``x``; other names must be propositions
of the capability system (``<cap>_a``, ``<cap>_c``, or the spec's INPUT/OUTPUT).

Integer variables (``variable_mappings``, or ``x:0...3`` in the spec) are slugs-style
integers, bit-blasted exactly as structured slugs does (``x@0.0.3``, ``x@1``), so the
specification files we write are valid structured-slugs input too.

The spec file may hold every section of a slugs specification (INPUT, OUTPUT, ENV_INIT,
SYS_INIT, ENV_TRANS, SYS_TRANS, ENV_LIVENESS, SYS_LIVENESS; formulas in structured-slugs infix,
``x'`` or ``next(x)``). CNU's processes pipeline decides what becomes of them, and so does
``cnu_pipeline``: ``capabilities`` (CNU's capability_processes_def) adds the file's formulas to
the ones the capabilities give; ``full_spec`` (CNU's full_spec_processes_def) takes the file as
the whole specification, to which only the request is added; the capabilities then give the
FlexBE state of each ``<capability>_a``.

``cnu_state_machine`` names a hand-written machine in CNU's ``sm/`` format (CNU's given-automaton
route, its ``sm_loader``): ``sm: {outcomes, initial_state}`` and ``states``, each with
``name``, ``state_class``, ``parameters`` (Python source text), ``outcomes``, ``transitions``
and ``autonomy`` (lists in the order of the outcomes). Its states replace the capabilities:
each becomes a capability whose transition relation is the machine's, started first if it is
the initial state, so the request's specification allows exactly the given machine.

Every problem raises ``CapabilityConfigError`` whose ``item`` is ``<capability>.<key>`` (or
the file key) of the offending entry.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field, replace
from typing import Any, Callable, Mapping

from respec.untrusted import BoundedYamlError, load_bounded_yaml
from respec.vocabulary.errors import ErrorCode
from respec.vocabulary.naming import COMPLETED, FAILED, FINISHED, activation
from respec.robot.files import MAX_CONFIG_DEPTH, ConfigFileInvalidError, SystemConfigError

CAPABILITIES_KEY, SPEC_KEY, MAPPINGS_KEY = 'cnu_capabilities', 'cnu_spec', 'cnu_mappings'
PIPELINE_KEY, STATE_MACHINE_KEY = 'cnu_pipeline', 'cnu_state_machine'
SYSTEM_FILE_KEYS = ('system', CAPABILITIES_KEY, SPEC_KEY, MAPPINGS_KEY, PIPELINE_KEY, STATE_MACHINE_KEY, 'reduce')
#: The system file's keys that name another file.
CNU_FILE_KEYS = (CAPABILITIES_KEY, SPEC_KEY, MAPPINGS_KEY, STATE_MACHINE_KEY)
CAPABILITIES_PIPELINE, FULL_SPEC_PIPELINE = 'capabilities', 'full_spec'   # CNU's two processes pipelines
FAILURE = 'failure'  # CNU's transition outcome of a failure; success is COMPLETED

# The meaning of CNU's generic global_mappings.yaml, used when a system names no mappings file.
DEFAULT_STATE_OUTCOMES = {
    'done': COMPLETED, 'finished': COMPLETED, 'received': COMPLETED, 'true': COMPLETED,
    'aborted': FAILURE, 'canceled': FAILURE, 'data_error': FAILURE, 'empty': FAILURE,
    'failed': FAILURE, 'false': FAILURE, 'no_connection': FAILURE, 'param_error': FAILURE,
    'timeout': FAILURE, 'unavailable': FAILURE,
}
CNU_SM_OUTCOMES = {FINISHED: FINISHED}  # CNU's global mappings: outcome -> SM outcome
DEFAULT_TRANSITION_OUTCOMES = (COMPLETED, FAILURE)

_NAME = re.compile(r'^[A-Za-z][A-Za-z0-9_]*$')
_COMPARISON = re.compile(r'^([A-Za-z][A-Za-z0-9_]*)\s*(!=|=)\s*(-?[0-9]+)$')
_INTEGER_DECLARATION = re.compile(r'^([A-Za-z][A-Za-z0-9_]*)\s*:\s*(-?[0-9]+)\s*\.\.\.\s*(-?[0-9]+)$')
_CAPABILITY_KEYS = ('interface', 'parameters', 'preconditions', 'postconditions', 'transition_relation',
                    'autonomy', 'outcomes')
_FILE_KEYS = ('name', 'capabilities', 'variable_mappings', 'state_outcome_mappings', 'memory')
_INITIAL_SECTIONS = ('ENV_INIT', 'SYS_INIT')
_FORMULA_SECTIONS = (*_INITIAL_SECTIONS, 'ENV_TRANS', 'SYS_TRANS', 'ENV_LIVENESS', 'SYS_LIVENESS')
_SPEC_SECTIONS = ('INPUT', 'OUTPUT', *_FORMULA_SECTIONS)
# CNU's files may spell a memory proposition with their suffix; ours is added by respec.vocabulary.naming.
CNU_MEMORY_SUFFIX = '_m'
# YAML reads `true`/`false` keys as booleans; CNU's mappings quote them, but be lenient.
_YAML_WORDS: dict[object, str] = {True: 'true', False: 'false'}


class CapabilityConfigError(SystemConfigError):
    """A CNU capability, spec or mappings file is invalid; ``item`` names the entry."""

    code = ErrorCode.ABSTRACTION_CONFIG_INVALID


@dataclass(frozen=True)
class Literal:
    """One term of a condition: ``name`` (a proposition, memory or integer), negated or compared.

    ``value`` is None for a Boolean term; for an integer term it is the compared value and
    ``negated`` means ``!=``. ``choose`` marks ``@var`` (the system picks the value).
    """

    name: str
    negated: bool = False
    value: int | None = None
    choose: bool = False


Clause = tuple[Literal, ...]   # a disjunction


@dataclass(frozen=True)
class Capability:
    name: str
    interface: str
    parameters: dict[str, object]
    preconditions: tuple[Clause, ...]
    postconditions: dict[str, tuple[Literal, ...]]          # transition outcome -> literals
    transition_relation: dict[str, tuple[Clause, ...]]      # transition outcome -> clauses of targets
    autonomy: dict[str, int]                                # FlexBE outcome -> level
    declared_outcomes: tuple[str, ...] = ()                 # FlexBE outcomes given in the file, if any

    def variable_parameters(self) -> dict[str, str]:
        """Parameters taken from the strategy: parameter -> integer variable (``@var``)."""
        return {key: value[1:] for key, value in self.parameters.items()
                if isinstance(value, str) and value.startswith('@')}


@dataclass(frozen=True)
class IntegerRange:
    name: str
    low: int
    high: int
    environment: bool = False
    value_names: dict[int, str] = field(default_factory=dict)


@dataclass(frozen=True)
class CapabilitySystem:
    """A validated CNU capability system (all mappings in file order)."""

    system: str
    capabilities: dict[str, Capability]
    integers: dict[str, IntegerRange]
    memory: dict[str, bool]                 # memory name (without _m) -> initial value
    state_outcomes: dict[str, str]          # FlexBE outcome -> transition outcome
    sm_outcomes: dict[str, str]             # SM-outcome key -> machine outcome
    transition_outcomes: tuple[str, ...]
    spec_inputs: tuple[str, ...] = ()       # Boolean propositions the spec file adds
    spec_outputs: tuple[str, ...] = ()
    spec_initial: tuple[str, ...] = ()      # the spec's ENV_INIT and SYS_INIT entries (text)
    spec_formulas: tuple[tuple[str, str], ...] = ()   # (section, e.g. 'sys_trans', infix text), all sections
    full_spec: bool = False                 # CNU's full-spec pipeline: the spec file is the specification
    reduce: bool = True
    source: str = ''

    # The robot interface (respec.robot.description.RobotDescription).
    reads_robot_state_by_default = False   # its spec file gives the initial conditions
    orders_goals = False                   # CNU's goals hold together at the end

    @property
    def default_initial_conditions(self) -> list[str]:
        """Nothing to name: the spec file's ENV_INIT and SYS_INIT entries and the memories' values apply."""
        return []

    @property
    def sensors(self) -> tuple[str, ...]:
        """The Boolean inputs its spec file adds (capabilities' outcomes report some of them)."""
        return self.spec_inputs

    def outcome_proposition(self, capability: str, transition_outcome: str) -> str:
        """CNU's name: the capability and the outcome's first letter (``br_c``, ``pay_f``)."""
        return f'{capability}_{transition_outcome[0]}'

    def sm_outcome(self, key: str) -> str:
        """The machine outcome the mappings name for ``key`` (``finished``, ``failed``); the key
        itself when they name none (a request may ask for ``failed`` although CNU's global
        mappings leave it out to recover from failures)."""
        return self.sm_outcomes.get(key, key)

    def possible_sm_outcomes(self) -> tuple[str, ...]:
        """Every outcome a machine of this system may end in: the mappings', and ``failed`` for
        the capability pipeline (a request may ask for it; a full specification is as written)."""
        extra = [] if self.full_spec else [self.sm_outcome(FAILED)]
        return tuple(dict.fromkeys([*self.sm_outcomes.values(), *extra]))

    def transition_outcome(self, capability: str, outcome: str) -> str:
        """The transition outcome a FlexBE outcome of ``capability`` means."""
        key = outcome if outcome in self.state_outcomes else _YAML_WORDS.get(outcome, outcome)
        if key not in self.state_outcomes:
            raise CapabilityConfigError(
                f'{self.system}: outcome {outcome!r} of capability {capability!r} has no '
                f'state_outcome_mappings entry (known: {", ".join(self.state_outcomes)})',
                item=f'{capability}.outcomes.{outcome}')
        return self.state_outcomes[key]


def is_capability_document(document: object) -> bool:
    """Whether a parsed system file points at CNU capability files (or a given machine)."""
    return isinstance(document, dict) and (CAPABILITIES_KEY in document or STATE_MACHINE_KEY in document)


def load_capability_system(document: Mapping[str, object], system: str, read: Callable[[str], str]) -> CapabilitySystem:
    """The capability system a system file (``document``) points at; ``read`` gives the text of a
    file named relative to the system file (raising OSError when it cannot)."""
    for key in document:
        if key not in SYSTEM_FILE_KEYS:
            raise CapabilityConfigError(f'{system}.yaml: unknown key {key!r} next to {CAPABILITIES_KEY} '
                                        f'(expected {", ".join(SYSTEM_FILE_KEYS)})', item=str(key))
    reduce = document.get('reduce', True)
    if not isinstance(reduce, bool):
        raise CapabilityConfigError(f'{system}.yaml: reduce must be true or false', item='reduce')
    pipeline = document.get(PIPELINE_KEY, CAPABILITIES_PIPELINE)
    if pipeline not in (CAPABILITIES_PIPELINE, FULL_SPEC_PIPELINE):
        raise CapabilityConfigError(f'{system}.yaml: {PIPELINE_KEY} must be {CAPABILITIES_PIPELINE} or '
                                    f'{FULL_SPEC_PIPELINE}, got {pipeline!r}', item=PIPELINE_KEY)
    machine = _read_yaml(document, STATE_MACHINE_KEY, read, system)
    capabilities = _read_yaml(document, CAPABILITIES_KEY, read, system, required=machine is None)
    spec = _read_yaml(document, SPEC_KEY, read, system) or {}
    mappings = _read_yaml(document, MAPPINGS_KEY, read, system)
    initial: tuple[str, ...] = ()
    if machine is not None:
        if capabilities is not None and not isinstance(capabilities, dict):
            raise CapabilityConfigError(f'{system}: the capabilities file must hold a mapping', item=CAPABILITIES_KEY)
        given, initial = capabilities_of_state_machine(machine, system)
        capabilities = {**(capabilities or {}), 'capabilities': given}
    result = capability_system_from_dicts(capabilities, spec, mappings, system, reduce,
                                          source=str(document.get(CAPABILITIES_KEY) or document[STATE_MACHINE_KEY]),
                                          full_spec=pipeline == FULL_SPEC_PIPELINE)
    if machine is not None:
        _check_one_target_per_outcome(result)
        result = replace(result, spec_initial=(*result.spec_initial, *initial))
    return result


def capabilities_of_state_machine(machine: object, system: str) -> tuple[dict[str, dict[str, object]], tuple[str, ...]]:
    """A machine in CNU's ``sm/`` format as capability entries, and the initial condition that
    starts its initial state. Parameters are Python source text already: ``*`` keeps them verbatim
    (``sm_generation.capabilities.parameter_source``)."""
    where = f'{system}: the state machine file'
    if not isinstance(machine, dict) or not isinstance(machine.get('sm'), dict) \
            or not isinstance(machine.get('states'), list) or not machine['states']:
        raise CapabilityConfigError(f'{where} must hold sm (outcomes, initial_state) and a list of states',
                                    item=STATE_MACHINE_KEY)
    capabilities: dict[str, dict[str, object]] = {}
    for index, state in enumerate(machine['states']):
        name = state.get('name') if isinstance(state, dict) else None
        item = f'states.{name if isinstance(name, str) else index}'
        if not isinstance(name, str) or not _NAME.match(name) or name in capabilities:
            raise CapabilityConfigError(f'{where}: state {index} needs a new name', item=item)
        outcomes, transitions = state.get('outcomes') or [], state.get('transitions') or []
        autonomy = state.get('autonomy') or []
        parameters = state.get('parameters') or {}
        if (not isinstance(outcomes, list) or not isinstance(transitions, list) or not isinstance(autonomy, list)
                or len(transitions) != len(outcomes) or len(autonomy) not in (0, len(outcomes))):
            raise CapabilityConfigError(f'{where}: state {name!r} needs outcomes, transitions and autonomy '
                                        'as lists of one length', item=item)
        if not isinstance(parameters, dict):
            raise CapabilityConfigError(f'{where}: state {name!r}: parameters must be a mapping', item=item)
        capabilities[name] = {
            'interface': state.get('state_class'),
            'parameters': {key: f'*{value}' for key, value in parameters.items()},
            'outcomes': [_word(o) for o in outcomes],
            'transition_relation': {_word(o): [str(t)] for o, t in zip(outcomes, transitions)},
            'autonomy': {_word(o): level for o, level in zip(outcomes, autonomy)},
        }
    first = machine['sm'].get('initial_state', machine['states'][0].get('name'))
    if first not in capabilities:
        raise CapabilityConfigError(f'{where}: initial_state {first!r} is none of its states', item='sm.initial_state')
    return capabilities, (activation(first),)


def _check_one_target_per_outcome(system: CapabilitySystem) -> None:
    """Two FlexBE outcomes of a given state that mean the same transition outcome must lead to the
    same state: the specification sees the transition outcome only."""
    for name, capability in system.capabilities.items():
        for outcome, clauses in capability.transition_relation.items():
            if len(set(clauses)) > 1:
                raise CapabilityConfigError(
                    f'{system.system}: state {name!r} leads to different states on outcomes that all mean '
                    f'{outcome!r}; give them different transition outcomes in the mappings', item=f'states.{name}')


def capability_system_from_dicts(capabilities: object, spec: object = None, mappings: object = None,
                                 system: str = '<dict>', reduce: bool = True, source: str = '',
                                 full_spec: bool = False) -> CapabilitySystem:
    """Validate parsed CNU files (capabilities, spec, mappings) and build the system."""
    if not isinstance(capabilities, dict):
        raise CapabilityConfigError(f'{system}: the capabilities file must hold a mapping', item=CAPABILITIES_KEY)
    for key in capabilities:
        if key not in _FILE_KEYS:
            raise CapabilityConfigError(f'{system}: unknown key {key!r} in the capabilities file '
                                        f'(expected {", ".join(_FILE_KEYS)})', item=str(key))
    state_outcomes, sm_outcomes, transition_outcomes = _mappings(mappings, system)
    own = _mapping(capabilities.get('state_outcome_mappings'), system, 'state_outcome_mappings')
    state_outcomes = {**state_outcomes, **{_word(k): str(v) for k, v in own.items()}}
    for outcome, meaning in state_outcomes.items():
        if meaning not in transition_outcomes:
            raise CapabilityConfigError(f'{system}: outcome {outcome!r} maps to {meaning!r}, not one of '
                                        f'{", ".join(transition_outcomes)}', item=f'state_outcome_mappings.{outcome}')

    integers = _integers(capabilities.get('variable_mappings'), system)
    inputs, outputs, initial, formulas = _spec(spec, system, integers)
    memory = _memory(capabilities.get('memory'), system)
    raw = capabilities.get('capabilities')
    if not isinstance(raw, dict) or not raw:
        raise CapabilityConfigError(f'{system}: capabilities must be a non-empty mapping', item='capabilities')
    names = set(raw) | set(memory)
    parsed = {}
    for name, entry in raw.items():
        if not isinstance(name, str) or not _NAME.match(name):
            raise CapabilityConfigError(f'{system}: invalid capability name {name!r}', item=str(name))
        parsed[name] = _capability(name, entry, system, transition_outcomes, state_outcomes, integers, names)
    result = CapabilitySystem(system=system, capabilities=parsed, integers=integers, memory=memory,
                              state_outcomes=state_outcomes, sm_outcomes=sm_outcomes,
                              transition_outcomes=transition_outcomes, spec_inputs=inputs, spec_outputs=outputs,
                              spec_initial=initial, spec_formulas=formulas, full_spec=full_spec, reduce=reduce,
                              source=source)
    _check_targets(result)
    return result


# --- files ----------------------------------------------------------------------------------

def _read_yaml(document: Mapping[str, object], key: str, read: Callable[[str], str], system: str,
               required: bool = False) -> object:
    value = document.get(key)
    if value is None:
        if required:
            raise CapabilityConfigError(f'{system}.yaml: {key} must name a file', item=key)
        return None
    if not isinstance(value, str) or not value:
        raise CapabilityConfigError(f'{system}.yaml: {key} must be a path, got {value!r}', item=key)
    try:
        text = read(value)
    except ConfigFileInvalidError as error:  # outside the config folder, not a regular file, too large
        raise CapabilityConfigError(f'{system}.yaml: {key}: {error}', item=key) from None
    except OSError as error:
        raise CapabilityConfigError(f'{system}.yaml: {key} {value!r} cannot be read ({error.strerror})',
                                    item=key) from None
    try:
        return load_bounded_yaml(text, MAX_CONFIG_DEPTH)
    except BoundedYamlError as error:
        raise CapabilityConfigError(f'{system}.yaml: {key} {value!r}: {error}', item=key) from None


def _mappings(mappings: object, system: str) -> tuple[dict[str, str], dict[str, str], tuple[str, ...]]:
    if mappings is None:
        return dict(DEFAULT_STATE_OUTCOMES), dict(CNU_SM_OUTCOMES), DEFAULT_TRANSITION_OUTCOMES
    if not isinstance(mappings, dict):
        raise CapabilityConfigError(f'{system}: the mappings file must hold a mapping', item=MAPPINGS_KEY)
    transition_outcomes = mappings.get('transition_outcomes', list(DEFAULT_TRANSITION_OUTCOMES))
    if (not isinstance(transition_outcomes, list) or not transition_outcomes
            or not all(isinstance(o, str) and _NAME.match(o) for o in transition_outcomes)):
        raise CapabilityConfigError(f'{system}: transition_outcomes must list outcome names',
                                    item='transition_outcomes')
    letters = [o[0] for o in transition_outcomes]
    if len(set(letters)) != len(letters) or 'a' in letters or 'm' in letters:
        raise CapabilityConfigError(f'{system}: transition_outcomes need distinct first letters other than '
                                    f'a and m (the activation and memory suffixes)', item='transition_outcomes')
    result: list[dict[str, str]] = []
    for key in ('state_outcome_mappings', 'sm_outcome_mappings'):
        value = mappings.get(key) or {}
        if not isinstance(value, dict) or not all(isinstance(v, str) and v for v in value.values()):
            raise CapabilityConfigError(f'{system}: {key} must map names to names', item=key)
        result.append({_word(k): v for k, v in value.items()})
    return result[0], result[1], tuple(transition_outcomes)


def _word(key: object) -> str:
    return _YAML_WORDS.get(key, str(key)) if isinstance(key, bool) else str(key)


def _mapping(raw: object, system: str, key: str) -> dict[Any, Any]:
    """The mapping under ``key`` (empty when absent); anything else names the key."""
    if raw is None:
        return {}
    if not isinstance(raw, dict):
        raise CapabilityConfigError(f'{system}: {key} must be a mapping', item=key)
    return raw


def _integers(raw: object, system: str) -> dict[str, IntegerRange]:
    raw = _mapping(raw, system, 'variable_mappings')
    integers: dict[str, IntegerRange] = {}
    for side, environment in (('env_props', True), ('sys_props', False)):
        variables = _mapping(raw.get(side), system, f'variable_mappings.{side}')
        for name, values in variables.items():
            where = f'variable_mappings.{side}.{name}'
            if not isinstance(name, str) or not _NAME.match(name) or name in integers:
                raise CapabilityConfigError(f'{system}: invalid or repeated variable name {name!r}', item=where)
            if (not isinstance(values, dict) or not values
                    or not all(isinstance(v, int) and not isinstance(v, bool) for v in values)):
                raise CapabilityConfigError(f'{system}: {where} must map integer values to names', item=where)
            integers[name] = IntegerRange(name, min(values), max(values), environment,
                                          {int(k): str(v) for k, v in values.items()})
    unknown = set(raw) - {'env_props', 'sys_props'}
    if unknown:
        raise CapabilityConfigError(f'{system}: variable_mappings may only hold env_props and sys_props',
                                    item=f'variable_mappings.{sorted(unknown)[0]}')
    return integers


def _spec(spec: object, system: str, integers: dict[str, IntegerRange]
          ) -> tuple[tuple[str, ...], tuple[str, ...], tuple[str, ...], tuple[tuple[str, str], ...]]:
    """The spec file's propositions, its initial values (text) and its formulas (section, text)."""
    if not spec:
        return (), (), (), ()
    if not isinstance(spec, dict):
        raise CapabilityConfigError(f'{system}: the spec file must hold a mapping', item=SPEC_KEY)
    sections = spec.get('specs') or {}
    if not isinstance(sections, dict):
        raise CapabilityConfigError(f'{system}: specs must map slugs sections to lists', item='specs')
    inputs: list[str] = []
    outputs: list[str] = []
    initial: list[str] = []
    formulas: list[tuple[str, str]] = []  # (section, text)
    for section, entries in sections.items():
        where = f'specs.{section}'
        if section not in _SPEC_SECTIONS:
            raise CapabilityConfigError(f'{system}: spec section {section!r} is not supported for capability '
                                        f'systems (supported: {", ".join(_SPEC_SECTIONS)})', item=where)
        if entries is None:   # a header without entries, as slugs allows
            continue
        if not isinstance(entries, list) or not all(isinstance(e, str) and e.strip() for e in entries):
            raise CapabilityConfigError(f'{system}: {where} must be a list of strings', item=where)
        for entry in entries:
            entry = entry.strip()
            if section in ('INPUT', 'OUTPUT'):
                declaration = _INTEGER_DECLARATION.match(entry)
                if declaration:
                    name, low, high = declaration[1], int(declaration[2]), int(declaration[3])
                    known = integers.get(name)
                    if low > high or (known and (known.low, known.high) != (low, high)):
                        raise CapabilityConfigError(f'{system}: {where} declares {entry!r}, which differs from '
                                                    'variable_mappings or is empty', item=entry)
                    if not known:
                        integers[name] = IntegerRange(name, low, high, section == 'INPUT')
                elif _NAME.match(entry):
                    (inputs if section == 'INPUT' else outputs).append(entry)
                else:
                    raise CapabilityConfigError(f'{system}: {where} entry {entry!r} is not a name or '
                                                'name:low...high', item=entry)
            else:
                formulas.append((section.lower(), entry))
                if section in _INITIAL_SECTIONS:
                    initial.append(entry)
    return tuple(inputs), tuple(outputs), tuple(initial), tuple(formulas)


def _memory(raw: object, system: str) -> dict[str, bool]:
    raw = _mapping(raw, system, 'memory')
    memory: dict[str, bool] = {}
    for side, names in raw.items():
        if side != 'sys_props' or not isinstance(names, dict):
            raise CapabilityConfigError(f'{system}: memory may only hold sys_props: name -> initial value',
                                        item=f'memory.{side}')
        for name, initial in names.items():
            name = str(name).removesuffix(CNU_MEMORY_SUFFIX)
            if not _NAME.match(name) or not isinstance(initial, bool):
                raise CapabilityConfigError(f'{system}: memory entry {name!r} needs a name and true/false',
                                            item=f'memory.sys_props.{name}')
            memory[name] = initial
    return memory


# --- capabilities ---------------------------------------------------------------------------

def _capability(name: str, entry: object, system: str, transition_outcomes: tuple[str, ...],
                state_outcomes: dict[str, str], integers: dict[str, IntegerRange], names: set[str]) -> Capability:
    where = f'{system}: capability {name!r}'
    if not isinstance(entry, dict):
        raise CapabilityConfigError(f'{where} must be a mapping', item=name)
    for key in entry:
        if key not in _CAPABILITY_KEYS:
            raise CapabilityConfigError(f'{where}: unknown key {key!r} (expected {", ".join(_CAPABILITY_KEYS)})',
                                        item=f'{name}.{key}')
    interface = entry.get('interface')
    if not isinstance(interface, str) or not _NAME.match(interface):
        raise CapabilityConfigError(f'{where}: interface must name a FlexBE state class', item=f'{name}.interface')
    parameters = entry.get('parameters') or {}
    if not isinstance(parameters, dict) or not all(isinstance(k, str) and _NAME.match(k) for k in parameters):
        raise CapabilityConfigError(f'{where}: parameters must map parameter names to values',
                                    item=f'{name}.parameters')
    for key, value in parameters.items():
        if isinstance(value, str) and value.startswith('@') and value[1:] not in integers:
            raise CapabilityConfigError(f'{where}: parameter {key} takes {value!r}, but {value[1:]!r} is no '
                                        f'integer variable (known: {", ".join(integers) or "none"})',
                                        item=f'{name}.parameters.{key}')
    declared = entry.get('outcomes') or ()
    if declared and (not isinstance(declared, list) or not all(isinstance(o, str) for o in declared)):
        raise CapabilityConfigError(f'{where}: outcomes must list FlexBE outcome names', item=f'{name}.outcomes')

    def outcome_key(key: object, what: str) -> str:
        key = _word(key)
        if key in transition_outcomes:
            return key
        if key in state_outcomes:
            return state_outcomes[key]
        raise CapabilityConfigError(f'{where}: {what} key {key!r} is neither a transition outcome '
                                    f'({", ".join(transition_outcomes)}) nor a mapped FlexBE outcome',
                                    item=f'{name}.{what}.{key}')

    def literal(text: str, key: str, allow_choice: bool) -> Literal:
        return parse_literal(text, f'{name}.{key}', where, integers, allow_choice)

    preconditions = tuple(tuple(literal(term, 'preconditions', False) for term in _terms(clause, name, 'preconditions'))
                          for clause in _list(entry.get('preconditions'), name, 'preconditions'))
    postconditions: dict[str, tuple[Literal, ...]] = {}
    for key, items in _by_outcome(entry.get('postconditions'), name, 'postconditions').items():
        outcome = outcome_key(key, 'postconditions')
        literals: list[Literal] = []
        for item in _list(items, name, f'postconditions.{key}'):
            if '|' in str(item):
                raise CapabilityConfigError(f'{where}: postcondition {item!r} is a disjunction; postconditions '
                                            'are single literals', item=f'{name}.postconditions.{key}')
            literals.append(literal(item, f'postconditions.{key}', True))
        postconditions[outcome] = postconditions.get(outcome, ()) + tuple(literals)
    relation: dict[str, tuple[Clause, ...]] = {}
    for key, items in _by_outcome(entry.get('transition_relation'), name, 'transition_relation').items():
        outcome = outcome_key(key, 'transition_relation')
        # A list of targets under one outcome is one choice (CNU: "must transition to one of these").
        targets = tuple(literal(term, f'transition_relation.{key}', False)
                        for item in _list(items, name, f'transition_relation.{key}')
                        for term in _terms(item, name, 'transition_relation'))
        relation[outcome] = relation.get(outcome, ()) + (targets,)
    autonomy: dict[str, int] = {}
    raw_autonomy = entry.get('autonomy') or {}
    if not isinstance(raw_autonomy, dict):
        raise CapabilityConfigError(f'{where}: autonomy must map FlexBE outcomes to levels 0..3', item=f'{name}.autonomy')
    for outcome, level in raw_autonomy.items():
        if isinstance(level, bool) or not isinstance(level, int) or not 0 <= level <= 3:
            raise CapabilityConfigError(f'{where}: autonomy of {outcome!r} must be 0..3, got {level!r}',
                                        item=f'{name}.autonomy.{outcome}')
        autonomy[_word(outcome)] = level
    return Capability(name, interface, dict(parameters), preconditions, postconditions, relation, autonomy,
                      tuple(declared))


def _list(value: object, name: str, key: str) -> list[str]:
    if value is None:
        return []
    if isinstance(value, str):
        return [value]
    if not isinstance(value, list) or not all(isinstance(v, (str, bool)) for v in value):
        raise CapabilityConfigError(f'capability {name!r}: {key} must be a list of conditions', item=f'{name}.{key}')
    return [_word(v) for v in value]


def _by_outcome(value: object, name: str, key: str) -> dict[Any, Any]:
    """A per-outcome mapping; a plain list means the completion outcome (as CNU reads it)."""
    if value is None:
        return {}
    if isinstance(value, (list, str)):
        return {COMPLETED: value}
    if not isinstance(value, dict):
        raise CapabilityConfigError(f'capability {name!r}: {key} must be a list or a mapping of outcomes to lists',
                                    item=f'{name}.{key}')
    return value


def _terms(clause: str, name: str, key: str) -> list[str]:
    terms = [term.strip() for term in str(clause).split('|')]
    if not all(terms):
        raise CapabilityConfigError(f'capability {name!r}: {key} entry {clause!r} has an empty term',
                                    item=f'{name}.{key}')
    return terms


def parse_literal(text: str, item: str, where: str, integers: Mapping[str, IntegerRange],
                  allow_choice: bool) -> Literal:
    """One condition term: ``[!]name``, ``name=value``, ``name!=value`` or (``allow_choice``) ``@name``."""
    text = str(text).strip()
    if text.startswith('@'):
        if not allow_choice or text[1:] not in integers:
            raise CapabilityConfigError(f'{where}: {text!r} must name an integer variable, in a postcondition',
                                        item=item)
        return Literal(text[1:], choose=True)
    comparison = _COMPARISON.match(text)
    if comparison:
        variable, operator, value = comparison[1], comparison[2], int(comparison[3])
        known = integers.get(variable)
        if known is None or not known.low <= value <= known.high:
            raise CapabilityConfigError(f'{where}: {text!r} compares {variable!r}, which is no integer variable '
                                        f'with that value in range', item=item)
        return Literal(variable, operator == '!=', value)
    negated = text.startswith('!')
    name = text[1:].strip() if negated else text
    if not _NAME.match(name):
        raise CapabilityConfigError(f'{where}: condition {text!r} is not [!]name, name=value or @name', item=item)
    if name in integers:
        raise CapabilityConfigError(f'{where}: {name!r} is an integer variable; compare it (name=value)', item=item)
    return Literal(name, negated)


def _check_targets(system: CapabilitySystem) -> None:
    for capability in system.capabilities.values():
        for outcome, clauses in capability.transition_relation.items():
            for clause in clauses:
                for target in clause:
                    if target.name not in system.capabilities and target.name not in system.sm_outcomes:
                        raise CapabilityConfigError(
                            f'{system.system}: capability {capability.name!r} transition_relation names '
                            f'{target.name!r}, which is neither a capability nor an SM outcome',
                            item=f'{capability.name}.transition_relation')
