"""A process's resident memory, and releasing what it no longer uses (Linux's /proc and glibc;
elsewhere what the standard library tells)."""

from __future__ import annotations

import os


def resident_memory(pid: int | None = None) -> int:
    """This process's resident memory in bytes (Linux; elsewhere its peak so far), or that of
    process ``pid`` (0 once it is gone)."""
    try:
        with open(f'/proc/{pid or "self"}/statm') as statm:
            return int(statm.read().split()[1]) * _PAGE_SIZE
    except OSError:
        if pid is not None:
            return 0
        import resource
        return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024


_PAGE_SIZE = os.sysconf('SC_PAGE_SIZE') if hasattr(os, 'sysconf') else 4096


def released_memory(collect: bool = True) -> int:
    """This process's resident size after its garbage is collected (with ``collect``) and freed
    heap pages go back to the system (glibc's malloc_trim; elsewhere only the collection)."""
    if collect:
        import gc
        gc.collect()
    try:
        import ctypes
        ctypes.CDLL('libc.so.6').malloc_trim(0)
    except (OSError, AttributeError):
        pass
    return resident_memory()
