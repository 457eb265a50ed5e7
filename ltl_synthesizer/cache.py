"""Answers of identical synthesis requests, kept so that a fleet asking the same task many times
pays for one synthesis.

An answer is kept under a key that digests everything it depends on (:func:`cache_key`: the
specification's text, what the caller adds to the answer, the options that change it and the
code that computes it), so a hit is the answer a fresh synthesis would give. What is kept is
the caller's business: an entry is a few named byte strings (the synthesis node keeps its
response and byproduct files). Entries are bounded in bytes (least recently used go first) in
memory and, with a directory, on disk too, where a restarted server finds them again.

Concurrent identical requests are one synthesis (:meth:`StrategyCache.answer`): the first
computes, the others wait for its answer. An answer the first one could not get (its time
limit, its cancel, its memory limit) is not kept, and each waiter then computes in turn within
its own limits.

On disk, each entry is one file ``<key>.entry`` in a private directory (0700, this user's,
refused if a link), written to a new 0600 file renamed over the name (a reader never sees half
an entry) and read without following a link, without blocking (a FIFO planted there is never
waited on) and only as a regular file of bounded size. Every file is signed with an HMAC under
a key private to the server (:func:`load_cache_key`: a 0600 key file, made on first use, or one
an operator gives a fleet), so a file written by anyone without the key, even under the right
name with a recomputed checksum, is not an answer. A file that is not a whole, signed entry of
this key (truncated, corrupted, forged, another format) is deleted and counts as a miss.
"""

from __future__ import annotations

import collections
import contextlib
import hashlib
import hmac
import json
import os
import stat
import tempfile
import threading
from dataclasses import dataclass
from importlib.util import find_spec
from pathlib import Path
from typing import Callable, Mapping

from respec.vocabulary.private_files import private_directory_problem

#: The default bound of a cache (memory, and the directory if any): 64 MiB holds about 70 000
#: automaton transitions of answers, or thousands of answers of ATLAS-sized tasks (~30 kB each).
DEFAULT_MAX_BYTES = 64 * 2**20
#: Bytes an entry costs beyond its parts (its key, its bookkeeping), so that many tiny entries
#: are bounded too.
ENTRY_OVERHEAD_BYTES = 256
#: Changes whenever what a key covers or how an entry is written changes: older entries miss.
FORMAT = 'behavior-synthesis strategy cache 2'
_MAGIC = (FORMAT + '\n').encode()
_HEADER_LENGTH_BYTES = 8
_SUFFIX = '.entry'
#: How often a waiter for another request's identical synthesis looks at its own limits.
WAIT_POLL_SECONDS = 0.02

Entry = Mapping[str, bytes]


#: Bytes of a signing key (:func:`load_cache_key`).
KEY_BYTES = 32


class CacheDirectoryError(OSError):
    """The cache directory or its key file is unsafe (a link, another user's, readable or
    writable by others) or unusable."""


def default_key_file(directory: str | Path) -> Path:
    """Where a cache directory's signing key lives unless an operator names one: beside the
    directory (``<directory>.key``), not in it, so that what can only write entries never reads it."""
    directory = Path(directory)
    return directory.with_name(directory.name + '.key')


def load_cache_key(path: str | Path, create: bool = True) -> bytes:
    """The signing key in ``path``: a regular 0600 file of this user (never a link) holding
    KEY_BYTES random bytes, written there first when missing and ``create``. Raises
    CacheDirectoryError naming what is wrong; a fleet gives every server the same file."""
    path = Path(path)
    if create:
        with contextlib.suppress(FileExistsError):
            descriptor = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_NOFOLLOW, 0o600)
            with os.fdopen(descriptor, 'wb') as file:
                file.write(os.urandom(KEY_BYTES))
    try:
        descriptor = os.open(path, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK)
    except OSError as error:
        raise CacheDirectoryError(f'strategy cache key file {str(path)!r} cannot be read ({error.strerror})') from None
    with os.fdopen(descriptor, 'rb') as file:
        info = os.fstat(file.fileno())
        if not stat.S_ISREG(info.st_mode):
            raise CacheDirectoryError(f'strategy cache key file {str(path)!r} is not a regular file')
        if info.st_uid != os.getuid() or info.st_mode & (stat.S_IRWXG | stat.S_IRWXO):
            raise CacheDirectoryError(f'strategy cache key file {str(path)!r} must be this user\'s and 0600 '
                                      f'(mode {stat.S_IMODE(info.st_mode):o})')
        key = file.read(KEY_BYTES + 1)
    if len(key) < 16:
        raise CacheDirectoryError(f'strategy cache key file {str(path)!r} holds {len(key)} bytes, fewer than 16')
    return key


