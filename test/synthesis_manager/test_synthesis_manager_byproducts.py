"""Byproduct files: names that never collide, retention (keep last N, max age, keep none)."""

import os
import time

import pytest

from synthesis_manager.byproducts import ByproductStore, InvalidSpecNameError


def write_set(store, name):
    with store.open_set(name) as files:
        for extension in ('structuredslugs', 'slugsin', 'json'):
            files.write(extension, f'{name} {extension}\n')
        return files


def visible_files(directory):
    return [path for path in directory.iterdir() if not path.name.startswith('.')]


def test_dotted_spec_names_keep_separate_files(tmp_path):
    store = ByproductStore(tmp_path)
    write_set(store, 'collide.one')
    write_set(store, 'collide.two')
    assert (tmp_path / 'collide.one.slugsin').read_text() == 'collide.one slugsin\n'
    assert (tmp_path / 'collide.two.slugsin').read_text() == 'collide.two slugsin\n'
    assert len(visible_files(tmp_path)) == 6


def test_only_the_newest_sets_are_kept(tmp_path):
    store = ByproductStore(tmp_path, keep_last=3)
    for index in range(6):
        write_set(store, f'spec{index}')
        stamp = time.time() - 100 + index  # distinct ages, spec5 newest
        for path in tmp_path.glob(f'spec{index}.*'):
            os.utime(path, (stamp, stamp))
    store.prune()
    assert sorted(p.name for p in tmp_path.glob('*.json')) == ['spec3.json', 'spec4.json', 'spec5.json']
    assert len(visible_files(tmp_path)) == 9


def test_sets_older_than_max_age_go(tmp_path):
    store = ByproductStore(tmp_path, keep_last=100, max_age=60)
    write_set(store, 'old')
    write_set(store, 'new')
    for path in tmp_path.glob('old.*'):
        os.utime(path, (time.time() - 120, time.time() - 120))
    (tmp_path / 'notes.txt').write_text('not a byproduct')
    store.prune()
    assert sorted(p.name for p in visible_files(tmp_path)) == [
        'new.json', 'new.slugsin', 'new.structuredslugs', 'notes.txt']


def test_keep_none_leaves_nothing(tmp_path):
    store = ByproductStore(tmp_path / 'byproducts', keep_last=0)
    files = write_set(store, 'spec')
    assert not files.directory.exists()
    assert not (tmp_path / 'byproducts').exists()


@pytest.mark.parametrize('name', ['../escape', '/abs', '.hidden', 'a/b', 'x' * 101])
def test_names_that_could_leave_the_directory_are_refused(tmp_path, name):
    with pytest.raises(InvalidSpecNameError):
        write_set(ByproductStore(tmp_path), name)
    assert not list(tmp_path.iterdir())


def test_retention_deletes_only_files_the_suite_wrote(tmp_path):
    """Pointed at a directory holding a user's files, retention leaves them alone, whatever
    their extension, age or name (issue 25)."""
    foreign = {'precious.json': 'mine', 'notes.slugsin': 'mine too', 'spec0x.structuredslugs': 'and this',
               '.hidden.byproducts': 'not a marker of a valid set'}
    for name, text in foreign.items():
        (tmp_path / name).write_text(text)
        os.utime(tmp_path / name, (1, 1))  # older than anything the suite writes
    store = ByproductStore(tmp_path, keep_last=1, max_age=60)
    for index in range(3):
        write_set(store, f'spec{index}')
    store.prune(now=time.time() + 3600)  # every set of ours is too old now
    assert {name: (tmp_path / name).read_text() for name in foreign} == foreign
    assert sorted(path.name for path in tmp_path.iterdir()) == sorted(foreign)
