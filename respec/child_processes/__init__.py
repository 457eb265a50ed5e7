"""Work in child processes that a cancel, a deadline or a shutdown ends at once: the project's
one process runner, below every core (syntheses and diagnoses, large compilations and
state-machine generations, repair searches, the GUI's simulations).

    runner   ChildProcess (one child: calls, progress, commands, cancel/deadline/memory watching,
             dying with its parent), ChildProcesses (a pool of them, idle ones kept for a while),
             WorkingChildrenMemory (the sum limit of a process tree)
    errors   what the runner raises when it stops work or its child dies: ChildWorkError and its
             kinds WorkCancelledError, WorkTimeoutError, WorkMemoryError, ChildDiedError
    memory   a process's resident memory, and releasing what it no longer uses

The synthesizer's use of it (its pool, its errors for a stopped synthesis) is
``ltl_synthesizer.isolated``.
"""