def cache_key(fields: Mapping[str, object]) -> str:
    """The key of an answer: a SHA-256 of ``fields`` (JSON values) as canonical JSON, with
    :data:`FORMAT`. Two requests have one key exactly when every field is equal."""
    text = json.dumps({'format': FORMAT, **fields}, sort_keys=True, ensure_ascii=False, separators=(',', ':'))
    return hashlib.sha256(text.encode()).hexdigest()


def source_digest(packages: tuple[str, ...]) -> str:
    """A SHA-256 of the Python sources of ``packages`` (found, not imported): part of a key, so
    that an entry kept on disk by other code (an update of the synthesizer) misses."""
    digest = hashlib.sha256()
    for package in packages:
        spec = find_spec(package)
        if spec is None or not spec.submodule_search_locations:
            raise ValueError(f'{package!r} is not an installed package')
        root = Path(next(iter(spec.submodule_search_locations)))
        for path in sorted(root.rglob('*.py')):
            digest.update(f'{package}/{path.relative_to(root).as_posix()}\0'.encode())
            digest.update(hashlib.sha256(path.read_bytes()).digest())
    return digest.hexdigest()


def entry_size(entry: Entry) -> int:
    """What ``entry`` counts against the bound: its parts' names and bytes plus the overhead."""
    return ENTRY_OVERHEAD_BYTES + sum(len(name) + len(data) for name, data in entry.items())


@dataclass
class CacheStatistics:
    hits: int = 0          # answered from memory or disk
    disk_hits: int = 0     # of those, read from the directory
    shared: int = 0        # answered by another request's synthesis, waited for
    misses: int = 0        # computed
    stored: int = 0        # answers kept
    evicted: int = 0       # entries dropped for the bound (memory)
    corrupt: int = 0       # files on disk that were not a whole, signed entry (deleted)
    rejected: int = 0      # of those, whole entries whose check found a problem (deleted too)


class _Flight:
    """One synthesis that identical requests wait for."""

    def __init__(self) -> None:
        self.done = threading.Event()
        self.entry: Entry | None = None


