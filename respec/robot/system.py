"""``RobotSystem``: one robot system, loaded once from its file(s), validated, immutable.

A robot system is one YAML file, ``<directory>/<name>.yaml`` (the first on the search path,
``respec.robot.files.config_search_path``), in one of two kinds:

``abstraction``   our own format (ATLAS-style): an ``abstraction:`` section with control modes,
                  actions, outcomes and sensors (``respec.robot.abstraction``), a ``flexbe:``
                  section mapping propositions to FlexBE states, and optionally ``simulation:``.
``capabilities``  a robot described by CNU's capability files, which the system file points at
                  (``respec.robot.cnu``); its FlexBE mapping comes from the capabilities and the
                  workspace's state classes.

Every stage takes a ``RobotSystem`` (or a name resolved once at the edge with
``robot_system``), so a request reads the system's files once, and the kind is decided here,
once, when the file is read.
"""

from __future__ import annotations

import contextlib
import errno
import json
import os
import threading
from collections import OrderedDict
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import Any, Callable, Mapping, Sequence, TypeVar

import yaml

from respec.robot.abstraction import RobotAbstraction, abstraction_from_document
from respec.robot.cnu import (CNU_FILE_KEYS, SYSTEM_FILE_KEYS, CapabilitySystem, is_capability_document,
                              load_capability_system)
from respec.robot.description import RobotDescription
from respec.robot.files import (ConfigDirs, ConfigFileInvalidError, SystemConfigError, SystemNotFoundError,
                                available_systems, check_system_name, config_search_path, load_config_yaml,
                                parse_config_text, read_config_file, system_file)

ABSTRACTION_KIND = 'abstraction'
Entry = TypeVar('Entry')
CAPABILITIES_KIND = 'capabilities'


@dataclass(frozen=True)
class RobotSystem:
    """A validated robot system: its name, file, kind and descriptions.

    ``capabilities`` is set for kind ``capabilities``; otherwise ``abstraction`` holds the
    validated ``abstraction:`` section (None when the file has none). ``sections`` holds the file's other top-level sections as read
    (``flexbe``, ``simulation``); the package that uses a section validates it
    (``sm_generation.config``, ``atlas_sim``).
    """

    name: str
    path: Path = field(compare=False)  # where it was read from: the same system may be read elsewhere
    abstraction: RobotAbstraction | None = None
    capabilities: CapabilitySystem | None = None
    sections: Mapping[str, object] = field(default_factory=dict, compare=False, repr=False)
    # The text of every file read, by its path relative to the system file's folder.
    files: Mapping[str, str] = field(default_factory=dict, compare=False, repr=False)

    @property
    def kind(self) -> str:
        return CAPABILITIES_KIND if self.capabilities is not None else ABSTRACTION_KIND

    @property
    def description(self) -> RobotDescription | None:
        """The robot as its format describes it (the robot interface, ``respec.robot.description``):
        the capability system, or the abstraction (None for a file without an ``abstraction:`` section)."""
        return self.capabilities if self.capabilities is not None else self.abstraction

    @property
    def config_file(self) -> str:
        """The file as users know it, e.g. 'config/atlas.yaml'."""
        return f'{self.path.parent.name}/{self.path.name}'

    def section(self, name: str) -> dict[str, Any]:
        """One top-level section of the system file; raises ConfigFileInvalidError if missing."""
        content = self.sections.get(name)
        if not isinstance(content, Mapping):
            raise ConfigFileInvalidError(f'{self.name}.yaml: missing or invalid section {name!r}', item=name)
        return dict(content)

    @property
    def default_initial_conditions(self) -> list[str]:
        """What a task on this robot starts from when it names nothing (``RobotDescription``)."""
        return self.description.default_initial_conditions if self.description is not None else []

    @property
    def reads_robot_state_by_default(self) -> bool:
        """Whether naming no initial conditions means the robot's reported state (``RobotDescription``);
        a file without a description is of our own format, whose robots report their state."""
        return self.description is None or self.description.reads_robot_state_by_default

    @property
    def orders_goals(self) -> bool:
        """Whether goals may be asked in a strict order (``RobotDescription``)."""
        return self.description is None or self.description.orders_goals

    def has_section(self, name: str) -> bool:
        return isinstance(self.sections.get(name), Mapping)

    def required_abstraction(self) -> RobotAbstraction:
        """The abstraction, for a stage that cannot work without one: raises AbstractionConfigError
        naming what is missing (a capability system, a file without an ``abstraction:`` section)."""
        return self.abstraction or abstraction_from_document(self.sections, self.name)

    def required_capabilities(self) -> CapabilitySystem:
        """The capability system, for a stage that ``for_description`` chose by it (a system of
        another kind there is a programming error, a TypeError)."""
        if self.capabilities is None:
            raise TypeError(f'{self.name} is not described by capabilities')
        return self.capabilities


