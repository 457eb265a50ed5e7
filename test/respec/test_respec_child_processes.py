"""respec.child_processes: work in child processes, stopped by killing the child, in the runner's
own words (what the synthesizer makes of it: test/ltl_synthesizer/test_ltl_synthesizer_isolated.py)."""

import operator
import os
import threading
import time
from pathlib import Path

import pytest

from respec.child_processes.errors import ChildDiedError, WorkCancelledError, WorkTimeoutError
from respec.child_processes.runner import ChildProcess, ChildProcesses
from respec.ltl import var
from respec.spec import GR1Specification


def test_a_cancel_and_the_deadline_stop_work_in_the_runners_words():
    pool = ChildProcesses()
    try:
        cancel = threading.Event()
        threading.Timer(0.5, cancel.set).start()
        started = time.monotonic()
        with pytest.raises(WorkCancelledError) as cancelled:
            pool.call(time.sleep, (60,), cancel=cancel, deadline=started + 30)
        assert type(cancelled.value) is WorkCancelledError and time.monotonic() - started < 5
        assert (str(cancelled.value), cancelled.value.code, cancelled.value.item) == ('work cancelled', 'PREEMPTED',
                                                                                      'cancelled')
        with pytest.raises(WorkTimeoutError) as late:
            pool.call(time.sleep, (60,), deadline=time.monotonic() + 0.2)
        assert (str(late.value), late.value.code, late.value.item) == ('work timeout', 'TIMEOUT', 'timeout')
        assert pool.call(operator.add, (2, 3)) == 5  # a fresh child replaced the killed ones
    finally:
        pool.close()
    with pytest.raises(WorkCancelledError):  # a closed pool takes no more work
        pool.call(operator.add, (1, 1))


def test_a_close_while_a_child_is_readied_for_work_leaves_no_child(monkeypatch):
    """close() (a server's shutdown) may come while a call readies its child outside the pool's
    lock: the call is cancelled and the child killed, not left running work nobody stops."""
    pool = ChildProcesses()
    pool.prepare(1)
    readied = []

    def settle_during_close(child, timeout=0.0):
        readied.append(child)
        pool.close()
        return True
    monkeypatch.setattr(ChildProcess, 'settle', settle_during_close)
    with pytest.raises(WorkCancelledError):
        pool.call(time.sleep, (60,))
    [child] = readied
    child.process.wait(timeout=10)  # killed: no runaway work outlives the pool


def test_a_child_that_dies_is_named_as_its_caller_calls_it():
    child = ChildProcess(name='simulation process')
    try:
        with pytest.raises(ChildDiedError) as died:
            child.call(os._exit, (3,), deadline=time.monotonic() + 30)
    finally:
        child.kill()
    assert str(died.value) == 'the simulation process ended (exit code 3) without an answer'
    assert died.value.item == 'simulation process'


def echo_commands(count: int, progress, commands):
    """In the child: report that it runs, then each command the caller sends, until ``count`` have come."""
    received = []
    progress({'n': -1})
    while len(received) < count:
        for value in commands(5.0):
            received.append(value)
            progress(value)
    return received


def test_commands_reach_the_running_work_and_late_ones_are_dropped(monkeypatch):
    # The child imports this module to find echo_commands.
    monkeypatch.setenv('PYTHONPATH', os.pathsep.join([str(Path(__file__).parent), os.environ.get('PYTHONPATH', '')]))
    child = ChildProcess()
    try:
        seen = []

        def progress(value):  # answer each report with the next command, from another thread
            seen.append(value)
            threading.Thread(target=child.command, args=({'n': value['n'] + 1},)).start()

        assert child.command({'n': -5})  # before the work: dropped
        assert child.call(echo_commands, (3,), on_progress=progress, wants_commands=True,
                          deadline=time.monotonic() + 30) == [{'n': 0}, {'n': 1}, {'n': 2}]
        assert seen == [{'n': -1}, {'n': 0}, {'n': 1}, {'n': 2}]
        time.sleep(0.2)  # the command sent after the third report arrives after the work ended
        assert child.call(operator.add, (2, 3), deadline=time.monotonic() + 30) == 5
        assert child.call(operator.add, (1, 1), deadline=time.monotonic() + 30) == 2
    finally:
        child.kill()
    assert child.command({'n': 9}) is False  # the child is gone


def test_specifications_reach_the_child_whole_with_their_shared_subformulas():
    """Requests pickle formula nodes as class and fields (runner._dumps): every kind of node
    comes back equal, and a subformula shared by two formulas is still one object."""
    import pickle

    from respec.ltl import FALSE, conj, disj, iff, implies, neg, next_
    from respec.child_processes.runner import _dumps
    shared = iff(var('x'), next_(var('y')))
    spec = GR1Specification(env_props=['x'], sys_props=['y'], env_trans=[implies(shared, disj([var('x'), FALSE]))],
                            sys_trans=[conj([shared, neg(var('y'))]), shared])
    loaded = pickle.loads(_dumps(spec))
    assert loaded == spec
    assert loaded.sys_trans[1] is loaded.sys_trans[0].args[0] is loaded.env_trans[0].left


def test_a_growing_tree_is_stopped_before_it_passes_the_sum_limit(monkeypatch):
    """The tree is read every ``period``: a child growing 100 MB per reading toward a 350 MB
    limit is ended at the reading of 300 MB (the next would be 400), not after passing it; a
    first reading after a pause does not count the pause's growth."""
    from types import SimpleNamespace

    from respec.child_processes import runner

    class Child:  # what the sum limit reads of a ChildProcess
        process = SimpleNamespace(pid=7)

    readings = {'child': 0}
    monkeypatch.setattr(runner, 'resident_memory', lambda pid=None: readings['child'] if pid == 7 else 0)
    monkeypatch.setattr(runner, '_child_pids', lambda: [7])
    clock = {'now': 100.0}
    monkeypatch.setattr(runner.time, 'monotonic', lambda: clock['now'])
    memory = runner.WorkingChildrenMemory(limit=350, period=0.1)
    child = Child()
    memory.working(child, True)
    verdicts = []
    for size in (100, 200, 300):
        clock['now'] += 0.125
        readings['child'] = size
        verdicts.append(memory.is_over(child))
    assert verdicts == [False, False, True] and memory.growth == 100
    clock['now'] += 60  # a minute later, 340 MB: under the limit, and no growth is known
    readings['child'] = 340
    assert not memory.is_over(child) and memory.growth == 0
