"""A synthesized behavior on the real FlexBE engine against the simulator node (ROS shell).

``run_on_flexbe`` exports the machine as a behavior package (sm_generation.flexbe_behavior),
loads its module as flexbe_onboard loads a behavior and runs it the same way: ``set_up``
(autonomy Full unless told otherwise: no operator confirms transitions),
``prepare_for_execution``, ``confirm``, ``execute``. The behavior's states drive the
``atlas_sim`` node over ROS 2 (atlas_sim_flexbe_states: one ExecuteCapability action per
capability); :class:`SimulatedOperator` answers InputState's ``flexbe/behavior_input``
requests by running the operator-input capability the request stands for on the simulator.

The trace for the specification check comes from
:class:`atlas_sim.executive.engine_trace.EngineTraceRecorder`: the top-level states of the running
machine are observed by wrapping their ``execute`` (the engine itself is not changed), the
robot's reports come from the simulator's events.

flexbe_core checks ``rclpy.ok()`` on rclpy's global context, so the engine's nodes live
there, on the same ROS domain as the simulator node.
"""

from __future__ import annotations

import contextlib
import importlib.util
import os
import sys
import tempfile
import threading
import time
import zlib
from pathlib import Path

from atlas_sim.executive.engine_trace import EngineTraceRecorder
from atlas_sim.executive.executor import ExecutionLimitError
from atlas_sim.simulator.node_names import CAPABILITY_ACTION_PREFIX
from atlas_sim.simulator.operator_data import answers_by_request_type, flexbe_input_data
from respec.robot import RobotSystem
from sm_generation.config import flexbe_config, input_request_capabilities
from sm_generation.flexbe_behavior import behavior_package
from sm_generation.state_machine import StateMachine

FULL_AUTONOMY = 3
BEHAVIOR_INPUT_ACTION = 'flexbe/behavior_input'
PREEMPTED = 'preempted'


class SimulatedOperator:
    """The operator behind ``flexbe/behavior_input`` (what FlexBE's UI serves for InputState)."""

    def __init__(self, node, request_capabilities: dict[int, str], answers: dict[int, object]):
        from flexbe_msgs.action import BehaviorInput
        from rclpy.action import ActionServer
        from rclpy.callback_groups import ReentrantCallbackGroup

        from synthesis_manager.ros.action_client import RaceFreeActionClient
        from synthesis_msgs.action import ExecuteCapability

        self._types = (BehaviorInput, ExecuteCapability)
        group = ReentrantCallbackGroup()
        self.request_capabilities = dict(request_capabilities)
        self.answers = dict(answers)
        # rclpy's own ActionClient can lose a goal's response (rclpy#1123).
        self.clients = {capability: RaceFreeActionClient(node, ExecuteCapability,
                                                         CAPABILITY_ACTION_PREFIX + capability, callback_group=group)
                        for capability in set(self.request_capabilities.values())}
        self.server = ActionServer(node, BehaviorInput, BEHAVIOR_INPUT_ACTION, self.answer, callback_group=group)

    async def answer(self, goal_handle):
        """Run the request's operator-input capability; awaited, so no executor thread waits."""
        behavior_input, execute_capability = self._types
        result = behavior_input.Result(result_code=behavior_input.Result.RESULT_ABORTED)
        request_type = goal_handle.request.request_type
        capability = self.request_capabilities.get(request_type)
        if capability is None or request_type not in self.answers:
            result.data = f'the simulated operator has no answer for request type {request_type}'
            goal_handle.abort()
            return result
        client = self.clients[capability]
        reason = f'no simulator answers {capability}'
        if client.server_is_ready() or client.wait_for_server(timeout_sec=5.0):  # waits once, at discovery
            handle = await client.send_goal_async(execute_capability.Goal(capability=capability))
            if handle.accepted:
                done = (await handle.get_result_async()).result
                if done.outcome == 'completed':
                    result.result_code = behavior_input.Result.RESULT_OK
                    result.data = flexbe_input_data(self.answers[request_type])
                reason = done.reason
            else:
                reason = 'the simulator rejected the request'
        if result.result_code != behavior_input.Result.RESULT_OK:
            result.data = reason
        goal_handle.succeed()
        return result


def load_behavior_class(package, directory: Path):
    """Write the package under ``directory`` and load its behavior class (as flexbe_onboard does)."""
    source = package.write(directory) / package.package / f'{package.module}.py'
    module_name = f'{package.package}_{package.module}_{id(package):x}'  # fresh per run, like onboard's tmp_<id>
    spec = importlib.util.spec_from_file_location(module_name, source)
    assert spec is not None and spec.loader is not None  # a .py file's
    module = importlib.util.module_from_spec(spec)
    sys.modules[module_name] = module
    spec.loader.exec_module(module)
    checksum = zlib.adler32(source.read_bytes()) & 0x7fffffff  # flexbe_onboard's behavior id
    return getattr(module, package.class_name), checksum


