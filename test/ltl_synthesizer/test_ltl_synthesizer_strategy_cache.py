"""The strategy cache's core (ltl_synthesizer.cache): keys, the LRU bound in bytes, one
computation for concurrent identical requests, and the private directory a restarted server
reads back (atomic 0600 files, links never followed, a corrupted file a miss)."""

import os
import stat
import threading
import time

import pytest

from ltl_synthesizer.cache import (ENTRY_OVERHEAD_BYTES, CacheDirectoryError, StrategyCache, cache_key,
                                   default_key_file, entry_size, load_cache_key, source_digest)
from waiting import wait_until


def entry(text: str, size: int = 0) -> dict:
    return {'answer': text.encode(), 'padding': b'x' * size}


def key(name: str) -> str:
    return cache_key({'specification': name})


def test_keys_differ_exactly_when_a_field_differs():
    fields = {'specification': {'sys_props': ['a']}, 'provenance': '', 'robotics_semantics': True}
    assert cache_key(fields) == cache_key(dict(reversed(fields.items())))
    for name, other in (('specification', {'sys_props': ['b']}), ('provenance', '{}'),
                        ('robotics_semantics', False)):
        assert cache_key({**fields, name: other}) != cache_key(fields)
    assert len(cache_key(fields)) == 64


def test_source_digest_follows_the_sources(tmp_path, monkeypatch):
    package = tmp_path / 'digested_package'
    package.mkdir()
    (package / '__init__.py').write_text('X = 1\n')
    monkeypatch.syspath_prepend(str(tmp_path))
    before = source_digest(('digested_package',))
    assert source_digest(('digested_package',)) == before
    (package / '__init__.py').write_text('X = 2\n')
    assert source_digest(('digested_package',)) != before


def test_the_least_recently_used_entries_go_past_the_bound_in_bytes():
    one = entry_size(entry('a', 1000))
    cache = StrategyCache(max_bytes=3 * one)
    for name in 'abc':
        assert cache.put(key(name), entry(name, 1000))
    assert cache.get(key('a')) == entry('a', 1000)  # a is now the most recently used
    cache.put(key('d'), entry('d', 1000))
    assert cache.get(key('b')) is None
    assert [cache.get(key(name)) is not None for name in 'acd'] == [True, True, True]
    assert cache.memory_bytes == 3 * one <= cache.max_bytes
    assert cache.statistics.evicted == 1
    assert not cache.put(key('huge'), entry('huge', 3 * one))  # alone over the bound: not kept
    assert cache.get(key('huge')) is None and len(cache) == 3


def test_an_entry_counts_its_bytes_and_an_overhead():
    assert entry_size({'a': b'12345'}) == ENTRY_OVERHEAD_BYTES + 1 + 5


def test_zero_bytes_disables_the_cache():
    cache = StrategyCache(max_bytes=0, directory='/nonexistent/never/created')
    calls = []
    for _ in range(3):
        assert cache.answer(key('a'), lambda: calls.append(1) or entry('a')) == (entry('a'), 'computed')
    assert len(calls) == 3 and cache.get(key('a')) is None and cache.directory is None


def test_concurrent_identical_requests_are_one_computation():
    cache = StrategyCache()
    calls, started, waiting = [], threading.Event(), set()

    def compute():
        calls.append(threading.current_thread().name)
        started.set()
        # the others arrive meanwhile: each waits for this computation (asking whether to give up)
        wait_until(lambda: len(waiting) == 7, 10, 'seven identical requests waiting for the first')
        return entry('answer')

    answers = [None] * 8

    def ask(index):
        answers[index] = cache.answer(key('same'), compute, give_up=lambda: waiting.add(index))

    threads = [threading.Thread(target=ask, args=(index,), name=f'asker-{index}') for index in range(8)]
    threads[0].start()
    started.wait(5)
    for thread in threads[1:]:
        thread.start()
    for thread in threads:
        thread.join(10)
    assert len(calls) == 1
    assert [value for value, _ in answers] == [entry('answer')] * 8
    assert sorted(how for _, how in answers) == ['computed'] + ['shared'] * 7
    assert cache.statistics.misses == 1 and cache.statistics.shared == 7
    assert cache.answer(key('same'), compute) == (entry('answer'), 'hit') and len(calls) == 1


def test_an_answer_not_kept_lets_each_waiter_compute_within_its_own_limits():
    cache = StrategyCache()
    calls, first_started, release = [], threading.Event(), threading.Event()

    def compute():
        calls.append(1)
        if len(calls) == 1:  # the first is stopped (its own cancel): nothing kept
            first_started.set()
            release.wait(5)
            return None
        return entry('answer')

    results = {}
    first = threading.Thread(target=lambda: results.setdefault('first', cache.answer(key('k'), compute)))
    first.start()
    first_started.wait(5)
    second = threading.Thread(target=lambda: results.setdefault('second', cache.answer(key('k'), compute)))
    second.start()
    time.sleep(0.1)
    release.set()
    first.join(5)
    second.join(5)
    assert results['first'] == (None, 'computed')
    assert results['second'] == (entry('answer'), 'computed')
    assert len(calls) == 2


