"""Byproduct files: names that never collide, retention (keep last N, max age, keep none)."""

import os
import time

import pytest

from synthesis_manager.byproducts import ByproductStore, InvalidSpecName


def write_set(store, name):
    with store.open_set(name) as files:
        for extension in ('structuredslugs', 'slugsin', 'json'):
            files.write(extension, f'{name} {extension}\n')
        return files


def test_dotted_spec_names_keep_separate_files(tmp_path):
    store = ByproductStore(tmp_path)
    write_set(store, 'collide.one')
    write_set(store, 'collide.two')
    assert (tmp_path / 'collide.one.slugsin').read_text() == 'collide.one slugsin\n'
    assert (tmp_path / 'collide.two.slugsin').read_text() == 'collide.two slugsin\n'
    assert len(list(tmp_path.iterdir())) == 6


def test_only_the_newest_sets_are_kept(tmp_path):
    store = ByproductStore(tmp_path, keep_last=3)
    for index in range(6):
        write_set(store, f'spec{index}')
        stamp = time.time() - 100 + index  # distinct ages, spec5 newest
        for path in tmp_path.glob(f'spec{index}.*'):
            os.utime(path, (stamp, stamp))
    store.prune()
    assert sorted(p.name for p in tmp_path.glob('*.json')) == ['spec3.json', 'spec4.json', 'spec5.json']
    assert len(list(tmp_path.iterdir())) == 9


def test_sets_older_than_max_age_go(tmp_path):
    store = ByproductStore(tmp_path, keep_last=100, max_age=60)
    write_set(store, 'old')
    write_set(store, 'new')
    for path in tmp_path.glob('old.*'):
        os.utime(path, (time.time() - 120, time.time() - 120))
    (tmp_path / 'notes.txt').write_text('not a byproduct')
    store.prune()
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        'new.json', 'new.slugsin', 'new.structuredslugs', 'notes.txt']


def test_keep_none_leaves_nothing(tmp_path):
    store = ByproductStore(tmp_path / 'byproducts', keep_last=0)
    files = write_set(store, 'spec')
    assert not files.directory.exists()
    assert not (tmp_path / 'byproducts').exists()


@pytest.mark.parametrize('name', ['../escape', '/abs', '.hidden', 'a/b', 'x' * 101])
def test_names_that_could_leave_the_directory_are_refused(tmp_path, name):
    with pytest.raises(InvalidSpecName):
        write_set(ByproductStore(tmp_path), name)
    assert not list(tmp_path.iterdir())
