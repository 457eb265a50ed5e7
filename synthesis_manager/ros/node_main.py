"""Run nodes until SIGINT/SIGTERM: the body of every node's console script and of ``serve``."""

from __future__ import annotations

import sys
from pathlib import Path

from synthesis_manager.ros.env import init_ros


def run_nodes(*node_factories, argv: list[str] | None = None, ready_message: str = '') -> int:
    """Create each node in one process, spin them on a SuiteExecutor, shut down cleanly."""
    from rclpy.executors import ExternalShutdownException

    from synthesis_manager.ros.executor import SuiteExecutor

    # rclpy's own signal handlers (installed by init) turn SIGINT and SIGTERM into a
    # context shutdown, which ends the spin loop below.
    context = init_ros(args=argv)
    executor = SuiteExecutor(num_threads=16, context=context)
    nodes = []
    try:
        for factory in node_factories:
            node = factory(context=context)
            nodes.append(node)
            executor.add_node(node)
        if ready_message:
            print(ready_message, flush=True)
        # spin_once with a timeout, not spin(): a signal arriving while the executor builds
        # its first wait set can be missed, and then spin() would wait forever.
        while context.ok():
            try:
                executor.spin_once(timeout_sec=0.25)
            except Exception:
                if context.ok():
                    raise
                # the context was shut down by a signal in the middle of this spin: done
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        stop_executor(executor, nodes)
        for node in reversed(nodes):
            node.destroy_node()
        context.try_shutdown()
    return 0


def stop_executor(executor, nodes, timeout: float = 1.0):
    """End running callbacks, then shut the executor down; the nodes can be destroyed after.

    Nodes with long-running callbacks offer ``stop_work()``. We wait for the callbacks
    ourselves because Executor.shutdown() in rclpy (Jazzy) returns without waiting, and a
    callback finishing after its node is destroyed fails to send its response. The wait is
    short: async callbacks suspended on a future cannot resume once the context is shut down
    (nothing spins any more), and a stopped synthesis ends within a second anyway; the
    entry points must exit within 3 s of SIGINT/SIGTERM.
    """
    for node in nodes:
        if hasattr(node, 'stop_work'):
            node.stop_work()
    work_tracker = getattr(executor, '_work_tracker', None)
    if work_tracker is not None:
        work_tracker.wait(timeout)
    executor.shutdown(timeout_sec=timeout)


def node_main(node_factory, name: str):
    """Console-script body for a single node."""
    own_arguments = sys.argv[1:sys.argv.index('--ros-args')] if '--ros-args' in sys.argv else sys.argv[1:]
    if {'-h', '--help'} & set(own_arguments):  # say what it is, do not start it
        print(f'usage: {Path(sys.argv[0]).name} [--ros-args -p NAME:=VALUE ...]\n\n'
              f'Runs the ROS 2 node {name} until Ctrl-C (SIGINT) or SIGTERM, on $ROS_DOMAIN_ID, DDS on '
              'loopback.\nIts parameters and their defaults: "Running the nodes" in docs/nodes.md.')
        sys.exit(0)
    sys.exit(run_nodes(node_factory, argv=sys.argv, ready_message=f'{name} ready'))
