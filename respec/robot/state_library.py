"""The FlexBE state classes a workspace defines, found as FlexBE's own tools find them (ROS-free).

The WebUI and flexbe_core's BehaviorLibrary list the packages of the ament index
(``<prefix>/share/ament_index/resource_index/packages`` for every ``AMENT_PREFIX_PATH``
entry) whose ``package.xml`` exports ``<flexbe_states/>``, and read the state classes in
their Python modules. We read those modules with ``ast`` (nothing is imported, so neither
ROS nor FlexBE has to be importable): each class's constructor parameters and, where they
are literal, the outcomes it passes to ``super().__init__(outcomes=[...])``.

Callers take the library as a plain mapping ``class name -> StateClass``, so tests and
other front ends can supply their own.
"""

from __future__ import annotations

import ast
import importlib.util
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Mapping

from respec.robot.cnu import CapabilityConfigError, CapabilitySystem
from respec.vocabulary.errors import ErrorCode

FLEXBE_STATES_EXPORT = '<flexbe_states'
#: What to do when a capability's state class is not found: where the classes are looked for.
WORKSPACE_HINT = ('AMENT_PREFIX_PATH must hold the FlexBE workspace that defines it: source that workspace '
                  '(source <workspace>/install/setup.bash), or in this repository run `make flexbe` and add '
                  '.venv/flexbe to AMENT_PREFIX_PATH')


@dataclass(frozen=True)
class StateClass:
    """A FlexBE state class: where it lives, what its constructor takes, what it returns."""

    name: str
    package: str
    parameters: tuple[str, ...]          # constructor parameters, in order (without self)
    required: tuple[str, ...]            # those without a default
    accepts_any: bool = False            # the constructor has **kwargs
    outcomes: tuple[str, ...] | None = None  # None: given at construction (e.g. OperatorDecisionState)


def workspace_state_library(prefixes: str | None = None) -> dict[str, StateClass]:
    """State classes of every FlexBE state package in the ament index (``AMENT_PREFIX_PATH``).

    A class name defined by several packages is taken from the first prefix that has it,
    as ament overlays do.
    """
    library: dict[str, StateClass] = {}
    text = os.environ.get('AMENT_PREFIX_PATH', '') if prefixes is None else prefixes
    for prefix in (Path(p) for p in text.split(os.pathsep) if p):
        index = prefix / 'share' / 'ament_index' / 'resource_index' / 'packages'
        if not index.is_dir():
            continue
        for marker in sorted(index.iterdir()):
            package = marker.name
            manifest = prefix / 'share' / package / 'package.xml'
            try:
                if FLEXBE_STATES_EXPORT not in manifest.read_text():
                    continue
            except OSError:
                continue
            for state in package_state_classes(package, _package_directory(package, prefix)):
                library.setdefault(state.name, state)
    return library


def _package_directory(package: str, prefix: Path) -> Path | None:
    for site in sorted(prefix.glob('lib/python*/site-packages')):
        if (site / package / '__init__.py').is_file():
            return site / package
    try:
        spec = importlib.util.find_spec(package)  # a top-level package: found, not imported
    except (ImportError, ValueError):
        return None
    locations = list(spec.submodule_search_locations or []) if spec else []
    return Path(locations[0]) if locations else None


def package_state_classes(package: str, directory: Path | None) -> list[StateClass]:
    """The state classes defined in the Python files of ``directory`` (sorted by file name)."""
    if directory is None or not directory.is_dir():
        return []
    found = []
    for path in sorted(directory.glob('*.py')):
        try:
            tree = ast.parse(path.read_text(), filename=str(path))
        except (OSError, SyntaxError, ValueError):
            continue
        for node in tree.body:
            if isinstance(node, ast.ClassDef) and _is_state_class(node):
                found.append(_state_class(node, package))
    return found


def _is_state_class(node: ast.ClassDef) -> bool:
    bases = {base.id if isinstance(base, ast.Name) else getattr(base, 'attr', '') for base in node.bases}
    return any(name.endswith('State') for name in bases)


