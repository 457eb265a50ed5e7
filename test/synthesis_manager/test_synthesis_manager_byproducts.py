"""Byproduct files: names that never collide, retention (keep last N, max age, keep none)."""

import errno
import os
import stat
import time

import pytest

from synthesis_manager.byproducts import (ByproductsDirectoryError, ByproductStore, InvalidSpecNameError,
                                          default_directory)

pytestmark = pytest.mark.ros


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


# Safety on a shared machine (issue 34, items 7 and 11): no link followed, a private default
# directory, and a full or read-only disk answered with a code.

def test_a_planted_marker_symlink_is_not_followed(tmp_path):
    target = tmp_path / 'victim.txt'
    target.write_text('precious\n')
    directory = tmp_path / 'byproducts'
    directory.mkdir(mode=0o700)
    (directory / '.planted.byproducts').symlink_to(target)
    with pytest.raises(ByproductsDirectoryError, match='symbolic link') as raised:
        write_set(ByproductStore(directory), 'planted')
    assert raised.value.code == 'SYNTHESIS_FAILED'
    assert target.read_text() == 'precious\n'


def test_a_planted_file_symlink_is_not_followed(tmp_path):
    target = tmp_path / 'victim.txt'
    target.write_text('precious\n')
    (tmp_path / 'planted.json').symlink_to(target)
    with pytest.raises(ByproductsDirectoryError, match='planted.json'):
        write_set(ByproductStore(tmp_path), 'planted')
    assert target.read_text() == 'precious\n'


def test_a_marker_behind_a_symlink_is_not_ours(tmp_path):
    """A link to a real marker elsewhere does not make retention delete its neighbours."""
    elsewhere = tmp_path / 'elsewhere'
    write_set(ByproductStore(elsewhere), 'other')
    directory = tmp_path / 'byproducts'
    directory.mkdir()
    (directory / 'other.json').write_text('a user file\n')
    (directory / '.other.byproducts').symlink_to(elsewhere / '.other.byproducts')
    write_set(ByproductStore(directory, keep_last=1), 'mine')
    assert (directory / 'other.json').read_text() == 'a user file\n'


def test_a_fresh_private_directory_is_0700(tmp_path):
    directory = tmp_path / 'private'
    write_set(ByproductStore(directory, private=True), 'fresh')
    assert stat.S_IMODE(directory.stat().st_mode) == 0o700
    assert (directory / 'fresh.json').read_text() == 'fresh json\n'


def test_the_default_directory_is_private():
    assert ByproductStore(default_directory()).private
    assert not ByproductStore('/somewhere/else').private


@pytest.mark.parametrize('mode', [0o777, 0o770, 0o1777])
def test_a_loose_private_directory_is_refused(tmp_path, mode):
    directory = tmp_path / 'loose'
    directory.mkdir()
    os.chmod(directory, mode)
    with pytest.raises(ByproductsDirectoryError, match='writable by others') as raised:
        write_set(ByproductStore(directory, private=True), 'refused')
    assert raised.value.item == 'byproducts_dir'
    assert list(directory.iterdir()) == []


def test_a_private_directory_of_another_user_is_refused(tmp_path, monkeypatch):
    directory = tmp_path / 'theirs'
    directory.mkdir(mode=0o700)
    if os.getuid() == 0:
        os.chown(directory, 12345, 12345)
    else:  # only root can give a directory away: this process pretends to be someone else
        monkeypatch.setattr(os, 'getuid', lambda: os.stat(directory).st_uid + 1)
    with pytest.raises(ByproductsDirectoryError, match='another user'):
        write_set(ByproductStore(directory, private=True), 'refused')
    assert list(directory.iterdir()) == []


