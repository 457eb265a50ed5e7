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

Retention only ever deletes what the suite wrote: each set has a marker ``.<spec_name>.byproducts``
(written before its files), and only the three files of a marked set (and the marker) are
deleted. A user's ``precious.json`` in the same directory is never touched, even when the
directory is shared with other programs.
"""

from __future__ import annotations

import contextlib
import errno
import os
import re
import tempfile
import time
from pathlib import Path

from respec.vocabulary.errors import CodedError, ErrorCode, quoted
from respec.vocabulary.private_files import private_directory_problem

EXTENSIONS = ('structuredslugs', 'slugsin', 'json')
DEFAULT_SPEC_NAME = 'synthesized_spec'
DEFAULT_KEEP_LAST = 200
# File stems stay inside the directory: no separators, no leading dot, no "..".
SPEC_NAME = re.compile(r'^[A-Za-z0-9][A-Za-z0-9_.-]{0,99}$')
_MARKER_SUFFIX = '.byproducts'
_MARKER_SIGNATURE = 'behavior synthesis byproducts; retention may delete: '
_MARKER_FILE = re.compile(r'^\.(?P<stem>.+)' + re.escape(_MARKER_SUFFIX) + '$')
# What a write cut short leaves: a ByproductSet.write's temporary file (``.<stem>.<random>.part``).
_PART_FILE = re.compile(r'^\.(?P<stem>.+)\.[A-Za-z0-9_]+\.part$')
#: Leftovers younger than this may be another synthesis's writing now: left alone.
LEFTOVER_AGE = 60.0


class InvalidSpecNameError(CodedError):
    code = ErrorCode.INVALID_SPEC_NAME


class ByproductsDirectoryError(CodedError):
    """The byproducts cannot be written safely or at all: an unsafe directory, a symbolic link
    where a byproduct goes, a full or read-only disk. Nothing was written outside the directory."""

    code = ErrorCode.SYNTHESIS_FAILED


def default_directory() -> Path:
    """Where byproducts go unless configured: private to the user (see the module docstring)."""
    return Path(tempfile.gettempdir()) / 'behavior_synthesis_byproducts'


def private_directory(directory: Path) -> Path:
    """``directory``, created 0700 if missing; refused unless it is a real directory of this
    user that no one else can write to (respec.vocabulary.private_files)."""
    try:
        problem = private_directory_problem(directory)
    except OSError as error:
        raise unwritable(directory, error) from None
    if problem is None:
        return directory
    raise ByproductsDirectoryError(f'refusing the byproducts directory {quoted(str(directory))}: it {problem}; '
                                   'remove it or set byproducts_dir', 'byproducts_dir')


def unwritable(path: Path, error: OSError) -> ByproductsDirectoryError:
    """The coded error for a byproduct that cannot be written (disk full, read-only, ...)."""
    reason = errno.errorcode.get(error.errno, 'error') if error.errno is not None else 'error'
    return ByproductsDirectoryError(f'cannot write {quoted(path.name)} in the byproducts directory: '
                                    f'{error.strerror or error} ({reason})', 'byproducts_dir')


def is_spec_name(name: str) -> bool:
    return bool(SPEC_NAME.match(name)) and '..' not in name


def checked_spec_name(spec_name: str) -> str:
    """``spec_name`` (or the default), refusing names that could leave the directory."""
    name = spec_name or DEFAULT_SPEC_NAME
    if not is_spec_name(name):
        raise InvalidSpecNameError(f'invalid spec_name {quoted(spec_name)}: use letters, digits, "_", "-" and "." '
                              '(at most 100, no path separators or "..")', 'spec_name')
    return name


class ByproductSet:
    """The files of one synthesis: ``paths[extension]``, written atomically by :meth:`write`."""

    def __init__(self, directory: Path, spec_name: str):
        self.name = checked_spec_name(spec_name)
        self.directory = directory
        self.paths = {extension: directory / f'{self.name}.{extension}' for extension in EXTENSIONS}
        self.marker = directory / f'.{self.name}{_MARKER_SUFFIX}'

    def mark(self):
        """Record that this set's files are ours (retention deletes nothing else).

        Refused when the marker or a file name is a symbolic link (an external synthesizer
        writing its file would follow it)."""
        for path in [self.marker, *self.paths.values()]:
            if path.is_symlink():
                raise ByproductsDirectoryError(f'refusing the byproduct {quoted(path.name)}: it is a symbolic link '
                                               '(links are never followed)', 'spec_name')
        text = _MARKER_SIGNATURE + ', '.join(path.name for path in self.paths.values()) + '\n'
        try:
            descriptor = os.open(self.marker, os.O_WRONLY | os.O_CREAT | os.O_TRUNC | os.O_NOFOLLOW, 0o600)
            with os.fdopen(descriptor, 'w', encoding='utf-8') as marker:
                marker.write(text)
        except OSError as error:
            raise unwritable(self.marker, error) from None

    def is_marked(self) -> bool:
        try:
            descriptor = os.open(self.marker, os.O_RDONLY | os.O_NOFOLLOW)
            with os.fdopen(descriptor, encoding='utf-8', errors='replace') as marker:
                return marker.read(len(_MARKER_SIGNATURE)) == _MARKER_SIGNATURE
        except OSError:
            return False

    def write(self, extension: str, text: str) -> Path:
        """Write one file atomically: a new private file renamed over the name (a symbolic link
        there is replaced, not followed); a full or read-only disk is a coded error."""
        path = self.paths[extension]
        part = None
        try:
            with tempfile.NamedTemporaryFile('w', dir=self.directory, prefix=f'.{self.name}.',
                                             suffix='.part', delete=False) as part:
                part.write(text)
            os.replace(part.name, path)
        except OSError as error:
            if part is not None:
                with contextlib.suppress(OSError):
                    os.unlink(part.name)
            raise unwritable(path, error) from None
        return path


class ByproductStore:
    """Where byproducts go and how long they stay (see the module docstring)."""

    def __init__(self, directory: str | Path, keep_last: int = DEFAULT_KEEP_LAST, max_age: float = 0.0,
                 private: bool | None = None):
        """``private``: check the directory as the default one (see :func:`private_directory`);
        None: only when ``directory`` is :func:`default_directory`."""
        if keep_last < 0 or max_age < 0:
            raise ValueError('keep_last and max_age must be >= 0')
        self.directory = Path(directory)
        self.private = self.directory == default_directory() if private is None else private
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
        if self.private:
            private_directory(self.directory)
        else:
            try:
                self.directory.mkdir(parents=True, exist_ok=True)
            except OSError as error:
                raise unwritable(self.directory, error) from None
        files = ByproductSet(self.directory, spec_name)
        files.mark()
        try:
            yield files
        finally:
            self.prune()

    def prune(self, now: float | None = None) -> list[Path]:
        """Delete the marked sets the policy no longer keeps; returns the deleted files."""
        newest: dict[str, float] = {}
        with os.scandir(self.directory) as entries:
            marked = [match['stem'] for match in map(_MARKER_FILE.match, (entry.name for entry in entries))
                      if match and is_spec_name(match['stem'])]
        for stem in marked:
            files = ByproductSet(self.directory, stem)
            if files.is_marked():
                newest[stem] = self._last_written(files)
        by_age = sorted(newest, key=lambda stem: newest[stem], reverse=True)
        doomed = by_age[self.keep_last:]
        if self.max_age > 0:
            cutoff = (time.time() if now is None else now) - self.max_age
            doomed += [stem for stem in by_age[:self.keep_last] if newest[stem] < cutoff]
        deleted = []
        for stem in doomed:
            files = ByproductSet(self.directory, stem)
            for path in [*files.paths.values(), files.marker]:  # the marker last: a retry finds the rest
                with contextlib.suppress(FileNotFoundError):  # another node may prune too
                    if path.is_file() and not path.is_symlink():
                        path.unlink()
                        deleted.append(path)
        return deleted

    def prune_leftovers(self, now: float | None = None) -> list[Path]:
        """Delete what writes cut short left behind (a full disk, a killed process): the
        ``.part`` files of byproducts and empty markers, older than LEFTOVER_AGE (plain files
        named as the suite names them; nothing else is touched). Run at the synthesis node's
        start; returns the deleted files."""
        if not self.directory.is_dir() or self.keep_last == 0:
            return []
        if self.private:
            private_directory(self.directory)  # never in a directory that is not safely ours
        cutoff = (time.time() if now is None else now) - LEFTOVER_AGE
        deleted = []
        with os.scandir(self.directory) as entries:
            for entry in entries:
                part, marker = _PART_FILE.match(entry.name), _MARKER_FILE.match(entry.name)
                match = part or marker
                stem = match['stem'] if match else ''
                if not is_spec_name(stem) or not entry.is_file(follow_symlinks=False):
                    continue
                info = entry.stat(follow_symlinks=False)
                if info.st_mtime < cutoff and (part or info.st_size == 0):
                    with contextlib.suppress(FileNotFoundError):
                        os.unlink(entry.path)
                        deleted.append(Path(entry.path))
        return deleted

    def _last_written(self, files: ByproductSet) -> float:
        """When a marked set was last written: its files' newest mtime, else its marker's."""
        def mtimes(paths):
            for path in paths:
                with contextlib.suppress(FileNotFoundError):
                    yield path.stat(follow_symlinks=False).st_mtime
        return max(mtimes(files.paths.values()), default=None) or max(mtimes([files.marker]), default=0.0)