class StrategyCache:
    """Entries under keys, least recently used dropped past ``max_bytes`` (0: nothing is kept,
    :meth:`answer` always computes); with ``directory``, kept there too, within the same bound,
    each file signed with the key in ``key_file`` (default: :func:`default_key_file`)."""

    def __init__(self, max_bytes: int = DEFAULT_MAX_BYTES, directory: str | Path | None = None,
                 key_file: str | Path | None = None):
        if max_bytes < 0:
            raise ValueError('max_bytes must be >= 0')
        self.max_bytes = max_bytes
        self.directory = Path(directory) if directory and max_bytes else None
        self.statistics = CacheStatistics()
        self._entries: collections.OrderedDict[str, Entry] = collections.OrderedDict()
        self._bytes = 0
        self._lock = threading.Lock()
        self._flights: dict[str, _Flight] = {}
        self._signing_key = b''
        if self.directory is not None:
            problem = private_directory_problem(self.directory)
            if problem:
                raise CacheDirectoryError(f'refusing the strategy cache directory {str(self.directory)!r}: '
                                          f'it {problem}')
            self._signing_key = load_cache_key(key_file or default_key_file(self.directory))

    @property
    def enabled(self) -> bool:
        return self.max_bytes > 0

    @property
    def memory_bytes(self) -> int:
        """What the entries in memory count against the bound."""
        with self._lock:
            return self._bytes

    def __len__(self) -> int:
        with self._lock:
            return len(self._entries)

    def get(self, key: str, check: Callable[[Entry], str | None] | None = None) -> Entry | None:
        """The entry of ``key`` (from memory, else from the directory), or None. An entry read
        from the directory is served only when ``check(entry)`` finds no problem (it names one:
        the file is then deleted, a miss)."""
        if not self.enabled:
            return None
        with self._lock:
            entry = self._entries.get(key)
            if entry is not None:
                self._entries.move_to_end(key)
                self.statistics.hits += 1
                return entry
        entry = self._read(key) if self.directory is not None else None
        if entry is not None and check is not None and check(entry):
            self._discard(self._path(key))
            with self._lock:
                self.statistics.rejected += 1
            entry = None
        if entry is not None:
            if entry_size(entry) <= self.max_bytes:  # a bound lowered since it was written
                self._remember(key, entry)
            with self._lock:
                self.statistics.hits += 1
                self.statistics.disk_hits += 1
        return entry

    def put(self, key: str, entry: Entry) -> bool:
        """Keep ``entry`` under ``key`` (in memory and in the directory); False when it alone
        exceeds the bound (nothing is kept)."""
        if not self.enabled or entry_size(entry) > self.max_bytes:
            return False
        self._remember(key, entry)
        if self.directory is not None:
            self._write(key, entry)
        with self._lock:
            self.statistics.stored += 1
        return True

    def answer(self, key: str, compute: Callable[[], Entry | None],
               give_up: Callable[[], bool] | None = None,
               check: Callable[[Entry], str | None] | None = None) -> tuple[Entry | None, str]:
        """The entry of ``key`` and how it came: ``('hit')`` kept, ``('shared')`` computed
        for an identical request running at the same time (waited for), ``('computed')`` by
        ``compute()`` here, which returns the entry to keep or None when its answer must not be
        kept (then the caller's answer is whatever ``compute`` left, and the entry is None).
        While waiting for another request, ``give_up()`` (its own cancel, its deadline) ends
        the wait: ``(None, 'gave up')``. ``check``: as for :meth:`get`."""
        if not self.enabled:
            return compute(), 'computed'
        while True:
            entry = self.get(key, check)
            if entry is not None:
                return entry, 'hit'
            with self._lock:
                flight = self._flights.get(key)
                leading = flight is None
                if leading:
                    flight = self._flights[key] = _Flight()
                    self.statistics.misses += 1
            assert flight is not None  # found or made just now
            if leading:
                try:
                    flight.entry = compute()
                    if flight.entry is not None:
                        self.put(key, flight.entry)
                    return flight.entry, 'computed'
                finally:
                    with self._lock:
                        del self._flights[key]
                    flight.done.set()
            while not flight.done.wait(WAIT_POLL_SECONDS):
                if give_up is not None and give_up():
                    return None, 'gave up'
            if flight.entry is not None:
                with self._lock:
                    self.statistics.shared += 1
                return flight.entry, 'shared'
            # Its answer was not kept (its own limits stopped it): try again, within ours.

    def _remember(self, key: str, entry: Entry) -> None:
        with self._lock:
            if key in self._entries:
                self._bytes -= entry_size(self._entries.pop(key))
            self._entries[key] = entry
            self._bytes += entry_size(entry)
            while self._bytes > self.max_bytes:
                _, dropped = self._entries.popitem(last=False)
                self._bytes -= entry_size(dropped)
                self.statistics.evicted += 1

    # --- on disk ------------------------------------------------------------------------------

    def _path(self, key: str) -> Path:
        if len(key) != 64 or any(c not in '0123456789abcdef' for c in key):
            raise ValueError(f'not a cache key: {key!r}')
        assert self.directory is not None  # the files of a cache that has a folder
        return self.directory / (key + _SUFFIX)

    def _write(self, key: str, entry: Entry) -> None:
        """Write the entry's file atomically (a new 0600 file renamed over the name: a link
        there is replaced, not followed), then drop the least recently used files past the
        bound. A full or read-only disk leaves the entry in memory only."""
        names = sorted(entry)
        header = json.dumps({'key': key, 'parts': [[name, len(entry[name])] for name in names],
                             'hmac': _parts_signature(self._signing_key, entry, names)}).encode()
        part = None
        try:
            descriptor, part = tempfile.mkstemp(dir=self.directory, prefix='.', suffix='.part')
            with os.fdopen(descriptor, 'wb') as file:
                file.write(_MAGIC + len(header).to_bytes(_HEADER_LENGTH_BYTES, 'little') + header)
                for name in names:
                    file.write(entry[name])
            os.replace(part, self._path(key))
        except OSError:
            if part is not None:
                with contextlib.suppress(OSError):
                    os.unlink(part)
            return
        self._prune_directory()

    def _read(self, key: str) -> Entry | None:
        """The entry in ``key``'s file, or None: missing, or not a whole, signed entry of this
        key (then deleted). A link is never followed and nothing is waited on: the file is
        opened non-blocking and read only when it is a regular file no larger than any entry kept."""
        path = self._path(key)
        try:
            descriptor = os.open(path, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK)
        except OSError:  # missing, a link (ELOOP), a FIFO without a writer, a socket
            if path.exists() or path.is_symlink():
                self._discard(path)
            return None
        try:
            with os.fdopen(descriptor, 'rb') as file:
                info = os.fstat(file.fileno())
                limit = self.max_bytes + 2**20
                if not stat.S_ISREG(info.st_mode) or info.st_size > limit:
                    raise ValueError('not a regular file, or larger than any entry kept')
                entry = _parsed_entry(file.read(limit + 1), key, self._signing_key)
                os.utime(file.fileno())  # recently used: the directory's pruning keeps it longer
            return entry
        except (OSError, ValueError, KeyError, TypeError):
            self._discard(path)
            return None

    def _discard(self, path: Path) -> None:
        with self._lock:
            self.statistics.corrupt += 1
        with contextlib.suppress(OSError):
            os.unlink(path)  # a link itself, never its target

    def _prune_directory(self) -> None:
        """Delete the least recently used entry files until the directory holds at most max_bytes."""
        files = []
        with contextlib.suppress(OSError), os.scandir(self.directory) as entries:
            for item in entries:
                if item.name.endswith(_SUFFIX) and item.is_file(follow_symlinks=False):
                    with contextlib.suppress(OSError):
                        info = item.stat(follow_symlinks=False)
                        files.append((info.st_mtime, info.st_size, item.path))
        total = sum(size for _, size, _ in files)
        for _, size, path in sorted(files):
            if total <= self.max_bytes:
                break
            with contextlib.suppress(OSError):
                os.unlink(path)
            total -= size