def for_description(registry: Mapping[type, Entry], system: RobotSystem, missing: Entry) -> Entry:
    """A layer's entry for ``system``'s description, by its class (``respec.robot.description``);
    ``missing`` for a system file without a description (an abstraction-kind file with only a
    ``flexbe:`` section)."""
    description = system.description
    if description is None:
        return missing
    try:
        return registry[type(description)]
    except KeyError:
        raise TypeError(f'no entry for a robot described by {type(description).__name__} '
                        f'(known: {", ".join(c.__name__ for c in registry)})') from None


def robot_system_from_file(path: str | Path, name: str | None = None,
                           config_folders: Sequence[Path] | None = None) -> RobotSystem:
    """The robot system of one system file (its kind told by its content). It and the files it
    references must resolve inside one of ``config_folders`` (default: the file's own folder)."""
    path = Path(path)
    folders = tuple(config_folders or (path.parent,))
    return _robot_system(name or path.stem, path,
                         lambda relative: read_config_file(path.parent, relative, folders))


def robot_system_from_files(name: str, files: Mapping[str, str], config_file: str | None = None) -> RobotSystem:
    """A robot system rebuilt from the texts of its files (``RobotSystem.files``), e.g. as a
    suite serves them to a GUI that runs elsewhere: the same system as the one read from disk."""
    def read(relative: str) -> str:
        if relative not in files:
            raise FileNotFoundError(errno.ENOENT, os.strerror(errno.ENOENT), relative)
        return files[relative]

    return _robot_system(name, Path(config_file or f'config/{name}.yaml'), read)

# A parsed system's key: its name, its file's path and text.
_SystemKey = tuple[str, str, str]


class _ParsedSystems:
    """Robot systems already parsed, by the texts of their files (least recently used dropped).

    Every request still reads the system's files, so an edit is seen by the next request; only
    parsing and validating unchanged texts again is saved (4.6 ms for ATLAS, three times a goal:
    a quarter of a busy server's time in a 200-goal burst)."""

    KEPT = 16

    def __init__(self) -> None:
        self._systems: OrderedDict[_SystemKey, RobotSystem] = OrderedDict()
        self._lock = threading.Lock()

    def get(self, key: _SystemKey, read: Callable[[str], str]) -> RobotSystem | None:
        with self._lock:
            system = self._systems.get(key)
            if system is not None:
                self._systems.move_to_end(key)
        if system is None or not all(_reads_unchanged(read, relative, text) for relative, text in system.files.items()):
            return None
        return system

    def put(self, key: _SystemKey, system: RobotSystem) -> None:
        with self._lock:
            self._systems[key] = system
            while len(self._systems) > self.KEPT:
                self._systems.popitem(last=False)


_parsed_systems = _ParsedSystems()


def _reads_unchanged(read: Callable[[str], str], relative: str, text: str) -> bool:
    try:
        return read(relative) == text
    except (OSError, UnicodeDecodeError):
        return False  # parsed again, which names the problem


def _robot_system(name: str, path: Path, read: Callable[[str], str]) -> RobotSystem:
    files: dict[str, str] = {}

    def read_and_keep(relative: str) -> str:
        try:
            files[relative] = read(relative)
        except UnicodeDecodeError as error:  # its repr holds the whole file: never shown
            raise ConfigFileInvalidError(f'{path.parent / relative}: not UTF-8 text (byte 0x{error.object[error.start]:02x} '
                                         f'at position {error.start})', item=relative) from None
        return files[relative]

    text = read_and_keep(path.name)
    key = (name, str(path), text)
    system = _parsed_systems.get(key, read)
    if system is None:
        system = _parsed_system(name, path, text, read_and_keep, files)
        _parsed_systems.put(key, system)
    return system


def _parsed_system(name: str, path: Path, text: str, read_and_keep: Callable[[str], str],
                   files: dict[str, str]) -> RobotSystem:
    document = parse_config_text(text, path)
    if is_capability_document(document):
        capabilities = load_capability_system(document, name, read_and_keep)
        return RobotSystem(name, path, capabilities=capabilities, sections=MappingProxyType(dict(document)),
                           files=MappingProxyType(files))
    # A file without an abstraction: section may still serve generation alone (its flexbe:
    # section); compiling a task on it reports the missing section.
    abstraction = abstraction_from_document(document, name) if 'abstraction' in document else None
    return RobotSystem(name, path, abstraction=abstraction, sections=MappingProxyType(dict(document)),
                       files=MappingProxyType(files))


def robot_system(system: RobotSystem | str, config_dir: ConfigDirs = None) -> RobotSystem:
    """``system`` itself, or the system of that name: the first found in ``config_dir`` (one
    directory or several, see ``config_search_path``), ``$BEHAVIOR_SYNTHESIS_CONFIG_DIR``, ``config/``.

    The edge where a name becomes a RobotSystem: raises SystemNotFoundError for an unknown
    name and a SystemConfigError subclass (naming the entry) for an invalid file.
    """
    if isinstance(system, RobotSystem):
        return system
    check_system_name(system)   # before the search path: an invalid name is named first
    search_path = config_search_path(config_dir)
    return robot_system_from_file(system_file(system, search_path), system, search_path)


