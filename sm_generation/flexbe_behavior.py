"""A synthesized state machine as a FlexBE behavior package (ROS-free).

``behavior_package(machine, config, name)`` writes what the FlexBE editor's "Save Behavior"
writes for a behavior, and around it what colcon needs to install it (ament_python):

    <package>/package.xml                    exports <flexbe_behaviors/>
    <package>/setup.py, setup.cfg, resource/<package>
    <package>/<package>/__init__.py
    <package>/<package>/<module>_sm.py       the behavior: class <Name>SM(Behavior), create()
    <package>/manifest/<module>.xml          the manifest the behavior dashboard lists

The code follows the editor's layout, which the editor parses back when it opens the
behavior: ``# x:.. y:..`` position comments before each state and container, one
``OperatableStateMachine.add`` per state, ``ConcurrencyContainer(..., conditions=[...])``
for states that activate several things at once, the [MANUAL_*] tags. Userdata: every key
a state remaps to lives in the root machine (default ``None`` until a state writes it, e.g.
``template_id`` from the InputState into the Pickup Object behavior); containers pass their
children's keys in and out. Autonomy levels are the configured ones (``Autonomy.Off`` ..
``Autonomy.Full``). Each state class is imported from its FlexBE package: ``flexbe.packages``
of the system config names them (module = class name in snake_case, as FlexBE's own
packages do); the generator's helper states come from flexbe_states.
"""

from __future__ import annotations

import io
import re
import zipfile
from dataclasses import dataclass
from pathlib import Path
from typing import Iterable

from sm_generation.config import FlexBEConfig
from sm_generation.errors import SMGenerationError, StateConfigInvalidError
from sm_generation.instantiation import HELPER_STATE_CLASSES, StateInstantiation
from sm_generation.layout import container_outcome_positions
from sm_generation.state_machine import State, StateMachine

FLEXBE_STATES_PACKAGE = 'flexbe_states'  # where the generator's helper states come from
AUTONOMY_NAMES = {0: 'Autonomy.Off', 1: 'Autonomy.Low', 2: 'Autonomy.High', 3: 'Autonomy.Full'}
DEFAULT_PACKAGE = 'synthesized_flexbe_behaviors'
ZIP_DATE = (2020, 1, 1, 0, 0, 0)  # same machine, same archive bytes
INDENT = '    '
STATE_INDENT = INDENT * 3
ADD_CALL = 'OperatableStateMachine.add('
CORE_IMPORTS = ('Autonomy', 'Behavior', 'ConcurrencyContainer', 'Logger', 'OperatableStateMachine',
                'PriorityContainer', 'StateLogger')


@dataclass(frozen=True)
class BehaviorPackage:
    """The files of one behavior package, by path relative to the package folder."""

    package: str
    behavior_name: str
    class_name: str
    module: str
    files: dict[str, str]

    def write(self, directory: str | Path) -> Path:
        """Write the package folder into ``directory``; returns the folder."""
        folder = Path(directory) / self.package
        for relative, text in self.files.items():
            path = folder / relative
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_text(text)
        return folder

    def zip_bytes(self) -> bytes:
        """The package folder as a zip archive (entries under ``<package>/``, fixed dates)."""
        buffer = io.BytesIO()
        with zipfile.ZipFile(buffer, 'w', zipfile.ZIP_DEFLATED) as archive:
            for relative, text in sorted(self.files.items()):
                archive.writestr(zipfile.ZipInfo(f'{self.package}/{relative}', date_time=ZIP_DATE), text)
        return buffer.getvalue()


# --- names (the editor's rules) ---------------------------------------------------------------

def behavior_class_name(behavior_name: str) -> str:
    """'Pickup Object' -> 'PickupObjectSM'."""
    return re.sub(r'[^\w]', '', behavior_name) + 'SM'


def behavior_module_name(behavior_name: str) -> str:
    """'Pickup Object' -> 'pickup_object_sm' (its manifest: pickup_object.xml)."""
    return re.sub(r'[^\w]', '_', behavior_name.lower()) + '_sm'


def default_behavior_name(goals: Iterable[str]) -> str:
    """A behavior name from the goals: 'look_down', 'pickup_object' -> 'Look Down Pickup Object'."""
    return ' '.join(word.capitalize() for goal in goals for word in goal.split('_') if word) or 'Synthesized'


def state_module_name(state_class: str) -> str:
    """'ChangeControlModeActionState' -> 'change_control_mode_action_state'."""
    return re.sub(r'(?<=[a-z0-9])(?=[A-Z])|(?<=[A-Z])(?=[A-Z][a-z])', '_', state_class).lower()


def check_package_name(package: str) -> str:
    if not re.fullmatch(r'[a-z][a-z0-9_]*', package):
        raise SMGenerationError(f'invalid ROS package name {package!r} '
                                '(lower case letters, digits and underscores, starting with a letter)', package)
    return package


