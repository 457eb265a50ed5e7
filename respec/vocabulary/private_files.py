"""Directories that only this user may write to: where the suite keeps files that it later reads
back or deletes (the synthesizer's byproducts, the strategy cache). A directory another user
could write to, or a symbolic link put where the directory goes, would let someone else choose
what is read or deleted."""

from __future__ import annotations

import os
import stat
from pathlib import Path


def private_directory_problem(directory: Path) -> str | None:
    """Create ``directory`` 0700 if missing (an OSError is the caller's to report); then what
    makes it unsafe ('is not a directory ...'), or None when it is a real directory (not a
    symbolic link) of this user that no one else can write to."""
    try:
        os.mkdir(directory, 0o700)
    except FileExistsError:
        pass
    info = os.lstat(directory)
    if not stat.S_ISDIR(info.st_mode):
        return 'is not a directory (a symbolic link or a file)'
    if info.st_uid != os.getuid():
        return f'belongs to another user (uid {info.st_uid})'
    if info.st_mode & (stat.S_IWGRP | stat.S_IWOTH):
        return f'is writable by others (mode {stat.S_IMODE(info.st_mode):o})'
    return None
