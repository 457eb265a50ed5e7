"""Locating and loading robot system configuration files.

Each robot system has one YAML file, ``<config_dir>/<system>.yaml``, with the sections
``abstraction`` (read by respec), ``flexbe`` (read by sm_generation) and ``simulation``
(read by atlas_sim). This module only finds and parses the file; each section is validated
by the package that owns it.
"""

from __future__ import annotations

import os
import re
from pathlib import Path

import yaml

from respec.errors import CodedError, ErrorCode, quoted

CONFIG_DIR_ENV = 'BEHAVIOR_SYNTHESIS_CONFIG_DIR'
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


def default_config_dir() -> Path:
    """The config directory: ``$BEHAVIOR_SYNTHESIS_CONFIG_DIR`` or the repository's ``config/``."""
    override = os.environ.get(CONFIG_DIR_ENV)
    if override:
        return Path(override)
    return Path(__file__).resolve().parents[2] / 'config'


def available_systems(config_dir: str | Path | None = None) -> list[str]:
    """Names of all systems that have a configuration file, sorted."""
    directory = Path(config_dir) if config_dir else default_config_dir()
    return sorted(p.stem for p in directory.glob('*.yaml') if _SYSTEM_NAME.match(p.stem))


def system_config_path(system: str, config_dir: str | Path | None = None) -> Path:
    """Path of the configuration file of ``system``; raises SystemNotFoundError if absent."""
    directory = Path(config_dir) if config_dir else default_config_dir()
    if not isinstance(system, str) or not _SYSTEM_NAME.match(system):
        raise SystemNotFoundError(f'invalid system name {quoted(system)}', item=str(system))
    path = directory / f'{system}.yaml'
    if not path.is_file():
        known = ', '.join(available_systems(directory)) or 'none'
        raise SystemNotFoundError(
            f'unknown system {quoted(system)}: no {path.name} in {directory} (known systems: {known})',
            item=system)
    return path


def parse_config_text(text: str, path: str | Path) -> dict:
    """The text of the system configuration file ``path`` as a dict (errors name the file)."""
    try:
        document = yaml.load(text, Loader=_SAFE_LOADER)
    except yaml.YAMLError as error:
        raise ConfigFileInvalidError(f'{path}: not valid YAML: {error}', item=str(path)) from error
    if not isinstance(document, dict):
        raise ConfigFileInvalidError(f'{path}: expected a mapping at the top level', item=str(path))
    return document