def check_behavior_name(name: str) -> str:
    if not re.search(r'[A-Za-z]', name) or not re.fullmatch(r'[\w ]+', name) or name[0].isdigit():
        raise SMGenerationError(f'invalid behavior name {name!r} (letters, digits, '
                                'spaces and underscores, not starting with a digit)', name)
    return name


# --- the package ---------------------------------------------------------------------------------

def behavior_package(machine: StateMachine, config: FlexBEConfig, behavior_name: str,
                     package: str = DEFAULT_PACKAGE, description: str = '', author: str = 'behavior-synthesis',
                     date: str = '') -> BehaviorPackage:
    """The behavior package for ``machine`` (a generated state machine)."""
    check_package_name(package)
    check_behavior_name(behavior_name)
    description = description or f'Synthesized for {config.system}.'
    module = behavior_module_name(behavior_name)
    class_name = behavior_class_name(behavior_name)
    code = _behavior_code(machine, config, behavior_name, class_name, description, author, date)
    files = {
        'package.xml': _package_xml(package, machine, config, description),
        'setup.py': _setup_py(package),
        'setup.cfg': f'[develop]\nscript_dir=$base/lib/{package}\n[install]\ninstall_scripts=$base/lib/{package}\n',
        f'resource/{package}': '',
        f'{package}/__init__.py': '',
        f'{package}/{module}.py': code,
        f'manifest/{module[:-len("_sm")]}.xml': _manifest(package, module, class_name, behavior_name,
                                                          machine, author, date, description),
    }
    return BehaviorPackage(package=package, behavior_name=behavior_name, class_name=class_name,
                           module=module, files=files)


# --- behavior code -------------------------------------------------------------------------------

def _state_package(state_class: str, config: FlexBEConfig, path: str) -> str:
    if state_class in HELPER_STATE_CLASSES:
        return FLEXBE_STATES_PACKAGE
    package = config.state_package(state_class)
    if not package:
        raise StateConfigInvalidError(f'no FlexBE package for state class '
                                      f'{state_class!r}: name one in flexbe.packages of config/{config.system}.yaml',
                                      path)
    return package


def _behavior_import(state: StateInstantiation, config: FlexBEConfig) -> str:
    if not config.behavior_package:
        raise StateConfigInvalidError(f'no FlexBE package for behavior '
                                      f'{state.behavior_class!r}: set flexbe.packages.behaviors of '
                                      f'config/{config.system}.yaml', state.state_path)
    return (f'from {config.behavior_package}.{behavior_module_name(state.behavior_class)} '
            f'import {behavior_class_name(state.behavior_class)}')


def _behavior_code(machine: StateMachine, config: FlexBEConfig, behavior_name: str, class_name: str,
                   description: str, author: str, date: str) -> str:
    state_classes = sorted({s.state_class for s in machine.primitives()})
    imports = sorted({f'from flexbe_core import {name}' for name in CORE_IMPORTS}
                     | {'from flexbe_core.proxy import initialize_proxies'}
                     | {f'from {_state_package(s.state_class, config, s.state_path)}.'
                        f'{state_module_name(s.state_class)} import {s.state_class}' for s in machine.primitives()}
                     | {_behavior_import(s, config) for s in machine.behaviors()})
    described = '\n'.join(f'{INDENT}{line}'.rstrip() for line in description.splitlines())
    lines = [
        '#!/usr/bin/env python', '# -*- coding: utf-8 -*-', '',
        '# Generated by behavior-synthesis (behavior-synthesis export-behavior).', '',
        '###########################################################',
        '#               WARNING: Generated code!                  #',
        '#              **************************                 #',
        '# Manual changes may get lost if file is generated again. #',
        '# Only code inside the [MANUAL] tags will be kept.        #',
        '###########################################################', '',
        '"""', f'Define {behavior_name}.', '', description, '', f'Created on {date}', f'@author: {author}', '"""',
        '', '', *imports, '',
        '# Additional imports can be added inside the following tags', '# [MANUAL_IMPORT]', '',
        '# [/MANUAL_IMPORT]', '', '',
        f'class {class_name}(Behavior):', f'{INDENT}"""', f'{INDENT}Define {behavior_name}.', '', described,
        f'{INDENT}"""', '',
        f'{INDENT}def __init__(self, node):', f'{INDENT * 2}super().__init__()',
        f"{INDENT * 2}self.name = '{behavior_name}'", '',
        f'{INDENT * 2}# parameters of this behavior', '',
        f'{INDENT * 2}# initialize ROS node information',
        f'{INDENT * 2}ConcurrencyContainer.initialize_ros(node)', f'{INDENT * 2}Logger.initialize(node)',
        f'{INDENT * 2}StateLogger.initialize_ros(node)', f'{INDENT * 2}OperatableStateMachine.initialize_ros(node)',
        f'{INDENT * 2}PriorityContainer.initialize_ros(node)', f'{INDENT * 2}initialize_proxies(node)',
        *(f'{INDENT * 2}{name}.initialize_ros(node)' for name in state_classes), '',
        f'{INDENT * 2}# references to used behaviors',
        *(f"{INDENT * 2}self.add_behavior({behavior_class_name(s.behavior_class)}, '{s.state_path[1:]}', node)"
          for s in sorted(machine.behaviors(), key=lambda s: s.state_path)), '',
        f'{INDENT * 2}# Additional initialization code can be added inside the following tags',
        f'{INDENT * 2}# [MANUAL_INIT]', '', f'{INDENT * 2}# [/MANUAL_INIT]', '',
        f'{INDENT * 2}# Behavior comments:', '',
        *_create_method(machine, config.userdata),
        f'{INDENT}# Private functions can be added inside the following tags', f'{INDENT}# [MANUAL_FUNC]', '',
        f'{INDENT}# [/MANUAL_FUNC]',
    ]
    return '\n'.join(lines) + '\n'