@dataclass(frozen=True)
class SystemCatalog:
    """The robot systems of a search path: their names, and each one loaded on request.

    ``config_dir`` adds directories before the shipped ``config/`` (``config_search_path``);
    ``names()`` is the union, a name in an earlier directory shadowing a later one. Loading reads
    the files afresh, so a request sees a system file as it is when it arrives.
    """

    config_dir: ConfigDirs = None

    def names(self) -> list[str]:
        return available_systems(self.config_dir)

    def load(self, name: RobotSystem | str) -> RobotSystem:
        return robot_system(name, self.config_dir)

    def files_bytes(self, name: str) -> int:
        """How many bytes of robot files loading ``name`` reads: its system file and the CNU files
        it names (sizes only; a system file over SMALL_SYSTEM_FILE_BYTES is not parsed for them),
        so that a caller can load a large robot where large work belongs. 0 when the system file
        cannot be found (loading says why)."""
        try:
            path = system_file(name, config_search_path(self.config_dir))
            size = path.stat().st_size
        except (SystemConfigError, OSError):
            return 0
        if size > SMALL_SYSTEM_FILE_BYTES:
            return size
        try:
            document = parse_config_text(path.read_text(encoding='utf-8'), path)
        except (SystemConfigError, OSError, UnicodeDecodeError):
            return size
        for key in CNU_FILE_KEYS:
            if isinstance(document.get(key), str):
                with contextlib.suppress(OSError):
                    size += (path.parent / document[key]).stat().st_size
        return size

    def fingerprint(self) -> tuple[tuple[str, int, int], ...]:
        """Every file under the catalog's directories as (path, modification time in ns, size):
        while it stays the same, so do the systems (a system reads no file outside them), and a
        caller watching for changes need not load them again (a 2 MB robot file takes seconds)."""
        files = []
        for directory in config_search_path(self.config_dir):
            for folder, subfolders, names in os.walk(directory):
                subfolders.sort()
                for name in sorted(names):
                    path = os.path.join(folder, name)
                    with contextlib.suppress(OSError):  # removed meanwhile
                        stat = os.stat(path)
                        files.append((path, stat.st_mtime_ns, stat.st_size))
        return tuple(files)


#: A system file up to this size is read to find the CNU files it names (CNU's are a few lines).
SMALL_SYSTEM_FILE_BYTES = 64 * 1024


# --- a catalog as text: how a suite serves its systems to a GUI running elsewhere ---------------

def catalog_to_json(catalog: SystemCatalog) -> str:
    """Every system of ``catalog`` as JSON (deterministic): name, config file and the text of
    each file it reads; a system that cannot be loaded is listed with its error instead."""
    from respec.vocabulary.errors import CodedError

    entries = []
    for name in catalog.names():
        try:
            system = catalog.load(name)
        except CodedError as error:
            entries.append({'name': name, 'error': {'code': error.code.name, 'message': str(error),
                                                    'item': error.item}})
            continue
        entries.append({'name': name, 'config_file': system.config_file, 'files': served_files(system)})
    return json.dumps({'systems': entries}, sort_keys=True)


# The system file's sections a suite serves; anything else in it (notes, other tools' keys) stays.
SERVED_SECTIONS = ('system', 'abstraction', 'flexbe', 'simulation', *SYSTEM_FILE_KEYS)


def served_files(system: RobotSystem) -> dict[str, str]:
    """What a client needs to rebuild ``system`` (``robot_system_from_files``), not its files: each
    file's parsed content written out again, so no comment or formatting leaves the server, and of
    the system file only the sections the suite reads (SERVED_SECTIONS)."""
    served = {}
    for relative, text in system.files.items():
        content = load_config_yaml(text, relative)
        if relative == system.path.name and isinstance(content, dict):
            content = {key: value for key, value in content.items() if key in SERVED_SECTIONS}
        served[relative] = yaml.safe_dump(content, sort_keys=False, allow_unicode=True)
    return served


@dataclass(frozen=True)
class ServedCatalog:
    """The systems a suite serves (``catalog_to_json``), with SystemCatalog's ``names``/``load``."""

    entries: Mapping[str, Mapping[str, Any]]

    @classmethod
    def from_json(cls, text: str) -> ServedCatalog:
        return cls({entry['name']: entry for entry in json.loads(text)['systems']})

    def names(self) -> list[str]:
        return sorted(self.entries)

    def load(self, name: RobotSystem | str) -> RobotSystem:
        if isinstance(name, RobotSystem):
            return name
        entry = self.entries.get(name)
        if entry is None:
            raise SystemNotFoundError(f'unknown system {name!r}: the suite serves no such system '
                                      f'(known systems: {", ".join(self.names()) or "none"})', item=str(name))
        if 'error' in entry:
            raise SystemConfigError(entry['error']['message'], item=entry['error']['item'])
        return robot_system_from_files(name, entry['files'], entry['config_file'])
