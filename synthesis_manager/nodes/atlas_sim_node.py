"""ROS 2 node ``atlas_sim``: the simulated ATLAS behind an action server and a state topic.

* action server ``atlas_sim/execute`` (synthesis_msgs/action/ExecuteCapability): the goal
  names one capability (control mode or action) and may carry the requesting state's
  userdata (e.g. the operator's ``template_id``), which the simulator checks as the robot
  would (atlas_sim.simulator.operator_data); the result is ``completed``/``failed``,
  the simulator's reason and the sim time it ended. Goals may overlap, as concurrency
  containers need: goals arriving within ``batch_window`` wall seconds of each other start
  in the same sim instant (``AtlasSimulator.start_concurrently``). Requests cannot be
  cancelled (the simulator has no way to), so cancel requests are rejected.
* one such action server per capability, ``atlas_sim/capabilities/<capability>`` (the goal's
  ``capability`` may be empty): FlexBE's proxy action client keeps one goal per action
  name, so states running at once (a concurrency container) each need their own. A goal
  for a capability whose request is still running joins that request (activating a running
  capability again keeps it running, the activation–outcome semantics). Per sensor,
  ``atlas_sim/capabilities/<sensor>`` completes once the sensor reads true.
* topic ``atlas_sim/state`` (synthesis_msgs/msg/RobotState) at ``state_rate`` Hz.
* physics runs in the node's own thread at ``speed`` sim seconds per wall second
  (0: as fast as possible; the default 10 is faster than real time), also between
  requests, as a real robot keeps balancing.

Settings (ROS parameters): ``synthesis_manager.settings.ATLAS_SIM`` (the robot system, its
initial conditions and faults, the seed, the speed and the state topic's rate). List parameters
take a string array or a comma-separated string. Run it with ``atlas-sim-node`` (DDS stays on
loopback) or in-process: ``AtlasSimNode(context=...)`` like the suite's nodes.
"""

from __future__ import annotations

import functools
import threading
import time

from rclpy.action import ActionServer, CancelResponse, GoalResponse
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.node import Node

from atlas_sim.simulator.atlas_simulator import Request
from atlas_sim.simulator.factory import make_simulator, parse_faults
from atlas_sim.simulator.node_names import ACTION_NAME, CAPABILITY_ACTION_PREFIX, NODE_NAME, STATE_TOPIC
from atlas_sim.simulator.operator_data import decode_userdata
from respec.vocabulary.errors import quoted
from respec.vocabulary.naming import parse_names
from respec.robot import robot_system
from synthesis_manager.ros.errors import log_internal_error
from synthesis_manager.ros.node_main import node_main
from synthesis_manager.ros.settings import declare_settings
from synthesis_manager.settings import ATLAS_SIM
from synthesis_msgs.action import ExecuteCapability
from synthesis_msgs.msg import RobotState



def robot_state_message(snapshot: dict) -> RobotState:
    return RobotState(stamp=float(snapshot['time']), mode=snapshot['mode'],
                      pending_mode=snapshot['pending_mode'] or '',
                      completed_actions=list(snapshot['completed_actions']), running=list(snapshot['running']),
                      head_tilt=float(snapshot['head_tilt']),
                      base_xy=[float(v) for v in snapshot['base_xy']],
                      pelvis_height=float(snapshot['pelvis_height']),
                      holding_object=bool(snapshot['holding_object']), fallen=bool(snapshot['fallen']))


class _Job:
    """A goal waiting for its request to be started and finished by the physics thread."""

    def __init__(self, capability: str, sensor: bool = False, data: dict | None = None):
        self.capability = capability
        self.sensor = sensor      # wait until the sensor reads true (no request)
        self.data = data          # the requesting state's userdata (None: it sent none)
        self.request: Request | None = None
        self.finished = threading.Event()

    @property
    def started(self) -> Request:
        """The simulator's request of a capability's job (every running one has it)."""
        assert self.request is not None, self.capability
        return self.request

    @property
    def done(self) -> bool:
        return self.request is not None and self.request.result is not None