def test_a_waiter_gives_up_at_its_own_limit():
    cache = StrategyCache()
    started, release = threading.Event(), threading.Event()

    def slow():
        started.set()
        release.wait(5)
        return entry('late')

    leader = threading.Thread(target=cache.answer, args=(key('k'), slow))
    leader.start()
    started.wait(5)
    give_up_at = time.monotonic() + 0.1
    began = time.monotonic()
    assert cache.answer(key('k'), slow, give_up=lambda: time.monotonic() > give_up_at) == (None, 'gave up')
    assert time.monotonic() - began < 1.0
    release.set()
    leader.join(5)


def test_a_restarted_cache_reads_its_private_directory(tmp_path):
    directory = tmp_path / 'cache'
    StrategyCache(directory=directory).put(key('a'), entry('a', 100))
    assert stat.S_IMODE(os.lstat(directory).st_mode) == 0o700
    files = list(directory.iterdir())
    assert [path.name for path in files] == [key('a') + '.entry']
    assert stat.S_IMODE(os.lstat(files[0]).st_mode) == 0o600
    restarted = StrategyCache(directory=directory)
    assert restarted.get(key('a')) == entry('a', 100)
    assert restarted.statistics.disk_hits == 1
    assert restarted.get(key('a')) == entry('a', 100) and restarted.statistics.disk_hits == 1  # now in memory


@pytest.mark.parametrize('damage', ['truncated', 'flipped byte', 'garbage', 'empty', 'another key'])
def test_a_corrupted_file_is_a_miss_and_is_deleted(tmp_path, damage):
    StrategyCache(directory=tmp_path / 'cache').put(key('a'), entry('a', 100))
    path = tmp_path / 'cache' / (key('a') + '.entry')
    data = path.read_bytes()
    if damage == 'truncated':
        path.write_bytes(data[:-10])
    elif damage == 'flipped byte':
        path.write_bytes(data[:-5] + bytes([data[-5] ^ 1]) + data[-4:])
    elif damage == 'garbage':
        path.write_bytes(os.urandom(len(data)))
    elif damage == 'empty':
        path.write_bytes(b'')
    else:  # a whole entry of another key, renamed
        StrategyCache(directory=tmp_path / 'cache').put(key('b'), entry('b', 100))
        os.replace(tmp_path / 'cache' / (key('b') + '.entry'), path)
    cache = StrategyCache(directory=tmp_path / 'cache')
    assert cache.get(key('a')) is None
    assert cache.statistics.corrupt == 1 and not path.exists()
    assert cache.answer(key('a'), lambda: entry('a', 100)) == (entry('a', 100), 'computed')
    assert StrategyCache(directory=tmp_path / 'cache').get(key('a')) == entry('a', 100)


def test_links_are_never_followed(tmp_path):
    target = tmp_path / 'precious'
    target.write_bytes(b'a user file')
    directory = tmp_path / 'cache'
    directory.mkdir(mode=0o700)
    link = directory / (key('a') + '.entry')
    link.symlink_to(target)
    cache = StrategyCache(directory=directory)
    assert cache.get(key('a')) is None  # not read through the link; the link is removed
    assert not link.is_symlink() and target.read_bytes() == b'a user file'
    link.symlink_to(target)
    cache.put(key('a'), entry('a'))  # replaces the link, never writes through it
    assert not link.is_symlink() and target.read_bytes() == b'a user file'
    assert StrategyCache(directory=directory).get(key('a')) == entry('a')
    linked_directory = tmp_path / 'linked'
    linked_directory.symlink_to(directory)
    with pytest.raises(CacheDirectoryError, match='symbolic link'):
        StrategyCache(directory=linked_directory)


def test_a_directory_others_can_write_is_refused(tmp_path):
    directory = tmp_path / 'shared'
    directory.mkdir()
    directory.chmod(0o777)
    with pytest.raises(CacheDirectoryError, match='writable by others'):
        StrategyCache(directory=directory)


def test_the_directory_keeps_within_the_bound(tmp_path):
    one = entry_size(entry('a', 1000))
    cache = StrategyCache(max_bytes=3 * one + 1000, directory=tmp_path / 'cache')
    for index, name in enumerate('abcde'):
        cache.put(key(name), entry(name, 1000))
        stamp = time.time() - 100 + index  # distinct ages: e newest
        os.utime(tmp_path / 'cache' / (key(name) + '.entry'), (stamp, stamp))
    sizes = [path.stat().st_size for path in (tmp_path / 'cache').iterdir()]
    assert sum(sizes) <= cache.max_bytes
    restarted = StrategyCache(max_bytes=cache.max_bytes, directory=tmp_path / 'cache')
    assert restarted.get(key('a')) is None and restarted.get(key('e')) == entry('e', 1000)