def _parts_signature(signing_key: bytes, entry: Entry, names: list[str]) -> str:
    signature = hmac.new(signing_key, digestmod=hashlib.sha256)
    for name in names:
        signature.update(name.encode() + b'\0' + len(entry[name]).to_bytes(8, 'little') + entry[name])
    return signature.hexdigest()


def _parsed_entry(data: bytes, key: str, signing_key: bytes) -> Entry:
    """The entry written by StrategyCache._write; ValueError when ``data`` is not one of ``key``
    signed with ``signing_key``."""
    if not data.startswith(_MAGIC):
        raise ValueError('another format')
    start = len(_MAGIC) + _HEADER_LENGTH_BYTES
    header_end = start + int.from_bytes(data[len(_MAGIC):start], 'little')
    header = json.loads(data[start:header_end])
    if header['key'] != key:
        raise ValueError('another key')
    entry, offset = {}, header_end
    for name, length in header['parts']:
        if not isinstance(name, str) or not isinstance(length, int) or length < 0:
            raise ValueError('a malformed header')
        entry[name] = data[offset:offset + length]
        offset += length
    if offset != len(data) or not hmac.compare_digest(
            _parts_signature(signing_key, entry, sorted(entry)), str(header['hmac'])):
        raise ValueError('truncated, corrupted or not signed with this key')
    return entry