class AtlasSimNode(Node):
    """See the module docstring. ``simulator`` replaces the one built from the parameters."""

    def __init__(self, simulator=None, **kwargs):
        super().__init__(NODE_NAME, **kwargs)
        self.settings = settings = declare_settings(self, ATLAS_SIM)
        if simulator is None:
            seed = int(settings.seed)
            simulator = make_simulator(
                robot_system(settings.system, settings.config_dir or None), parse_names(settings.initial_conditions),
                faults=parse_faults(parse_names(settings.fail), parse_names(settings.fail_first)),
                seed=None if seed < 0 else seed)
        self.simulator = simulator
        self.speed = float(settings.speed)
        self.batch_window = float(settings.batch_window)
        self.lock = threading.Lock()  # guards the simulator and the job lists (render under it too)
        self._pending: list[_Job] = []
        self._last_arrival = 0.0
        self._running: list[_Job] = []
        self._stop = threading.Event()
        group = ReentrantCallbackGroup()
        self.state_publisher = self.create_publisher(RobotState, STATE_TOPIC, 10)
        self.state_timer = self.create_timer(1.0 / float(settings.state_rate), self.publish_state,
                                             callback_group=group)
        self.action_server = ActionServer(
            self, ExecuteCapability, ACTION_NAME, self.execute,
            goal_callback=self.accept_goal, cancel_callback=lambda _: CancelResponse.REJECT,
            callback_group=group)
        abstraction = self.simulator.abstraction
        self.capability_servers = [
            ActionServer(self, ExecuteCapability, CAPABILITY_ACTION_PREFIX + name,
                         functools.partial(self.execute, name=name, sensor=name in abstraction.sensors),
                         goal_callback=functools.partial(self.accept_named_goal, name),
                         cancel_callback=lambda _: CancelResponse.REJECT, callback_group=group)
            for name in (*abstraction.capabilities, *abstraction.sensors)]
        self._physics = threading.Thread(target=self._physics_loop, name='atlas-sim-physics', daemon=True)
        self._physics.start()

    def destroy_node(self):
        self.destroy_timer(self.state_timer)  # no more publishing while the node goes away
        self._stop.set()
        self._physics.join(timeout=5.0)
        for job in self._pending + self._running:
            job.finished.set()
        self.action_server.destroy()
        for server in self.capability_servers:
            server.destroy()
        super().destroy_node()

    # --- ROS side ------------------------------------------------------------------------------

    def accept_goal(self, goal_request) -> GoalResponse:
        known = self.simulator.abstraction.is_capability(goal_request.capability)
        if not known:
            self.get_logger().warning(f'rejecting unknown capability {quoted(goal_request.capability)}')
        return GoalResponse.ACCEPT if known else GoalResponse.REJECT

    def accept_named_goal(self, name: str, goal_request) -> GoalResponse:
        """A per-capability server: the goal may repeat its capability's name or leave it empty."""
        if goal_request.capability not in ('', name):
            self.get_logger().warning(f'rejecting {quoted(goal_request.capability)} sent to the {name!r} server')
            return GoalResponse.REJECT
        return GoalResponse.ACCEPT

    def execute(self, goal_handle, name: str | None = None, sensor: bool = False):
        goal = goal_handle.request
        job = _Job(name or goal.capability, sensor, decode_userdata(goal.userdata_keys, goal.userdata_values))
        with self.lock:
            self._pending.append(job)
            self._last_arrival = time.monotonic()
        goal_handle.publish_feedback(ExecuteCapability.Feedback(status=f'{job.capability} requested'))
        while not job.finished.wait(0.05):
            if self._stop.is_set():
                break
        result = ExecuteCapability.Result()
        if job.sensor and job.finished.is_set() and not self._stop.is_set():
            goal_handle.succeed()
            result.outcome, result.reason = 'completed', f'{job.capability} reads true'
            result.stamp = float(self.simulator.time)
            return result
        if not job.done:
            goal_handle.abort()
            result.outcome, result.reason = 'failed', 'simulator shut down'
            return result
        goal_handle.succeed()
        done = job.started.result
        assert done is not None  # job.done
        result.outcome, result.reason, result.stamp = done.outcome, done.reason, float(done.finished_at)
        return result

    def publish_state(self):
        with self.lock:
            snapshot = self.simulator.snapshot()
        self.state_publisher.publish(robot_state_message(snapshot))

    # --- physics thread --------------------------------------------------------------------------

    def _physics_loop(self):
        try:
            self._run_physics()
        except Exception as error:  # noqa: BLE001 - a dead physics thread must not leave goals waiting forever
            log_internal_error(self.get_logger(), 'physics stopped', error)
            self._stop.set()
            with self.lock:
                for job in self._pending + self._running:
                    job.finished.set()

    def _run_physics(self):
        anchor = None  # (wall, sim) pair for pacing
        while not self._stop.is_set():
            with self.lock:
                started = self._start_pending()
                self.simulator.step()
                self._finish_jobs()
                now = self.simulator.time
            if started or anchor is None:
                anchor = (time.monotonic(), now)
            if self.speed > 0:  # pace: sim time runs at speed x wall time
                delay = anchor[0] + (now - anchor[1]) / self.speed - time.monotonic()
                if delay > 0:
                    time.sleep(delay)
            else:
                time.sleep(0)  # let the executor threads in

    def _start_pending(self) -> bool:
        """Start the goals that arrived together (none arrived for ``batch_window``)."""
        if not self._pending:
            return False
        while time.monotonic() - self._last_arrival < self.batch_window:
            self.lock.release()   # let late goals of the same batch arrive; sim time stands still
            time.sleep(self.batch_window / 4)
            self.lock.acquire()
        jobs, self._pending = self._pending, []
        waiting_for_sensors = [job for job in jobs if job.sensor]
        joining = [job for job in jobs if not job.sensor and job.capability in self._running_requests()]
        for job in joining:  # activated again while running: the running request answers both
            job.request = self._running_requests()[job.capability]
        jobs = [job for job in jobs if job not in waiting_for_sensors and job not in joining]
        self._running.extend(waiting_for_sensors + joining)
        names = [job.capability for job in jobs]
        duplicates = {n for n in names if names.count(n) > 1}
        unique = [job for job in jobs if job.capability not in duplicates]
        requests = self.simulator.start_concurrently([job.capability for job in unique],
                                                     {job.capability: job.data for job in unique})
        for job, request in zip(unique, requests):
            job.request = request
        for job in jobs:  # the same capability twice at once: one runs, the others are refused
            if job.capability in duplicates:
                job.request = self.simulator.start(job.capability, job.data)
        self._running.extend(jobs)
        self._finish_jobs()
        return True

    def _running_requests(self) -> dict:
        """Capability -> its running request."""
        return {job.capability: job.request for job in self._running
                if not job.sensor and job.started.result is None}

    def _finish_jobs(self):
        for job in [j for j in self._running if self._job_finished(j)]:
            self._running.remove(job)
            job.finished.set()

    def _job_finished(self, job: _Job) -> bool:
        if job.sensor:
            return bool(self.simulator.sensors.get(job.capability))
        return job.started.result is not None


def main():
    node_main(AtlasSimNode, NODE_NAME)


if __name__ == '__main__':
    main()
