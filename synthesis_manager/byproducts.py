"""The synthesizer's byproduct files and their retention policy (ROS-free).

Like the original, every synthesis leaves ``<spec_name>.structuredslugs``, ``.slugsin`` and
``.json`` in a directory. The extension is appended to the whole spec name, never put in
place of a dotted part of it, so ``collide.one`` and ``collide.two`` keep separate files; a
later synthesis with the same spec name replaces that name's files. Files are written
atomically (a reader never sees half a file, even with two goals of one name at once).

Retention: after each synthesis only the newest ``keep_last`` sets (a set = one spec name's
files) are kept, and with ``max_age`` > 0 sets older than that many seconds go too.
``keep_last=0`` keeps none: the files live in a private temporary directory (the slugs
backend still needs them on disk) that is removed when the synthesis ends.
"""

from __future__ import annotations

import contextlib
import os
import re
import tempfile
import time
from pathlib import Path

from respec.errors import CodedError

EXTENSIONS = ('structuredslugs', 'slugsin', 'json')
DEFAULT_SPEC_NAME = 'synthesized_spec'
DEFAULT_KEEP_LAST = 200
# File stems stay inside the directory: no separators, no leading dot, no "..".
SPEC_NAME = re.compile(r'^[A-Za-z0-9][A-Za-z0-9_.-]{0,99}$')
_BYPRODUCT_FILE = re.compile(r'^(?P<stem>.+)\.(?:' + '|'.join(EXTENSIONS) + r')$')


class InvalidSpecName(CodedError):
    code = 'INVALID_SPEC_NAME'


def checked_spec_name(spec_name: str) -> str:
    """``spec_name`` (or the default), refusing names that could leave the directory."""
    name = spec_name or DEFAULT_SPEC_NAME
    if not SPEC_NAME.match(name) or '..' in name:
        shown = spec_name if len(spec_name) <= 40 else spec_name[:40] + '...'
        raise InvalidSpecName(f'invalid spec_name {shown!r}: use letters, digits, "_", "-" and "." '
                              '(at most 100, no path separators or "..")', 'spec_name')
    return name


class ByproductSet:
    """The files of one synthesis: ``paths[extension]``, written atomically by :meth:`write`."""

    def __init__(self, directory: Path, spec_name: str):
        self.name = checked_spec_name(spec_name)
        self.directory = directory
        self.paths = {extension: directory / f'{self.name}.{extension}' for extension in EXTENSIONS}

    def write(self, extension: str, text: str) -> Path:
        path = self.paths[extension]
        with tempfile.NamedTemporaryFile('w', dir=self.directory, prefix=f'.{self.name}.',
                                         suffix='.part', delete=False) as part:
            part.write(text)
        os.replace(part.name, path)
        return path


class ByproductStore:
    """Where byproducts go and how long they stay (see the module docstring)."""

    def __init__(self, directory: str | Path, keep_last: int = DEFAULT_KEEP_LAST, max_age: float = 0.0):
        if keep_last < 0 or max_age < 0:
            raise ValueError('keep_last and max_age must be >= 0')
        self.directory = Path(directory)
        self.keep_last = keep_last
        self.max_age = max_age

    @contextlib.contextmanager
    def open_set(self, spec_name: str):
        """Yield the ByproductSet for a synthesis; apply the retention policy when it ends."""
        checked_spec_name(spec_name)  # a bad name fails before anything is created
        if self.keep_last == 0:
            with tempfile.TemporaryDirectory(prefix='behavior-synthesis-byproducts-') as private:
                yield ByproductSet(Path(private), spec_name)
            return
        self.directory.mkdir(parents=True, exist_ok=True)
        try:
            yield ByproductSet(self.directory, spec_name)
        finally:
            self.prune()

    def prune(self, now: float | None = None) -> list[Path]:
        """Delete the sets the policy no longer keeps; returns the deleted files."""
        newest: dict[str, float] = {}
        files: dict[str, list[Path]] = {}
        with os.scandir(self.directory) as entries:
            for entry in entries:
                match = _BYPRODUCT_FILE.match(entry.name)
                if not match or not entry.is_file(follow_symlinks=False):
                    continue
                with contextlib.suppress(FileNotFoundError):  # another node may prune too
                    mtime = entry.stat(follow_symlinks=False).st_mtime
                    stem = match['stem']
                    files.setdefault(stem, []).append(Path(entry.path))
                    newest[stem] = max(newest.get(stem, 0.0), mtime)
        by_age = sorted(newest, key=newest.get, reverse=True)
        doomed = by_age[self.keep_last:]
        if self.max_age > 0:
            cutoff = (time.time() if now is None else now) - self.max_age
            doomed += [stem for stem in by_age[:self.keep_last] if newest[stem] < cutoff]
        deleted = []
        for stem in doomed:
            for path in files[stem]:
                with contextlib.suppress(FileNotFoundError):
                    path.unlink()
                    deleted.append(path)
        return deleted