def test_a_private_directory_that_is_a_symlink_is_refused(tmp_path):
    real = tmp_path / 'real'
    real.mkdir(mode=0o700)
    (tmp_path / 'link').symlink_to(real)
    with pytest.raises(ByproductsDirectoryError, match='not a directory'):
        write_set(ByproductStore(tmp_path / 'link', private=True), 'refused')
    assert list(real.iterdir()) == []


@pytest.mark.parametrize('number', [errno.ENOSPC, errno.EROFS])
def test_a_full_or_read_only_disk_is_a_coded_error(tmp_path, monkeypatch, number):
    store = ByproductStore(tmp_path)

    def failing_replace(source, destination):
        raise OSError(number, os.strerror(number))

    monkeypatch.setattr(os, 'replace', failing_replace)
    with pytest.raises(ByproductsDirectoryError) as raised:
        write_set(store, 'full')
    message = str(raised.value)
    assert raised.value.code == 'SYNTHESIS_FAILED'
    assert errno.errorcode[number] in message and 'full.structuredslugs' in message
    assert len(message) < 300
    assert not list(tmp_path.glob('*.part'))


def test_an_unwritable_marker_is_a_coded_error(tmp_path, monkeypatch):
    real_open = os.open

    def full_disk(path, flags, *args):
        if flags & os.O_CREAT:
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        return real_open(path, flags, *args)

    monkeypatch.setattr(os, 'open', full_disk)
    with pytest.raises(ByproductsDirectoryError, match='ENOSPC'):
        write_set(ByproductStore(tmp_path), 'full')


def test_leftovers_of_cut_short_writes_are_pruned_and_nothing_else(tmp_path):
    """Issue 34, item 12: a full disk or a kill leaves ``.part`` files and empty markers that
    retention never saw. The synthesis node's start deletes them once older than LEFTOVER_AGE;
    a set being written now, a marked set, a user's files and links stay."""
    from synthesis_manager.byproducts import LEFTOVER_AGE
    store = ByproductStore(tmp_path)
    kept = write_set(store, 'kept')
    old = time.time() - LEFTOVER_AGE - 10
    leftovers = [tmp_path / '.cut.a1b2c3d4.part', tmp_path / '.empty.byproducts']
    recent = [tmp_path / '.writing.e5f6g7h8.part', tmp_path / '.starting.byproducts']
    users = [tmp_path / 'precious.part', tmp_path / '.hidden.part', tmp_path / '.notes.byproducts.txt']
    for path in leftovers + recent + users:
        path.write_text('' if path.name.endswith('.byproducts') else 'partial')
    (tmp_path / 'target').write_text('a user file')
    link = tmp_path / '.link.a1b2c3d4.part'
    link.symlink_to(tmp_path / 'target')
    for path in leftovers + users + [kept.marker]:
        os.utime(path, (old, old))
    os.utime(link, (old, old), follow_symlinks=False)
    assert sorted(store.prune_leftovers()) == sorted(leftovers)
    assert not any(path.exists() for path in leftovers)
    assert all(path.exists() for path in recent + users + [kept.marker, *kept.paths.values(), link])
    assert (tmp_path / 'target').read_text() == 'a user file'


def test_the_synthesis_node_prunes_leftovers_at_its_start(ros, tmp_path):
    from rclpy.parameter import Parameter

    from synthesis_manager.byproducts import LEFTOVER_AGE
    from synthesis_manager.nodes.ltl_synthesis_node import LTLSynthesisNode
    old = time.time() - LEFTOVER_AGE - 10
    leftovers = [tmp_path / '.cut.a1b2c3d4.part', tmp_path / '.empty.byproducts']
    for path in leftovers:
        path.write_text('' if path.suffix == '.byproducts' else 'partial')
        os.utime(path, (old, old))
    (tmp_path / 'precious.json').write_text('{}')
    ros.add_node(LTLSynthesisNode, parameter_overrides=[Parameter('byproducts_dir', value=str(tmp_path))])
    assert not any(path.exists() for path in leftovers)
    assert (tmp_path / 'precious.json').exists()