def test_a_lowered_bound_misses_entries_over_it(tmp_path):
    StrategyCache(directory=tmp_path / 'cache').put(key('big'), entry('big', 4 * 2**20))
    small = StrategyCache(max_bytes=2**20, directory=tmp_path / 'cache')
    assert small.get(key('big')) is None and small.memory_bytes == 0
    assert list((tmp_path / 'cache').iterdir()) == []


def test_a_fifo_planted_as_an_entry_is_a_miss_at_once(tmp_path):
    directory = tmp_path / 'cache'
    StrategyCache(directory=directory)
    fifo = directory / (key('a') + '.entry')
    os.mkfifo(fifo, 0o600)
    cache = StrategyCache(directory=directory)
    began = time.monotonic()
    result = []
    reader = threading.Thread(target=lambda: result.append(cache.get(key('a'))), daemon=True)
    reader.start()
    reader.join(5)
    assert not reader.is_alive(), 'reading a FIFO entry blocked'
    assert result == [None] and time.monotonic() - began < 5
    assert not fifo.exists() and cache.statistics.corrupt == 1
    assert cache.answer(key('a'), lambda: entry('a')) == (entry('a'), 'computed')


def _forged(path, text: bytes):
    """Rewrite the entry file at ``path`` with another answer and a recomputed SHA-256 (what
    someone who can write the directory but lacks the key can do)."""
    import hashlib
    import json
    data = path.read_bytes()
    magic_end = data.index(b'\n') + 1
    start = magic_end + 8
    header_end = start + int.from_bytes(data[magic_end:start], 'little')
    header = json.loads(data[start:header_end])
    parts = {'answer': text, 'padding': b''}
    digest = hashlib.sha256()
    for name in sorted(parts):
        digest.update(name.encode() + b'\0' + len(parts[name]).to_bytes(8, 'little') + parts[name])
    header['parts'] = [[name, len(parts[name])] for name in sorted(parts)]
    header['hmac'] = header['sha256'] = digest.hexdigest()
    encoded = json.dumps(header).encode()
    path.write_bytes(data[:magic_end] + len(encoded).to_bytes(8, 'little') + encoded
                     + b''.join(parts[name] for name in sorted(parts)))


def test_an_entry_forged_without_the_key_is_a_miss(tmp_path):
    directory = tmp_path / 'cache'
    StrategyCache(directory=directory).put(key('a'), entry('a'))
    path = directory / (key('a') + '.entry')
    _forged(path, b'the task is impossible; call +1-555-FORGED')
    cache = StrategyCache(directory=directory)
    assert cache.get(key('a')) is None
    assert cache.statistics.corrupt == 1 and not path.exists()


def test_the_signing_key_is_a_private_file_beside_the_directory(tmp_path):
    directory = tmp_path / 'cache'
    StrategyCache(directory=directory).put(key('a'), entry('a'))
    key_file = default_key_file(directory)
    assert key_file == tmp_path / 'cache.key' and key_file.is_file()
    assert stat.S_IMODE(os.lstat(key_file).st_mode) == 0o600
    assert len(load_cache_key(key_file, create=False)) == 32
    key_file.unlink()  # a new key: what the old one signed is no longer an answer
    assert StrategyCache(directory=directory).get(key('a')) is None


def test_a_fleet_shares_a_key_its_operator_gives(tmp_path):
    fleet_key = tmp_path / 'fleet.key'
    fleet_key.write_bytes(os.urandom(32))
    fleet_key.chmod(0o600)
    StrategyCache(directory=tmp_path / 'one', key_file=fleet_key).put(key('a'), entry('a'))
    (tmp_path / 'two').mkdir(mode=0o700)
    os.replace(tmp_path / 'one' / (key('a') + '.entry'), tmp_path / 'two' / (key('a') + '.entry'))
    assert StrategyCache(directory=tmp_path / 'two', key_file=fleet_key).get(key('a')) == entry('a')
    assert StrategyCache(directory=tmp_path / 'two').get(key('a')) is None  # its own key: not signed with it


@pytest.mark.parametrize('problem', ['readable by others', 'a link', 'too short'])
def test_an_unsafe_key_file_is_refused(tmp_path, problem):
    key_file = tmp_path / 'cache.key'
    if problem == 'a link':
        (tmp_path / 'elsewhere').write_bytes(os.urandom(32))
        key_file.symlink_to(tmp_path / 'elsewhere')
    else:
        key_file.write_bytes(os.urandom(32 if problem == 'readable by others' else 4))
        key_file.chmod(0o644 if problem == 'readable by others' else 0o600)
    with pytest.raises(CacheDirectoryError, match='key file'):
        StrategyCache(directory=tmp_path / 'cache', key_file=key_file)