def _state_class(node: ast.ClassDef, package: str) -> StateClass:
    init = next((item for item in node.body if isinstance(item, ast.FunctionDef) and item.name == '__init__'), None)
    if init is None:
        return StateClass(node.name, package, (), (), accepts_any=True)
    positional = [a.arg for a in init.args.posonlyargs + init.args.args][1:]  # without self
    with_default = len(init.args.defaults)
    required = positional[:len(positional) - with_default] if with_default else positional
    keyword_only = [a.arg for a in init.args.kwonlyargs]
    required += [a for a, default in zip(keyword_only, init.args.kw_defaults) if default is None]
    return StateClass(node.name, package, tuple(positional + keyword_only), tuple(required),
                      accepts_any=init.args.kwarg is not None, outcomes=_literal_outcomes(init))


def _literal_outcomes(init: ast.FunctionDef) -> tuple[str, ...] | None:
    for call in ast.walk(init):
        if not (isinstance(call, ast.Call) and isinstance(call.func, ast.Attribute) and call.func.attr == '__init__'):
            continue
        for keyword in call.keywords:
            if keyword.arg == 'outcomes':
                try:
                    value = ast.literal_eval(keyword.value)
                except ValueError:
                    return None
                if isinstance(value, (list, tuple)) and all(isinstance(v, str) for v in value):
                    return tuple(value)
                return None
    return None


class StateClassError(CapabilityConfigError):
    """A capability names a state class the workspace lacks, or a parameter the class does not take."""

    code = ErrorCode.CONFIG_VARIABLE_CONFIG_INVALID


def capability_outcomes(system: CapabilitySystem, library: Mapping[str, StateClass]) -> dict[str, tuple[str, ...]]:
    """Check every capability's class and parameters against ``library``; its FlexBE outcomes.

    Outcomes are the class's literal ones; for a class that takes them at construction
    (OperatorDecisionState) they are the capability's ``outcomes`` parameter, or its own
    ``outcomes:`` list. Raises StateClassError naming the capability and the class or parameter.
    """
    result = {}
    for name, capability in system.capabilities.items():
        state = library.get(capability.interface)
        if state is None:
            found = (f'known: {", ".join(sorted(library))}' if library
                     else 'no FlexBE state package is on AMENT_PREFIX_PATH at all')
            raise StateClassError(f'{system.system}: capability {name!r} uses state class {capability.interface!r}, '
                                  f'which no FlexBE state package in the workspace defines ({found}); '
                                  f'{WORKSPACE_HINT}', item=f'{name}.interface')
        for parameter in capability.parameters:
            if parameter not in state.parameters and not state.accepts_any:
                raise StateClassError(f'{system.system}: capability {name!r}: {capability.interface} '
                                      f'({state.package}) takes no parameter {parameter!r} '
                                      f'(it takes: {", ".join(state.parameters) or "none"})',
                                      item=f'{name}.parameters.{parameter}')
        missing = [p for p in state.required if p not in capability.parameters]
        if missing:
            raise StateClassError(f'{system.system}: capability {name!r}: {capability.interface} needs parameter '
                                  f'{missing[0]!r}', item=f'{name}.parameters.{missing[0]}')
        outcomes = state.outcomes
        if outcomes is None:
            given = capability.parameters.get('outcomes', list(capability.declared_outcomes))
            if not isinstance(given, list) or not given or not all(isinstance(o, str) for o in given):
                raise StateClassError(f'{system.system}: capability {name!r}: {capability.interface} takes its '
                                      'outcomes at construction; give them as the outcomes parameter',
                                      item=f'{name}.parameters.outcomes')
            outcomes = tuple(given)
        for outcome in outcomes:
            system.transition_outcome(name, outcome)  # every outcome must mean something
        for outcome in capability.autonomy:
            if outcome not in outcomes:
                raise StateClassError(f'{system.system}: capability {name!r}: autonomy names {outcome!r}, which is '
                                      f'not an outcome of {capability.interface} ({", ".join(outcomes)})',
                                      item=f'{name}.autonomy.{outcome}')
        result[name] = tuple(outcomes)
    return result
