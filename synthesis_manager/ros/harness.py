"""A launch-free harness for running ROS 2 nodes in-process (tests, benchmarks, demo, clients).

``RosHarness`` owns a private rclpy context on a reserved ROS_DOMAIN_ID and the entry points'
executor (ros/executor.py) spinning in a background thread, so several test runs on one
machine never talk to each other and nothing is left running afterwards::

    with RosHarness() as ros:
        server = ros.add_node(MyServer)        # node classes take a ``context`` keyword
        client = ros.add_node(MyClient)
        ...
"""

from __future__ import annotations

import contextlib
import os
import threading
from typing import TYPE_CHECKING

from synthesis_manager.ros.env import prepare_ros_environment
from synthesis_manager.ros.node_main import stop_executor

if TYPE_CHECKING:  # rclpy loads when the harness starts
    from rclpy import Context
    from rclpy.node import Node

    from synthesis_manager.ros.executor import SuiteExecutor


class RosHarness:
    """Context manager: reserved domain, own rclpy context, executor thread, clean teardown."""

    def __init__(self, num_threads: int = 8, domain_id: int | None = None, default_context: bool = False):
        """``domain_id=None`` reserves a free domain; give one to join an existing system.

        ``default_context``: use rclpy's global context (code such as flexbe_core checks
        ``rclpy.ok()`` without a context); it is shut down and renewed on exit.
        """
        self._num_threads = num_threads
        self.domain_id = domain_id
        self._default_context = default_context
        self._stack = contextlib.ExitStack()
        self.nodes: list[Node] = []
        self.context: Context | None = None
        self.executor: SuiteExecutor | None = None
        self._thread: threading.Thread | None = None
        self._closing = threading.Event()

    def __enter__(self) -> 'RosHarness':
        if self.domain_id is None:
            self.domain_id = self._stack.enter_context(reserve_domain_id())
        # Processes started while the harness runs join its domain; afterwards the domain may be
        # another process's reservation, so later ones must not inherit it.
        self._stack.callback(_restore_environment_variable, 'ROS_DOMAIN_ID', os.environ.get('ROS_DOMAIN_ID'))
        prepare_ros_environment(self.domain_id)
        import rclpy
        from rclpy.signals import SignalHandlerOptions

        from synthesis_manager.ros.executor import SuiteExecutor

        self.context = rclpy.utilities.get_default_context() if self._default_context else rclpy.Context()
        # No rclpy signal handlers: Ctrl-C stays a KeyboardInterrupt for the code using the
        # harness (a client cancels its goal, then leaves the block).
        rclpy.init(context=self.context, domain_id=self.domain_id,
                   signal_handler_options=SignalHandlerOptions.NO)
        self.executor = SuiteExecutor(num_threads=self._num_threads, context=self.context)
        self._thread = threading.Thread(target=self._spin, name='ros-harness-executor', daemon=True)
        self._thread.start()
        return self

    def _spin(self):
        from rclpy.exceptions import InvalidHandle
        from rclpy.executors import ExternalShutdownException

        while True:
            try:
                self.executor.spin()
                return
            except ExternalShutdownException:
                return
            except InvalidHandle:
                # An entity destroyed from another thread (e.g. flexbe_core's proxies shut down
                # at the end of a behavior) while the executor gathered its wait set: the next
                # turn leaves it out.
                if self._closing.is_set():
                    return
            except Exception:
                if not self._closing.is_set():
                    raise
                return  # the teardown shut the context down between two waits


    def add_node(self, node_factory, *args, **kwargs):
        """Create a node in this harness's context and spin it; returns the node."""
        node = node_factory(*args, context=self.context, **kwargs)
        self.nodes.append(node)
        self.executor.add_node(node)
        return node

    def __exit__(self, *exc_info):
        self._closing.set()
        try:
            stop_executor(self.executor, self.nodes)
            self._thread.join(timeout=1.0)  # the spin ends with the executor, before the context
            for node in reversed(self.nodes):
                node.destroy_node()
            if self._default_context:  # renews the global context for the next user
                import rclpy

                rclpy.try_shutdown()
            else:
                self.context.try_shutdown()
            self._thread.join(timeout=5.0)
            retrieve_teardown_exceptions(self.executor)
        finally:
            self._stack.close()
        return False


def _restore_environment_variable(name: str, value: str | None) -> None:
    if value is None:
        os.environ.pop(name, None)
    else:
        os.environ[name] = value


def retrieve_teardown_exceptions(executor) -> None:
    """Take the exceptions of callbacks that failed as the executor stopped (typically "cannot use
    Destroyable", or a flexbe_core proxy already torn down). rclpy fetches a callback's exception
    on its next spin; with no next spin it prints 'The following exception was never retrieved'
    when the callback is garbage collected, long after and with no context."""
    for handler in list(getattr(executor, '_futures', ())):  # rclpy keeps no public list
        if handler.done():
            handler.exception()


def wait_for(future, timeout: float = 10.0):
    """Block the calling (non-executor) thread until an rclpy future is done; return its result."""
    done = threading.Event()
    future.add_done_callback(lambda _: done.set())
    if not done.wait(timeout):
        raise TimeoutError(f'no result within {timeout} s')
    return future.result()


def environment_domain_id() -> int:
    """The ROS_DOMAIN_ID of this process's environment (0 when unset), as clients use."""
    return int(os.environ.get('ROS_DOMAIN_ID') or 0)


class _RotatingDomainSelector:
    """Domain ids 1..100, continuing where the last reservation of this process stopped.

    domain_coordinator's default selector starts at 1 every time, so consecutive harnesses
    in one process would reuse one domain and could meet entities the previous one left in
    discovery; rotating (from a per-process offset) keeps consecutive users apart.
    """

    def __init__(self):
        self._next = os.getpid() % 100

    def __call__(self) -> int:
        self._next = self._next % 100 + 1
        return self._next


_domain_selector = _RotatingDomainSelector()


def reserve_domain_id():
    """Context manager reserving a ROS_DOMAIN_ID no other process on this machine uses."""
    from domain_coordinator import domain_id

    return domain_id(selector=_domain_selector)
