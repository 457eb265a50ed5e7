"""Locating and loading robot system configuration files.

Each robot system has one YAML file, ``<directory>/<system>.yaml``, with the sections
``abstraction`` (read by respec), ``flexbe`` (read by sm_generation) and ``simulation``
(read by atlas_sim). This module only finds and parses the file; each section is validated
by the package that owns it.

Systems are looked up along a search path, so a user's own systems add to the shipped ones
instead of replacing them: the directories given (``--config-dir``, a node's ``config_dir``;
several joined with ``os.pathsep``), then those of ``$BEHAVIOR_SYNTHESIS_CONFIG_DIR``, then the
repository's ``config/``. A name found in an earlier directory shadows the same name later.
"""

from __future__ import annotations

import argparse
import os
import re
from pathlib import Path
from typing import Sequence, Union

import yaml

from respec.errors import CodedError, ErrorCode, quoted, unbuildable_value

CONFIG_DIR_ENV = 'BEHAVIOR_SYNTHESIS_CONFIG_DIR'
#: The systems shipped with the repository; always last on the search path.
SHIPPED_CONFIG_DIR = Path(__file__).resolve().parents[2] / 'config'
#: One directory, several joined with os.pathsep (a string, as a ROS parameter holds them), or a list.
ConfigDirs = Union[str, Path, Sequence[Union[str, Path]], None]
_SYSTEM_NAME = re.compile(r'^[A-Za-z][A-Za-z0-9_]*$')
# libyaml's safe loader when PyYAML was built with it (5x faster), else the pure-Python one.
_SAFE_LOADER = getattr(yaml, 'CSafeLoader', yaml.SafeLoader)


class SystemConfigError(CodedError):
    """A system configuration problem; ``item`` names the offending system, file or key."""

    code = ErrorCode.CONFIG_FILE_INVALID


class SystemNotFoundError(SystemConfigError):
    """No configuration file exists for the requested system."""

    code = ErrorCode.UNKNOWN_SYSTEM


class ConfigFileInvalidError(SystemConfigError):
    """The configuration file exists but cannot be parsed or lacks a required section."""


class ConfigDirectoryNotFoundError(SystemConfigError):
    """A directory given for the search path does not exist (a typo would otherwise go unnoticed)."""

    code = ErrorCode.SYSTEM_CONFIG_NOT_FOUND


def config_search_path(config_dirs: ConfigDirs = None) -> tuple[Path, ...]:
    """Where systems are looked up, in order: ``config_dirs``, ``$BEHAVIOR_SYNTHESIS_CONFIG_DIR``,
    then the shipped ``config/`` (each directory once). Raises ConfigDirectoryNotFoundError for a
    given directory that does not exist."""
    given = [*_directories(config_dirs), *_directories(os.environ.get(CONFIG_DIR_ENV))]
    for directory in given:
        if not directory.is_dir():
            raise ConfigDirectoryNotFoundError(f'configuration directory {directory} does not exist',
                                               item=str(directory))
    path: dict[Path, Path] = {}
    for directory in [*given, SHIPPED_CONFIG_DIR]:
        path.setdefault(directory.resolve(), directory)
    return tuple(path.values())


def _directories(config_dirs: ConfigDirs) -> list[Path]:
    if not config_dirs:
        return []
    if isinstance(config_dirs, Path):
        return [config_dirs]
    if isinstance(config_dirs, str):
        return [Path(part) for part in config_dirs.split(os.pathsep) if part]
    return [directory for entry in config_dirs for directory in _directories(entry)]


def available_systems(config_dirs: ConfigDirs = None) -> list[str]:
    """Names of all systems on the search path (``config_search_path``), sorted."""
    return sorted({p.stem for directory in config_search_path(config_dirs) for p in directory.glob('*.yaml')
                   if _SYSTEM_NAME.match(p.stem)})


def system_config_path(system: str, config_dirs: ConfigDirs = None) -> Path:
    """The file of ``system``: the first on the search path; raises SystemNotFoundError if none has it."""
    if not isinstance(system, str) or not _SYSTEM_NAME.match(system):
        raise SystemNotFoundError(f'invalid system name {quoted(system)}', item=str(system))
    search_path = config_search_path(config_dirs)
    for directory in search_path:
        path = directory / f'{system}.yaml'
        if path.is_file():
            return path
    known = ', '.join(available_systems(config_dirs)) or 'none'
    raise SystemNotFoundError(
        f'unknown system {quoted(system)}: no {system}.yaml in {", ".join(map(str, search_path))} '
        f'(known systems: {known})', item=system)


class _AddConfigDir(argparse.Action):
    """Each ``--config-dir`` adds a directory; kept as one os.pathsep-joined string (a ROS parameter's type)."""

    def __call__(self, parser, namespace, value, option_string=None):
        setattr(namespace, self.dest, os.pathsep.join(filter(None, [getattr(namespace, self.dest, ''), value])))


def add_config_dir_argument(parser) -> None:
    """The ``--config-dir DIR`` option every command shares (repeatable; see ``config_search_path``)."""
    parser.add_argument('--config-dir', action=_AddConfigDir, default='', metavar='DIR',
                        help='a directory of robot system files (<system>.yaml), searched before the shipped '
                             'config/; repeat it, or join directories with ' + repr(os.pathsep) + ', to add several')


def parse_config_text(text: str, path: str | Path) -> dict:
    """The text of the system configuration file ``path`` as a dict (errors name the file)."""
    try:
        document = yaml.load(text, Loader=_SAFE_LOADER)
    except yaml.YAMLError as error:
        raise ConfigFileInvalidError(f'{path}: not valid YAML: {error}', item=str(path)) from error
    except ValueError as error:
        raise ConfigFileInvalidError(f'{path}: {unbuildable_value(error)}', item=str(path)) from None
    if not isinstance(document, dict):
        raise ConfigFileInvalidError(f'{path}: expected a mapping at the top level', item=str(path))
    return document
