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

import os
import re
from pathlib import Path
from typing import TYPE_CHECKING, Any, Sequence, Union

from respec.untrusted import BoundedFileError, BoundedYamlError, load_bounded_yaml, read_bounded_file
from respec.vocabulary.errors import CodedError, ErrorCode, quoted

if TYPE_CHECKING:  # only the commands parse arguments (a robot file's reader needs no argparse)
    import argparse

CONFIG_DIR_ENV = 'BEHAVIOR_SYNTHESIS_CONFIG_DIR'
#: The systems shipped with the repository; always last on the search path.
SHIPPED_CONFIG_DIR = Path(__file__).resolve().parents[2] / 'config'
#: One directory, several joined with os.pathsep (a string, as a ROS parameter holds them), or a list.
ConfigDirs = Union[str, Path, Sequence[Union[str, Path]], None]
_SYSTEM_NAME = re.compile(r'^[A-Za-z][A-Za-z0-9_]*$')
#: The largest robot file read (a system file, a file it references): ATLAS's is 11 KB, a
#: 160-capability robot's capabilities about 100 KB.
MAX_CONFIG_FILE_BYTES = 4 * 2**20
#: Deepest nesting of mappings and lists in a robot file.
MAX_CONFIG_DEPTH = 32


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
    return _systems_on(config_search_path(config_dirs))


def _systems_on(search_path: Sequence[Path]) -> list[str]:
    return sorted({p.stem for directory in search_path for p in directory.glob('*.yaml') if _SYSTEM_NAME.match(p.stem)})


def check_system_name(system: object) -> None:
    """Raises SystemNotFoundError unless ``system`` can name a system file."""
    if not isinstance(system, str) or not _SYSTEM_NAME.match(system):
        raise SystemNotFoundError(f'invalid system name {quoted(system)}', item=str(system))


def system_file(system: str, search_path: Sequence[Path]) -> Path:
    """The file of ``system``: the first on ``search_path`` (``config_search_path``); raises
    SystemNotFoundError if none has it."""
    check_system_name(system)
    for directory in search_path:
        path = directory / f'{system}.yaml'
        if path.is_file():
            return path
    known = ', '.join(_systems_on(search_path)) or 'none'
    raise SystemNotFoundError(
        f'unknown system {quoted(system)}: no {system}.yaml in {", ".join(map(str, search_path))} '
        f'(known systems: {known})', item=system)


def add_config_dir_argument(parser: argparse.ArgumentParser) -> None:
    """The ``--config-dir DIR`` option every command shares (repeatable; see ``config_search_path``)."""
    import argparse

    class AddConfigDir(argparse.Action):
        """Each ``--config-dir`` adds a directory; kept as one os.pathsep-joined string (a ROS parameter's type)."""

        def __call__(self, parser: argparse.ArgumentParser, namespace: argparse.Namespace,
                     value: str | Sequence[Any] | None, option_string: str | None = None) -> None:
            assert isinstance(value, str)  # one DIR per option (no nargs)
            setattr(namespace, self.dest, os.pathsep.join(filter(None, [getattr(namespace, self.dest, ''), value])))

    parser.add_argument('--config-dir', action=AddConfigDir, default='', metavar='DIR',
                        help='a directory of robot system files (<system>.yaml), searched before the shipped '
                             'config/; repeat it, or join directories with ' + repr(os.pathsep) + ', to add several')


def parse_config_text(text: str, path: str | Path) -> dict[str, Any]:
    """The text of the system configuration file ``path`` as a dict (errors name the file, the
    line and the column, and refuse aliases and nesting deeper than MAX_CONFIG_DEPTH)."""
    document = load_config_yaml(text, path)
    if not isinstance(document, dict):
        raise ConfigFileInvalidError(f'{path}: expected a mapping at the top level', item=str(path))
    return document


def load_config_yaml(text: str, path: str | Path) -> object:
    """The value of a robot file's YAML text, within the bounds (``respec.untrusted``);
    ConfigFileInvalidError naming the file, the line and the column."""
    try:
        return load_bounded_yaml(text, MAX_CONFIG_DEPTH)
    except BoundedYamlError as error:
        raise ConfigFileInvalidError(f'{path}: {error}', item=str(path)) from None


def read_config_file(folder: Path, relative: str, config_folders: Sequence[Path] = ()) -> str:
    """The text of the robot file ``relative`` (to the system file's ``folder``, or absolute),
    which must resolve inside ``folder`` or one of ``config_folders`` (the search path): a
    ``..`` or a symbolic link out of them, or an absolute path elsewhere, is refused without
    reading the target, as are anything but a regular file (opened without blocking: a FIFO is
    never waited on) and files over MAX_CONFIG_FILE_BYTES. OSError with the reason otherwise."""
    if not isinstance(relative, str) or not relative:
        raise ConfigFileInvalidError(f'{quoted(relative)} must name a file', item=str(relative))
    resolved = Path(os.path.realpath(folder / relative))
    roots = [Path(os.path.realpath(root)) for root in (folder, *config_folders)]
    if not any(resolved == root or root in resolved.parents for root in roots):
        raise ConfigFileInvalidError(
            f'{quoted(relative)} resolves outside the config folders ({", ".join(map(str, dict.fromkeys(roots)))}); '
            'robot files must stay inside them: keep the file beside the system file, or add the folder '
            'holding it with --config-dir', item=str(relative))
    try:
        return read_bounded_file(resolved, MAX_CONFIG_FILE_BYTES)
    except BoundedFileError as error:
        raise ConfigFileInvalidError(f'{folder / relative}: {error.problem}', item=str(relative)) from None
