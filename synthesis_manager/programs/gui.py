"""``behavior-synthesis gui``: the synthesis web GUI on http://127.0.0.1:PORT/.

By default the four suite nodes run in this process on a private ROS domain, next to the
GUI's action client; ``--connect`` instead joins a suite already running on the
environment's ROS_DOMAIN_ID (e.g. ``behavior-synthesis serve``). The page and its API are
``synthesis_manager.web``; this module only wires them to ROS and runs uvicorn.
"""

from __future__ import annotations

import contextlib
import os
import signal
import socket
import sys
import threading
import time

import uvicorn
from rclpy.node import Node

from respec.vocabulary.errors import ErrorCode, ExitStatus, exit_status_help
from synthesis_manager.client import SynthesisClient, SynthesisOutcome, make_goal
from synthesis_manager.http_connections import BoundedH11Protocol, install_repeat_filter, raise_descriptor_limit
from synthesis_manager.ros.harness import RosHarness, environment_domain_id
from synthesis_manager.ros.namespaces import namespace_placement
from synthesis_manager.ros.robot_systems import SuiteSystems
from synthesis_manager.programs.send_goal import add_robot_namespace_argument
from synthesis_manager.suite import add_suite_arguments, suite_node_factories
from synthesis_manager.web.backend import SynthesisBackend
from synthesis_manager.web.outcome import JobOutcome
from synthesis_manager.web.routes import create_app

DEFAULT_PORT = 8080
LOOPBACK_HOSTS = ('127.0.0.1', 'localhost', '::1')


def add_arguments(parser):
    parser.epilog = exit_status_help(ExitStatus.OK, ExitStatus.USAGE, ExitStatus.UNAVAILABLE)
    parser.add_argument('--port', type=int, default=DEFAULT_PORT,
                        help=f'TCP port of the page (default {DEFAULT_PORT}; 0 picks a free one)')
    parser.add_argument('--host', default='127.0.0.1',
                        help='address to listen on (default 127.0.0.1: this machine only)')
    parser.add_argument('--connect', action='store_true',
                        help='use the suite already running on $ROS_DOMAIN_ID instead of starting one')
    add_robot_namespace_argument(parser)  # with --connect: the robot whose suite the page uses
    parser.add_argument('--goal-timeout', type=float, default=600.0,
                        help='seconds to wait for the result of one goal')
    add_suite_arguments(parser)


class RosGoalRunner:
    """``run_goal`` for SynthesisBackend: sends each job to ``/behavior_synthesis`` and hands the
    action's SynthesisOutcome to the (ROS-free) web layer as a JobOutcome."""

    def __init__(self, client, server_timeout: float = 5.0, goal_timeout: float = 600.0):
        self.client = client
        self.server_timeout = server_timeout
        self.goal_timeout = goal_timeout

    def __call__(self, request, feedback, cancel) -> JobOutcome:
        if not self.client.wait_for_server(timeout=self.server_timeout):
            outcome = SynthesisOutcome(
                ErrorCode.SERVICE_UNAVAILABLE.number, ErrorCode.SERVICE_UNAVAILABLE,
                f'no {self.client.node.resolve_service_name(self.client.action_name)} action server answered within '
                f'{self.server_timeout:g} s (start one with `behavior-synthesis serve`)')
        else:
            goal = make_goal(request.system, request.initial_conditions, request.goals, request.sm_outcomes,
                             option=request.option, name=request.name, unordered=request.unordered,
                             ltl_specification=request.custom_ltl)
            outcome = self.client.run(goal, feedback=feedback, cancel=cancel, timeout=self.goal_timeout)
        return JobOutcome.from_result(outcome.to_dict(), outcome.machine)


@contextlib.contextmanager
def ros_backend(args=None, connect: bool = False):
    """A SynthesisBackend sending jobs over ROS: to an in-process suite, or (connect) a running one."""
    with RosHarness(domain_id=environment_domain_id() if connect else None) as ros:
        if not connect:
            for factory in suite_node_factories(args):
                ros.add_node(factory)
        # In the robot's namespace, the node's relative names (behavior_synthesis, robot_systems)
        # reach that robot's suite.
        client_node = ros.add_node(Node, 'behavior_synthesis_gui',
                                   **namespace_placement(getattr(args, 'namespace', '') if connect else ''))
        client = SynthesisClient(client_node)
        robot = '' if client_node.get_namespace() == '/' else f' of {client_node.get_namespace()}'
        where = (f'the suite{robot} on ROS_DOMAIN_ID {ros.domain_id}' if connect
                 else f'an in-process suite (private ROS domain {ros.domain_id})')
        # Attached to a running suite, the page shows and checks the suite's systems (served on
        # robot_systems), never config files of this machine.
        yield SynthesisBackend(
            RosGoalRunner(client, goal_timeout=getattr(args, 'goal_timeout', 600.0)),
            config_dir=getattr(args, 'config_dir', '') or None,
            systems=SuiteSystems(client_node) if connect else None, description=f'synthesizing with {where}')