def _positions(entries: Iterable[StateInstantiation]) -> str:
    return ', '.join(f'x:{round(e.position[0])} y:{round(e.position[1])}' for e in entries)


def _container_variables(machine: StateMachine) -> dict[str, str]:
    return {c.state_path: f'_sm_{c.name.lower()}_{index}' for index, c in enumerate(machine.containers())}


def _create_method(machine: StateMachine, defaults: dict[str, str]) -> list[str]:
    body = INDENT * 2
    outcome_entries = {e.name: e for e in machine.outcome_entries}
    placed = [outcome_entries[o] for o in machine.outcomes if o in outcome_entries]
    lines = [f'{INDENT}def create(self):', f'{body}"""Create state machine."""', f'{body}# Root state machine']
    if placed:
        lines.append(f'{body}# {_positions(placed)}')
    # The root's input keys come from outside (the behavior's userdata, with the configured
    # defaults); the other keys are written by states before they are read.
    keys = f', input_keys={_list(machine.input_keys)}' if machine.input_keys else ''
    lines.append(f'{body}_state_machine = OperatableStateMachine(outcomes={_list(machine.outcomes)}{keys})')
    lines += [f'{body}_state_machine.userdata.{key} = {defaults.get(key, "None")}' for key in machine.remapped_keys()]
    lines += ['', f'{body}# Additional creation code can be added inside the following tags',
              f'{body}# [MANUAL_CREATE]', '', f'{body}# [/MANUAL_CREATE]', '']
    variables = _container_variables(machine)
    for container in machine.containers():
        lines += _container_definition(container, variables[container.state_path], variables)
    lines.append(f'{body}with _state_machine:')
    for state in machine.ordered_states():
        lines += _add_state(state, variables)
    lines += [f'{body}return _state_machine', '']
    return lines


def _container_definition(container: StateMachine, variable: str, variables: dict[str, str]) -> list[str]:
    body = INDENT * 2
    head = f'{body}{variable} = ConcurrencyContainer('
    pad = ' ' * len(head)
    conditions = [f"('{outcome}', [" + ', '.join(f"('{name}', '{result}')" for name, result in
                                                  zip(condition.state_name, condition.state_outcome)) + '])'
                  for outcome, condition in zip(container.cond_outcome, container.cond_transition)]
    if not conditions:
        raise SMGenerationError('a concurrency container needs outcome conditions',
                                container.state_path)
    outcome_positions = container_outcome_positions(len(container.outcomes))
    lines = [f'{body}# ' + ', '.join(f'x:{round(x)} y:{round(y)}' for x, y in outcome_positions),
             f'{head}outcomes={_list(container.outcomes)},']
    if container.input_keys:
        lines.append(f'{pad}input_keys={_list(container.input_keys)},')
    if container.output_keys:
        lines.append(f'{pad}output_keys={_list(container.output_keys)},')
    condition_pad = pad + ' ' * len('conditions=[')
    lines.append(f'{pad}conditions=[')
    lines += [f'{condition_pad}{condition},' for condition in conditions[:-1]]
    lines += [f'{condition_pad}{conditions[-1]}', f'{condition_pad}])', '']
    lines.append(f'{body}with {variable}:')
    for child in container.ordered_states():
        lines += _add_state(child, variables)
    return lines


