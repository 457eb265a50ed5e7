"""Waiting coroutines are resumed only when their turn is due; per-request log lines keep
what rclpy's logger would write (ros/executor.py, ros/stage_calls.py, ros/logs.py)."""

import sys
import threading
import time

import pytest
from rcl_interfaces.msg import Log
from rclpy.logging import LoggingSeverity
from rclpy.node import Node

from synthesis_manager.ros.logs import QuickLogger
from synthesis_manager.ros.stage_calls import ExecutorTurn, LookTimer, awaited_turn, next_executor_turn
from waiting import wait_until

pytestmark = pytest.mark.ros


def test_the_turn_a_coroutine_waits_on_is_found_through_nested_awaits():
    turn = next_executor_turn(lambda: False, look_every=60.0)

    async def inner():
        await turn

    async def outer():
        await inner()

    coroutine = outer()
    coroutine.send(None)
    assert awaited_turn(coroutine) is turn and not turn.due()
    coroutine.close()
    assert awaited_turn(None) is None


def test_a_turn_is_due_when_ready_or_when_its_look_is_due():
    ready = threading.Event()
    turn = next_executor_turn(ready.is_set, look_every=60.0)
    assert not turn.due()
    ready.set()
    assert turn.due()
    soon = next_executor_turn(look_every=0.05)
    assert not soon.due()
    time.sleep(0.06)
    assert soon.due() and next_executor_turn().due() and ExecutorTurn().due()


def test_the_suite_executor_resumes_a_waiting_coroutine_only_when_its_turn_is_due(ros):
    node = ros.add_node(Node, 'turn_test')
    node.create_timer(0.01, lambda: None)  # wakes the executor 100 times a second
    ready, resumptions = threading.Event(), []

    async def waiting():
        while not ready.is_set():
            resumptions.append(time.monotonic())
            await next_executor_turn(ready.is_set, look_every=0.5)
        return 'done'

    task = ros.executor.create_task(waiting)
    time.sleep(1.2)  # the behaviour under test: how often it is resumed over 1.2 s of executor wake-ups
    # Started once, then looked again every 0.5 s: 3, not the ~100 wake-ups of the executor.
    assert 2 <= len(resumptions) <= 4, resumptions
    ready.set()
    deadline = time.monotonic() + 2.0
    while not task.done() and time.monotonic() < deadline:
        time.sleep(0.01)
    assert task.done() and task.result() == 'done'


def test_a_look_timer_wakes_the_executor_only_while_a_coroutine_waits(ros):
    node = ros.add_node(Node, 'look_timer_test')  # nothing else wakes this executor
    looks = LookTimer(node, 0.05)
    assert not looks.active
    taken, release = [], threading.Event()

    async def waiting():
        with looks.waiting():
            while not release.is_set():
                taken.append(time.monotonic())
                await next_executor_turn(look_every=0.05)

    task = ros.executor.create_task(waiting)
    wait_until(lambda: looks.active and len(taken) >= 8, 1.0, 'eight looks of the timer (every 0.05 s)')
    release.set()
    deadline = time.monotonic() + 2.0
    while not task.done() and time.monotonic() < deadline:
        time.sleep(0.01)
    time.sleep(0.2)  # its next tick turns it off
    assert task.done() and not looks.active


def test_quick_log_lines_reach_rosout_as_rclpy_would_write_them(ros):
    listener = ros.add_node(Node, 'rosout_listener')
    lines, heard = [], threading.Event()

    def on_log(line):
        if line.name == 'quick_logging':
            lines.append(line)
            heard.set()
    listener.create_subscription(Log, '/rosout', on_log, 100)
    node = ros.add_node(Node, 'quick_logging')
    log = QuickLogger(node.get_logger())
    wait_until(lambda: node.count_subscribers('/rosout') > 0, 10, "the listener's /rosout subscription discovered")
    node.get_logger().set_level(LoggingSeverity.WARN)
    log.info('not written: below the level')
    expected_line = sys._getframe().f_lineno + 1
    log.warning('a goal failed: TIMEOUT')
    assert heard.wait(5.0)
    time.sleep(0.2)
    assert [(line.msg, line.level) for line in lines] == [('a goal failed: TIMEOUT', Log.WARN)]
    assert lines[0].function == 'test_quick_log_lines_reach_rosout_as_rclpy_would_write_them'
    assert lines[0].file == __file__ and lines[0].line == expected_line


def test_log_lines_are_bounded():
    """Issue 48, item 3: one log line was 522 MB. A line keeps its start and says what it left out."""
    from synthesis_manager.ros.logs import MAX_LOG_LINE_CHARS, bounded_line

    assert bounded_line('short') == 'short'
    line = bounded_line('x' * 10 * MAX_LOG_LINE_CHARS)
    assert line.startswith('x' * MAX_LOG_LINE_CHARS) and len(line) < MAX_LOG_LINE_CHARS + 60
    assert line.endswith(f'({9 * MAX_LOG_LINE_CHARS} more characters not logged)')
