"""Input from outside the suite (robot files, request fields, the files a command is given),
read within bounds.

Files: :func:`read_bounded_file` opens without blocking (a FIFO is never waited on), reads only
regular files, and at most a given size.

YAML: a few hundred bytes of nested aliases (``*name``) expand to gigabytes, and deep nesting
exhausts the stack, long before any validation can look at the value. So the text's events are
checked first (libyaml's parser when PyYAML has it): no alias, at most ``max_depth`` levels of
mappings and sequences; only then is the value built. Errors carry the line and column, never
the text around them (a file's lines are not ours to repeat).
"""

from __future__ import annotations

import os
import stat
from pathlib import Path
from typing import Protocol

import yaml

from respec.vocabulary.errors import quoted, unbuildable_value

# libyaml's parser and safe loader when PyYAML was built with it (5x faster), else pure Python.
_SAFE_LOADER = getattr(yaml, 'CSafeLoader', yaml.SafeLoader)
_OPENING = (yaml.MappingStartEvent, yaml.SequenceStartEvent)
_CLOSING = (yaml.MappingEndEvent, yaml.SequenceEndEvent)


def utf8_length(text: str) -> int:
    """Bytes of ``text`` in UTF-8 (a lone surrogate, which a message may carry, counts as its 3 bytes)."""
    return len(text.encode('utf-8', errors='surrogatepass'))


class BoundedYamlError(ValueError):
    """Text that is not YAML within the bounds; ``problem`` says what, ``line``/``column``
    (1-based, or None) where."""

    def __init__(self, problem: str, line: int | None = None, column: int | None = None):
        self.problem, self.line, self.column = problem, line, column
        super().__init__(problem + self.where)

    @property
    def where(self) -> str:
        return f' (line {self.line}, column {self.column})' if self.line is not None else ''


def load_bounded_yaml(text: str, max_depth: int) -> object:
    """The value of the YAML ``text``; BoundedYamlError when it is not valid YAML, uses an
    alias or nests deeper than ``max_depth`` mappings and sequences."""
    try:
        _check_events(text, max_depth)
        return yaml.load(text, Loader=_SAFE_LOADER)
    except yaml.YAMLError as error:
        mark = getattr(error, 'problem_mark', None)
        problem = getattr(error, 'problem', None) or 'malformed'
        if 'nesting depth' in problem:  # libyaml's own bound (1000 levels), met while it looks ahead
            raise _located(f'YAML nested deeper than {max_depth} levels', mark) from None
        raise _located(f'not valid YAML: {quoted(problem, 80)}', mark) from None
    except BoundedYamlError:
        raise
    except (ValueError, OverflowError) as error:  # e.g. a timestamp or number no value can hold
        raise BoundedYamlError(unbuildable_value(error)) from None


def _check_events(text: str, max_depth: int) -> None:
    depth = 0
    for event in yaml.parse(text, Loader=_SAFE_LOADER):
        if isinstance(event, yaml.AliasEvent):
            raise _located('YAML aliases (*name) are not accepted', event.start_mark)
        if isinstance(event, _OPENING):
            depth += 1
            if depth > max_depth:
                raise _located(f'YAML nested deeper than {max_depth} levels', event.start_mark)
        elif isinstance(event, _CLOSING):
            depth -= 1


class _Mark(Protocol):
    """Where PyYAML met a problem (its pure-Python and libyaml marks both have these)."""

    line: int
    column: int


def _located(problem: str, mark: _Mark | None) -> BoundedYamlError:
    if mark is None:
        return BoundedYamlError(problem)
    return BoundedYamlError(problem, mark.line + 1, mark.column + 1)


class BoundedFileError(OSError):
    """A file that is not read: ``problem`` says why (not a regular file, larger than the bound)."""

    def __init__(self, path: str | Path, problem: str):
        self.path, self.problem = str(path), problem
        super().__init__(f'{path}: {problem}')


def read_bounded_file(path: str | Path, max_bytes: int) -> str:
    """The UTF-8 text of the regular file ``path`` of at most ``max_bytes`` bytes. Opened
    without blocking and checked before reading: BoundedFileError for a FIFO, a device, a
    directory or a larger file; OSError when it cannot be opened; UnicodeDecodeError for
    bytes that are not UTF-8 (its text is the caller's to keep out of messages)."""
    descriptor = os.open(path, os.O_RDONLY | os.O_NONBLOCK)
    with os.fdopen(descriptor, 'rb') as file:
        if not stat.S_ISREG(os.fstat(file.fileno()).st_mode):
            raise BoundedFileError(path, 'not a regular file')
        data = file.read(max_bytes + 1)
    if len(data) > max_bytes:
        raise BoundedFileError(path, f'larger than {_size(max_bytes)}, the most accepted here')
    return data.decode()


def _size(count: int) -> str:
    return f'{count // 2**20} MiB' if count % 2**20 == 0 else f'{count} bytes'