def observe_top_level_states(machine, recorder: EngineTraceRecorder) -> None:
    """Report the top-level states' starts and outcomes to ``recorder``.

    The engine calls ``execute`` of the current state once per tick; a state starts with its
    first call after an outcome (or ever) and ends with the call returning an outcome. An
    outcome the operator forced (FlexBE's ``flexbe/command/transition``) is the one flexbe_core's
    ManuallyTransitionableState notes as requested in that call.
    """
    for state in machine._states:  # noqa: SLF001 - flexbe_core keeps no public list
        original = state.execute
        running = {'now': False}

        def observed(*args, _state=state, _original=original, _running=running, **kwargs):
            if not _running['now']:
                _running['now'] = True
                recorder.entered(_state.name)
            outcome = _original(*args, **kwargs)
            if outcome is not None and outcome != PREEMPTED:
                _running['now'] = False
                forced = getattr(_state, '_manual_transition_requested', None) == outcome
                recorder.returned(_state.name, outcome, forced=forced)
            return outcome
        state.execute = observed


def reset_flexbe_proxies(executor=None, node=None) -> None:
    """flexbe_core keeps its proxies in class attributes; forget them so the next run starts clean.

    With ``executor`` and ``node`` (the behavior's), the node is taken off the executor first,
    so that no proxy callback starts while the proxies are shut down.
    """
    if executor is not None and node is not None:
        executor.remove_node(node)
        _wait_for_proxy_tasks(executor)
    from flexbe_core.proxy import (ProxyActionClient, ProxyPublisher, ProxyServiceCaller,
                                   ProxySubscriberCached, shutdown_proxies)

    shutdown_proxies()
    for proxy in (ProxyActionClient, ProxyPublisher, ProxyServiceCaller, ProxySubscriberCached):
        for name in ('_clients', '_topics', '_services'):
            registry = getattr(proxy, name, None)
            if isinstance(registry, dict):
                registry.clear()


def _wait_for_proxy_tasks(executor, timeout: float = 2.0) -> None:
    """Let the work flexbe_core's proxies handed to ``executor`` run before they are cleared.

    flexbe_core gives some of it to the executor as tasks of no node (a subscriber's callback
    registered right after it subscribes), so taking the node off does not stop them; run after
    the clearing, one found its topic gone and its TypeError ended the executor's thread (1 CI
    run of 6)."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline and any(
            not task.done() and 'flexbe_core' in (getattr(getattr(task, '_handler', None), '__module__', '') or '')
            for task, _, _ in list(getattr(executor, '_tasks', ()))):
        time.sleep(0.01)


def run_on_flexbe(machine: StateMachine, simulator, simulator_lock, domain_id: int, system: RobotSystem,
                  behavior_name: str = 'Synthesized Behavior', autonomy: int = FULL_AUTONOMY,
                  max_wall_time: float = 600.0, verbose: bool = False):
    """Run ``machine`` on FlexBE; returns an ExecutionResult.

    ``system`` is the RobotSystem ``machine`` was generated for. The simulator node must be
    running on ``domain_id`` around ``simulator``. Raises
    ExecutionLimitError (with the partial trace) if no outcome came within ``max_wall_time``.
    flexbe_core's INFO log lines and progress notes (about a hundred per run) are shown on
    stderr only when ``verbose``; its warnings and errors always are.
    """
    from rclpy.logging import LoggingSeverity
    from rclpy.node import Node

    from synthesis_manager.ros.harness import RosHarness

    config = flexbe_config(system)
    package = behavior_package(machine, config, behavior_name, date=time.strftime('%a %b %d %Y'))
    recorder = EngineTraceRecorder(machine, simulator, system, simulator_lock)
    notes = sys.stderr if verbose else open(os.devnull, 'w')  # noqa: SIM115 - closed below
    try:  # flexbe_core prints progress notes: keep them off stdout, which is the command's output
        with contextlib.redirect_stdout(notes), tempfile.TemporaryDirectory(prefix='flexbe_behavior_') as directory, \
                RosHarness(domain_id=domain_id, default_context=True) as ros:
            behavior_class, checksum = load_behavior_class(package, Path(directory))
            requests = input_request_capabilities(config)
            SimulatedOperator(ros.add_node(Node, 'simulated_operator'), requests,
                              answers_by_request_type(simulator.settings, requests))
            node = ros.add_node(Node, 'flexbe_onboard')
            if not verbose:
                node.get_logger().set_level(LoggingSeverity.WARN)
            try:
                outcome = _execute(behavior_class(node), checksum, autonomy, recorder, max_wall_time)
            finally:
                reset_flexbe_proxies(ros.executor, node)
    finally:
        recorder.close()
        if notes is not sys.stderr:
            notes.close()
    result = recorder.result()
    if outcome == PREEMPTED or result.outcome is None:
        raise ExecutionLimitError(f'no SM outcome within {max_wall_time:g} s on the FlexBE engine '
                                  f'(engine returned {outcome!r})', item=behavior_name, trace=result.trace)
    return result


def _execute(behavior, checksum: int, autonomy: int, recorder: EngineTraceRecorder, max_wall_time: float):
    """flexbe_onboard's sequence: set_up, prepare_for_execution, confirm, execute."""
    behavior.set_up(beh_id=checksum, autonomy_level=autonomy, debug=False)
    behavior.prepare_for_execution({})
    observe_top_level_states(behavior._state_machine, recorder)  # noqa: SLF001
    behavior.confirm()
    watchdog = threading.Timer(max_wall_time, behavior.preempt)
    watchdog.daemon = True
    watchdog.start()
    try:
        return behavior.execute()
    finally:
        watchdog.cancel()