def _add_state(state: State, variables: dict[str, str]) -> list[str]:
    pad = STATE_INDENT + ' ' * len(ADD_CALL)
    if state.state_class == StateInstantiation.CLASS_CONCURRENCY:
        implementation = variables[state.state_path]
        remapping = {key: key for key in state.input_keys + [k for k in state.output_keys
                                                              if k not in state.input_keys]}
    elif state.state_class == StateInstantiation.CLASS_BEHAVIOR:
        implementation = (f"self.use_behavior({behavior_class_name(state.behavior_class)}, "
                          f"'{state.state_path[1:]}')")
        remapping = dict(zip(state.userdata_keys, state.userdata_remapping))
    else:
        arguments = ', '.join(f'{name}={value}' for name, value in
                              zip(state.parameter_names, state.parameter_values))
        implementation = f'{state.state_class}({arguments})'
        remapping = dict(zip(state.userdata_keys, state.userdata_remapping))
    transitions = ', '.join(f"'{o}': '{t}'" for o, t in zip(state.outcomes, state.transitions))
    autonomy = ', '.join(f"'{o}': {AUTONOMY_NAMES.get(a, 'Autonomy.Inherit')}"
                         for o, a in zip(state.outcomes, state.autonomy))
    lines = [f'{STATE_INDENT}# x:{round(state.position[0])} y:{round(state.position[1])}',
             f"{STATE_INDENT}{ADD_CALL}'{state.name}',", f'{pad}{implementation},',
             f'{pad}transitions={{{transitions}}},']
    if remapping:
        lines.append(f'{pad}autonomy={{{autonomy}}},')
        lines.append(f'{pad}remapping={{' + ', '.join(f"'{k}': '{v}'" for k, v in remapping.items()) + '})')
    else:
        lines.append(f'{pad}autonomy={{{autonomy}}})')
    return lines + ['']


def _list(names: Iterable[str]) -> str:
    return '[' + ', '.join(f"'{name}'" for name in names) + ']'


# --- package files -------------------------------------------------------------------------------

def _package_xml(package: str, machine: StateMachine, config: FlexBEConfig, description: str) -> str:
    depends = sorted({'flexbe_core', FLEXBE_STATES_PACKAGE}
                     | {config.state_package(s.state_class) or FLEXBE_STATES_PACKAGE for s in machine.primitives()
                        if s.state_class not in HELPER_STATE_CLASSES}
                     | ({config.behavior_package} if machine.behaviors() else set()))
    return '\n'.join([
        '<?xml version="1.0"?>',
        '<?xml-model href="http://download.ros.org/schema/package_format3.xsd" '
        'schematypens="http://www.w3.org/2001/XMLSchema"?>',
        '<package format="3">', f'  <name>{package}</name>', '  <version>0.0.0</version>',
        f'  <description>{_xml_text(description)}</description>',
        '  <maintainer email="user@example.org">user</maintainer>', '  <license>BSD-3-Clause</license>', '',
        *(f'  <exec_depend>{name}</exec_depend>' for name in depends), '',
        '  <export>', '    <build_type>ament_python</build_type>', '    <flexbe_behaviors />', '  </export>',
        '</package>', ''])


def _setup_py(package: str) -> str:
    return '\n'.join([
        '"""colcon (ament_python) build of a FlexBE behavior package; manifests go to lib/<package>/manifest."""',
        '', 'from glob import glob', '', 'from setuptools import setup', '',
        f"PACKAGE_NAME = '{package}'", '',
        'setup(', '    name=PACKAGE_NAME,', "    version='0.0.0',", '    packages=[PACKAGE_NAME],',
        '    data_files=[',
        "        ('share/ament_index/resource_index/packages', ['resource/' + PACKAGE_NAME]),",
        "        ('share/' + PACKAGE_NAME, ['package.xml']),",
        "        ('lib/' + PACKAGE_NAME + '/manifest', glob('manifest/*.xml')),",
        '    ],', "    install_requires=['setuptools'],", '    zip_safe=True,', ')', ''])


def _manifest(package: str, module: str, class_name: str, behavior_name: str, machine: StateMachine,
              author: str, date: str, description: str) -> str:
    contained = sorted({s.behavior_class for s in machine.behaviors()})
    return '\n'.join([
        '<?xml version="1.0" encoding="UTF-8"?>', '', f'<behavior name="{_xml_text(behavior_name)}">', '',
        f'    <executable package_path="{package}.{module}" class="{class_name}" />',
        '    <tagstring>synthesized</tagstring>', f'    <author>{_xml_text(author)}</author>',
        f'    <date>{_xml_text(date)}</date>', '    <description>',
        *(f'        {_xml_text(line)}' for line in description.splitlines()), '    </description>', '',
        '    <!-- Contained Behaviors -->', *(f'    <contains name="{_xml_text(name)}" />' for name in contained), '',
        '    <!-- Available Parameters -->', '', '</behavior>', ''])


def _xml_text(text: str) -> str:
    return text.replace('&', '&amp;').replace('<', '&lt;').replace('>', '&gt;').replace('"', '&quot;')