def listening_socket(host: str, port: int) -> socket.socket:
    """A socket bound to ``host:port`` and listening (port 0: the OS picks a free port)."""
    family = socket.AF_INET6 if ':' in host else socket.AF_INET
    sock = socket.socket(family, socket.SOCK_STREAM)
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    sock.bind((host, port))
    sock.listen(64)
    return sock


class GuiServer(uvicorn.Server):
    """uvicorn's server, stopping promptly on SIGINT/SIGTERM and then returning normally.

    ``on_stop`` runs first: the backend cancels its jobs and ends the event streams, which
    uvicorn's graceful shutdown would otherwise wait for. uvicorn raises the signals it
    caught again once it has stopped, and a second SIGTERM would kill the process before
    its ROS side is shut down; here the signal has done its job and is not raised again,
    and ``stopped_by`` keeps it for the exit status (128 + its number).
    """

    def __init__(self, config: uvicorn.Config, on_stop=None):
        super().__init__(config)
        self.on_stop = on_stop
        self.stopped_by: int | None = None

    def handle_exit(self, sig, frame):
        if self.stopped_by is None:
            self.stopped_by = int(sig)
        if self.on_stop is not None:
            self.on_stop()
        super().handle_exit(sig, frame)

    @contextlib.contextmanager
    def capture_signals(self):
        if threading.current_thread() is not threading.main_thread():  # signals reach the main thread only
            yield
            return
        previous = {sig: signal.signal(sig, self.handle_exit) for sig in (signal.SIGINT, signal.SIGTERM)}
        try:
            yield
        finally:
            for sig, handler in previous.items():
                signal.signal(sig, handler)


def make_server(app, sock: socket.socket, on_stop=None) -> GuiServer:
    """A server for ``app`` on an already bound socket (call ``.run(sockets=[sock])``).

    Requests still running a second after the server is told to stop are cut short; connections
    are bounded (``http_connections``).
    """
    host, port = sock.getsockname()[:2]
    raise_descriptor_limit()
    install_repeat_filter()
    return GuiServer(uvicorn.Config(app, host=host, port=port, log_level='warning', http=BoundedH11Protocol,
                                    timeout_graceful_shutdown=1, ws='none'), on_stop=on_stop)


@contextlib.contextmanager
def background_server(app, host: str = '127.0.0.1', port: int = 0, startup_timeout: float = 10.0):
    """Serve ``app`` from a thread (tests, screenshots); yields the page's URL."""
    sock = listening_socket(host, port)
    server = make_server(app, sock)
    thread = threading.Thread(target=server.run, kwargs={'sockets': [sock]}, name='gui-http', daemon=True)
    thread.start()
    try:
        deadline = time.monotonic() + startup_timeout
        while not server.started:
            if not thread.is_alive() or time.monotonic() > deadline:
                raise RuntimeError('the GUI web server did not start')
            time.sleep(0.02)
        yield f'http://{host}:{sock.getsockname()[1]}/'
    finally:
        server.should_exit = True
        thread.join(timeout=10.0)
        sock.close()


def run(args) -> int:
    os.environ.setdefault('MUJOCO_GL', 'egl')  # the simulation renders frames off-screen
    if args.host not in LOOPBACK_HOSTS:
        print(f'gui: warning: listening on {args.host}: other machines can reach the page and '
              'start synthesis jobs', file=sys.stderr)
    try:
        sock = listening_socket(args.host, args.port)
    except OSError as error:
        print(f'gui: cannot listen on {args.host}:{args.port}: {error.strerror}', file=sys.stderr)
        return ExitStatus.UNAVAILABLE
    with sock:
        try:
            with ros_backend(args, connect=args.connect) as backend:
                server = make_server(create_app(backend), sock, on_stop=backend.stop)
                host, port = sock.getsockname()[:2]
                shown = f'[{host}]' if ':' in host else host
                print(f'behavior synthesis GUI: http://{shown}:{port}/ ({backend.description}); '
                      'Ctrl-C to stop', flush=True)
                server.run(sockets=[sock])
                if server.stopped_by is not None:
                    return 128 + server.stopped_by
        except KeyboardInterrupt:  # a signal before the server ran: cli.main exits with 128 + it
            pass
    return ExitStatus.OK
