"""The ``/behavior_synthesis`` and ``/flexbe_synthesis`` action servers: compilation ->
synthesis -> state machine generation.

Both actions (the original BehaviorSynthesis and CNU's FlexBESynthesis, which FlexBE WebUI
revisions send) are read into one SynthesisTask and run the same pipeline with the same cancel;
synthesis_manager.ros.cnu_interface chooses FlexBESynthesis' type (CNU's own when importable).
Each stage is an asynchronous call to its service node, awaited by the goal's coroutine
(synthesis_manager.ros.stage_calls): a waiting goal holds no executor thread, so any number
of goals run side by side and the executor keeps serving. Cancel requests, the stage's time
limit, shutdown and the stage's node going away end the wait; a cancel is forwarded to the
synthesizer. Beyond ``max_active_goals`` goals at once, new goals are answered BUSY at once;
beyond twice that many accepted and unfinished (a flood), new goals are rejected on arrival.
A goal's ``timeout`` counts its whole pipeline from acceptance (synthesis_manager.limits).
"""

from __future__ import annotations

import contextlib
import threading
import time
from dataclasses import dataclass, field, replace
from typing import Callable

from rclpy.action import CancelResponse, GoalResponse
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.node import Node
from rclpy.time import Time

from ltl_specification.errors import InvalidInitialConditionsError
from ltl_synthesizer.interrupt import released_memory
from ltl_specification.repair import REPAIRABLE
from ltl_specification.initial_conditions import (detected_status, initial_conditions_from_robot_state,
                                                  reads_robot_state)
from respec.errors import INTERNAL_ERROR, CodedError, ErrorCode
from sm_generation.instantiation import count_states
from synthesis_manager.client_shares import ClientShares, goal_origin
from synthesis_manager.limits import (MAX_STRING_BYTES, BusyError, GoalDeadline,
                                      GoalTimeoutError, capped_timeout, check_message, check_timeout, utf8_length)
from synthesis_manager.requests import (InvalidRequestError, SynthesisTask, task_from_behavior_synthesis,
                                        task_from_flexbe_synthesis)
from synthesis_manager.ros.action_server import BurstActionServer
from synthesis_manager.ros.cnu_interface import load_flexbe_synthesis_interface
from synthesis_manager.ros.conversions import error_code, error_name, is_empty_spec
from synthesis_manager.ros.errors import log_internal_error
from synthesis_manager.ros.logs import QuickLogger
from synthesis_manager.ros.node_main import node_main
from synthesis_manager.ros.qos import action_server_qos, service_qos
from synthesis_manager.ros.robot_state import RobotStateListener
from synthesis_manager.ros.settings import declare_settings
from synthesis_manager.ros.stage_calls import (WATCH_PERIOD, Preempted, ServerStoppingError, StageCaller,
                                              StageFailedError, StageTimeoutError, next_executor_turn)
from synthesis_manager.settings import BEHAVIOR_SYNTHESIS_SERVER
from synthesis_msgs.action import BehaviorSynthesis
from synthesis_msgs.msg import FSAutomaton, LTLSpecification
from synthesis_msgs.srv import (CancelSynthesis, GenerateFlexBESM, GenerateLTLSpecification, ProposeRepairs,
                                SynthesizeAutomaton)


# Seconds past synthesis_timeout the synthesis node has to answer (a goal's own limit gets none).
SYNTHESIS_ANSWER_GRACE = 1.0
# Fixes a refused goal's result suggests, and how long their search may take: its budget (the
# problem's diagnosis included), plus a child interpreter's start and its answer.
MAX_SUGGESTED_FIXES = 3
REPAIR_DEADLINE_FACTOR = 1.0
REPAIR_STARTUP_GRACE = 3.0


@dataclass
class PipelineOutcome:
    """What a goal produced, whichever action it came through."""

    code: ErrorCode = ErrorCode.SUCCESS
    message: str = ''
    ltl_specification: LTLSpecification = field(default_factory=LTLSpecification)
    automaton: FSAutomaton = field(default_factory=FSAutomaton)
    states: list = field(default_factory=list)
    notes: list = field(default_factory=list)  # what the result should tell, e.g. detected initial conditions
    fixes: list = field(default_factory=list)  # verified fixes of a refused task, one sentence each

    def message_with_fixes(self) -> str:
        """The message, followed by the suggested fixes when there are any."""
        if not self.fixes:
            return self.message
        return (f'{self.message}\n\nVerified fixes (each compiled and synthesized, and found realizable; '
                '`behavior-synthesis repair` with the same task lists more):\n'
                + '\n'.join(f'  {line}' for line in self.fixes))

    @property
    def succeeded(self) -> bool:
        return self.code == ErrorCode.SUCCESS

    def fail(self, code: ErrorCode, message: str):
        self.code, self.message = code, message


@dataclass(frozen=True)
class ActionInterface:
    """An action type served by this node: how its goals and results map to the pipeline's."""

    action_type: type
    action_name: str
    read_goal: Callable        # (goal, default_system) -> SynthesisTask
    make_result: Callable      # (PipelineOutcome) -> action_type.Result


def behavior_synthesis_result(outcome: PipelineOutcome):
    return BehaviorSynthesis.Result(
        error_code=error_code(outcome.code, outcome.message_with_fixes()), states=outcome.states,
        ltl_specification=outcome.ltl_specification, automaton=outcome.automaton)


def action_interfaces(flexbe_synthesis) -> tuple[ActionInterface, ...]:
    """The served actions; ``flexbe_synthesis``: the FlexBESynthesisInterface offered."""
    def flexbe_synthesis_result(outcome: PipelineOutcome):
        return flexbe_synthesis.result(outcome.code, outcome.message, outcome.states, outcome.notes, outcome.fixes)
    return (ActionInterface(BehaviorSynthesis, 'behavior_synthesis', task_from_behavior_synthesis,
                            behavior_synthesis_result),
            ActionInterface(flexbe_synthesis.action_type, 'flexbe_synthesis', task_from_flexbe_synthesis,
                            flexbe_synthesis_result))


class FeedbackChannel:
    """Publishes a goal's feedback and remembers the progress reached."""

    def __init__(self, goal_handle, feedback_type):
        self.goal_handle, self.feedback_type, self.progress = goal_handle, feedback_type, 0.0

    def __call__(self, status: str, progress: float | None = None):
        if progress is not None:
            self.progress = float(progress)
        self.goal_handle.publish_feedback(self.feedback_type(status=status, progress=self.progress))


def forget_goal_request(goal_handle) -> None:
    """Empty a finished goal's request: rclpy keeps its handle, the request included, until the
    result is gone (result_retention), so a refused 50 MB goal would hold its 50 MB that long."""
    request = goal_handle.request
    empty = type(request)()
    for name in request.get_fields_and_field_types():
        setattr(request, name, getattr(empty, name))


class HeapTrim:
    """Give freed heap pages back to the system after goals (what a big goal's strings left):
    PERIOD seconds after the last goal ended (a trim takes 1-9 ms; a burst gets one, after it).
    A node timer, idle between goals, not a thread: one started while the process shuts down
    would never run, and its starter would wait for it forever."""

    PERIOD = 1.0

    def __init__(self, node: Node):
        self.timer = node.create_timer(self.PERIOD, self._trim)
        self.timer.cancel()

    def __call__(self) -> None:
        self.timer.reset()

    def _trim(self) -> None:
        self.timer.cancel()
        released_memory(collect=False)


def flexbe_log_publisher(node: Node, topic: str) -> Callable[[str], None]:
    """A function logging an error on FlexBE's operator log (flexbe_msgs/BehaviorLog).

    FlexBE is not on the package registries, so this only logs where flexbe_msgs is installed
    (always so for FlexBE users); elsewhere, or with an empty topic, it does nothing.
    """
    try:
        from flexbe_msgs.msg import BehaviorLog
    except ImportError:
        BehaviorLog = None
    if BehaviorLog is None or not topic:
        return lambda text: None
    publisher = node.create_publisher(BehaviorLog, topic, 10)
    return lambda text: publisher.publish(BehaviorLog(text=text, status_code=BehaviorLog.ERROR))


class BehaviorSynthesisServer(Node):
    """Action servers ``behavior_synthesis`` (synthesis_msgs/action/BehaviorSynthesis) and
    ``flexbe_synthesis`` (CNU's flexbe_synthesis_msgs/action/FlexBESynthesis when importable, else
    our look-alike synthesis_msgs/action/FlexBESynthesis; the log says why, once).

    Settings (ROS parameters): ``synthesis_manager.settings.BEHAVIOR_SYNTHESIS_SERVER``.
    """

    def __init__(self, **kwargs):
        super().__init__('behavior_synthesis_server', **kwargs)
        self.settings = declare_settings(self, BEHAVIOR_SYNTHESIS_SERVER)
        self._stopping = threading.Event()
        self._active_goals = 0
        self._accepted_goals = 0  # accepted and not finished: running, or waiting for the executor
        self.heap_trim = HeapTrim(self)
        self.shares = ClientShares(self.settings.max_client_goals, self.settings.max_client_goal_seconds,
                                   self.settings.max_client_waiting)
        self._lock = threading.Lock()
        self.stages = StageCaller(self)
        self.log = QuickLogger(self.get_logger())  # a line per failed goal
        self.log_to_flexbe = flexbe_log_publisher(self, self.settings.flexbe_log_topic)
        group = ReentrantCallbackGroup()

        def client(service_type, name):
            return self.create_client(service_type, name, callback_group=group, qos_profile=service_qos())
        self.compiler = client(GenerateLTLSpecification, 'ltl_compilation')
        self.synthesizer = client(SynthesizeAutomaton, 'ltl_synthesis')
        self.synthesis_cancel = client(CancelSynthesis, 'ltl_synthesis/cancel')
        self.compiler_cancel = client(CancelSynthesis, 'ltl_compilation/cancel')
        self.generator_cancel = client(CancelSynthesis, 'sm_generate/cancel')
        self.generator = client(GenerateFlexBESM, 'sm_generate')
        self.repairer = client(ProposeRepairs, 'propose_repairs')
        self.robot_state = RobotStateListener(self, self.settings.robot_state_topic, callback_group=group)
        flexbe_synthesis = load_flexbe_synthesis_interface()
        # Before `make flexbe` CNU's package is missing in every ordinary run: said at debug
        # here, and once plainly when a client uses /flexbe_synthesis (where it matters).
        self._fallback_note = flexbe_synthesis.fallback_reason
        if self._fallback_note:
            self.get_logger().debug(self._fallback_note)
        # rclpy keeps each result for result_timeout seconds (default 900: ~38 KB per goal).
        self.action_servers = [
            BurstActionServer(self, interface.action_type, interface.action_name,
                         self._executor_for(interface),
                         goal_callback=self.admit_goal,
                         cancel_callback=lambda _: CancelResponse.ACCEPT, callback_group=group,
                         result_timeout=max(1, round(self.settings.result_retention)),
                         **action_server_qos())
            for interface in action_interfaces(flexbe_synthesis)]

    def _executor_for(self, interface):
        """The execute callback of ``interface``'s action server (a coroutine function)."""
        async def execute(goal_handle):
            try:
                return await self.execute(goal_handle, interface)
            finally:
                self.goal_finished()
                forget_goal_request(goal_handle)
                self.heap_trim()
        return execute

    def stop_work(self):
        """Make goals that are waiting on a stage give up (at shutdown)."""
        self._stopping.set()
        self.stages.stop()

    def destroy_node(self):
        for action_server in self.action_servers:
            action_server.destroy()
        super().destroy_node()

    # --- goal execution -----------------------------------------------------------------

    async def execute(self, goal_handle, interface: ActionInterface):
        if self._fallback_note and interface.action_name == 'flexbe_synthesis':
            self.get_logger().info(self._fallback_note)
            self._fallback_note = ''
        feedback = FeedbackChannel(goal_handle, interface.action_type.Feedback)
        outcome = PipelineOutcome()
        task = deadline = None
        try:
            check_message(goal_handle.request, 'goal')
            task = interface.read_goal(goal_handle.request, self.settings.default_system)
            requested = check_timeout(task.timeout)
            task = replace(task, timeout=capped_timeout(requested, self.settings.max_goal_timeout))
            deadline = GoalDeadline(task.timeout, started=self.accepted_at(goal_handle), requested=requested)
            if deadline.capped():
                feedback(deadline.capped())
            async with self.client_share(goal_handle, feedback, deadline):
                with self.admitted():
                    await self.run_pipeline(goal_handle, task, outcome, feedback, deadline)
        except Preempted:
            outcome.fail(ErrorCode.PREEMPTED, 'cancelled by the client')
            goal_handle.canceled()
            return interface.make_result(outcome)
        except CodedError as error:
            outcome.fail(error.code, str(error))
        except Exception as error:  # a bug: logged with its traceback; the server keeps serving
            log_internal_error(self.get_logger(), 'behavior synthesis failed', error)
            outcome.fail(INTERNAL_ERROR, f'internal error: {error!r}')
        if not outcome.succeeded and task is not None:
            await self.suggest_fixes(goal_handle, task, outcome, feedback, deadline)
        if outcome.succeeded:
            goal_handle.succeed()
        else:
            # Clients that drop the result of an aborted goal still see why: the last feedback
            # says it, and FlexBE WebUI 4.0.3 (which also drops feedback) shows FlexBE's log.
            failure = f'{outcome.code}: {outcome.message}'
            feedback(failure)
            self.log_to_flexbe(f'Behavior synthesis failed: {failure}')
            self.log.warning(failure)
            goal_handle.abort()
        return interface.make_result(outcome)

    async def suggest_fixes(self, goal_handle, task: SynthesisTask, outcome: PipelineOutcome, feedback,
                            deadline: GoalDeadline | None):
        """For a task refused as impossible: the best verified fixes (``ltl_specification.repair``,
        searched by the compilation node within ``repair_time_budget``): after the message in
        BehaviorSynthesis' ``error_code.message``, one per line after the failure in CNU's
        FlexBESynthesis ``messages[]``.
        Without an answer in time the refusal stands as it is."""
        budget = self.settings.repair_time_budget
        if budget <= 0 or str(outcome.code) not in REPAIRABLE or task.option == 'ltl_synthesis_only' \
                or goal_handle.is_cancel_requested or (deadline is not None and deadline.passed()):
            return
        feedback('Looking for changes that make the task possible')
        try:
            found = await self.call(goal_handle, self.repairer, ProposeRepairs.Request(
                system=task.system, goals=task.goals, initial_conditions=task.initial_conditions,
                sm_outcomes=task.sm_outcomes, custom_ltl=task.custom_ltl or LTLSpecification(),
                unordered_goals=task.unordered_goals, time_budget=float(budget), max_proposals=MAX_SUGGESTED_FIXES),
                'repair search', budget * REPAIR_DEADLINE_FACTOR + REPAIR_STARTUP_GRACE, deadline=deadline)
        except (CodedError, Preempted) as error:  # the refusal is the answer; the fixes were a help
            self.log.info(f'no fixes suggested: {error}'[:300])
            return
        if error_name(found.error_code.value) != ErrorCode.SUCCESS or not found.summaries:
            return
        outcome.fixes = [f'Suggested fix {number}: {summary}' for number, summary in enumerate(found.summaries, 1)]

    def admit_goal(self, _goal_request) -> GoalResponse:
        """Accept a goal unless a flood is under way: beyond max_active_goals accepted goals
        the next ones are answered BUSY (a result), beyond twice that they are rejected at
        once (one response, no result for a client to lose; send-goal reports it as BUSY)."""
        with self._lock:
            if self._accepted_goals >= 2 * self.settings.max_active_goals:
                return GoalResponse.REJECT
            self._accepted_goals += 1
        return GoalResponse.ACCEPT

    def goal_finished(self):
        with self._lock:
            self._accepted_goals -= 1

    @contextlib.asynccontextmanager
    async def client_share(self, goal_handle, feedback, deadline: GoalDeadline):
        """Run a goal within its client's share (ClientShares): until it fits, it waits, told
        its place; its time limit (or, without one, its stages' limits) counts against the
        client's max_client_goal_seconds."""
        seconds = deadline.limit or sum(getattr(self.settings, f'{stage}_timeout')
                                        for stage in ('compilation', 'synthesis', 'generation'))
        ticket = self.shares.join(goal_origin(goal_handle.goal_id.uuid), seconds)
        try:
            told = 0
            while place := self.shares.admit(ticket):
                if goal_handle.is_cancel_requested:
                    raise Preempted()
                if self._stopping.is_set():
                    raise ServerStoppingError('the server is shutting down')
                if deadline.passed():
                    raise deadline.timed_out("waiting for its client's running goals to finish")
                if place != told:
                    told = place
                    feedback(f'Waiting: {self.shares.running(ticket.origin)} goals of this client are running '
                             f'(max_client_goals {self.shares.max_running}, max_client_goal_seconds '
                             f'{self.shares.max_seconds:g}); this goal is number {place} of its waiting goals')
                await next_executor_turn(look_every=WATCH_PERIOD)
            yield
        finally:
            self.shares.leave(ticket)

    @contextlib.contextmanager
    def admitted(self):
        """Count a goal in while it runs; raise BusyError when max_active_goals are running."""
        limit = self.settings.max_active_goals
        with self._lock:
            if self._active_goals >= limit:
                raise BusyError(f'the server is busy: {self._active_goals} goals in progress '
                           f'(max_active_goals {limit}); try again later')
            self._active_goals += 1
        try:
            yield
        finally:
            with self._lock:
                self._active_goals -= 1

    def accepted_at(self, goal_handle) -> float:
        """When the goal was accepted (time.monotonic()): its time limit counts from then."""
        # rclpy stamps GoalInfo with the server's clock on acceptance; ServerGoalHandle exposes
        # only its goal_id, so the stamp is read from the GoalInfo it keeps.
        stamp = getattr(goal_handle, '_goal_info', None)
        if stamp is None:
            return time.monotonic()
        waited = (self.get_clock().now() - Time.from_msg(stamp.stamp)).nanoseconds / 1e9
        return time.monotonic() - max(0.0, waited)

    async def run_pipeline(self, goal_handle, task: SynthesisTask, outcome: PipelineOutcome, feedback,
                           deadline: GoalDeadline | None = None):
        deadline = deadline or GoalDeadline(task.timeout)
        goal_id = bytes(goal_handle.goal_id.uuid).hex()
        spec_name = task.byproduct_stem or f'{task.system or "behavior"}_{goal_id[:8]}'

        provenance = ''  # what the specification was compiled from: the synthesizer diagnoses with it
        if task.option == 'ltl_synthesis_only':
            if task.custom_ltl is None or is_empty_spec(task.custom_ltl):
                raise InvalidRequestError('ltl_synthesis_only needs the complete LTL specification '
                                     'in request.ltl_specification')
            outcome.ltl_specification = task.custom_ltl
        else:
            task = await self.with_initial_conditions(goal_handle, task, outcome, feedback, deadline)
            feedback('Compiling the LTL specification', 0.05)
            # The node gets what is left of the goal's time, so that it stops a large compilation
            # when the goal ends (its own limit otherwise; 30 s).
            limit = deadline.stage_limit(self.settings.compilation_timeout, 'LTL compilation')
            compiled = await self.call(goal_handle, self.compiler, GenerateLTLSpecification.Request(
                system=task.system, goals=task.goals, initial_conditions=task.initial_conditions,
                sm_outcomes=task.sm_outcomes, custom_ltl=task.custom_ltl or LTLSpecification(),
                unordered_goals=task.unordered_goals, timeout=float(limit), request_id=goal_id),
                'LTL compilation', limit,
                on_cancel=lambda: self.cancel_request(self.compiler_cancel, goal_id, goal_handle),
                deadline=deadline)
            self.check(compiled.error_code)
            outcome.ltl_specification = compiled.ltl_specification
            provenance = compiled.provenance
            if utf8_length(provenance) > MAX_STRING_BYTES:  # the synthesizer would refuse the request
                self.get_logger().warning(f'the provenance of {spec_name} ({utf8_length(provenance)} bytes) is '
                                          'not sent: an unrealizable specification is diagnosed by its formulas only')
                provenance = ''
            feedback('Compiled the LTL specification', 1 / 3)
            if task.option == 'ltl_compilation_only':
                return

        feedback('Synthesizing an automaton', 0.4)
        try:
            # The synthesizer gets what is left of the goal's time and answers SYNTHESIS_TIMEOUT
            # then; but its clock starts on receipt, later: the goal's limit ends the wait itself.
            timeout = deadline.stage_limit(task.timeout, 'LTL synthesis') if task.timeout else \
                self.settings.synthesis_timeout
            synthesized = await self.call(goal_handle, self.synthesizer, SynthesizeAutomaton.Request(
                ltl_specification=outcome.ltl_specification, spec_name=spec_name,
                timeout=float(timeout), request_id=goal_id, provenance=provenance,
                diagnosis_timeout=float(self.settings.diagnosis_timeout)),
                'LTL synthesis', timeout + SYNTHESIS_ANSWER_GRACE,
                on_cancel=lambda: self.cancel_request(self.synthesis_cancel, goal_id),
                deadline=deadline)
        except GoalTimeoutError as passed:  # the synthesis stage's code, whoever saw the limit pass
            raise StageFailedError(error_code(ErrorCode.SYNTHESIS_TIMEOUT, str(passed))) from None
        if task.timeout and error_name(synthesized.error_code.value) == ErrorCode.SYNTHESIS_TIMEOUT:
            # Name the goal's limit, not the time that was left of it.
            synthesized.error_code.message = str(deadline.timed_out('LTL synthesis'))
        self.check(synthesized.error_code)
        if synthesized.error_code.message:  # a warning the automaton comes with (not well-separated)
            outcome.message = synthesized.error_code.message
            outcome.notes.append(synthesized.error_code.message)
        outcome.automaton = synthesized.automaton
        feedback(f'Synthesized an automaton with {len(outcome.automaton.automaton)} states', 2 / 3)
        if task.option in ('ltl_synthesis_only', 'ltl_steps_only'):
            return

        feedback('Generating the state machine', 0.7)
        limit = deadline.stage_limit(self.settings.generation_timeout, 'state machine generation')
        generated = await self.call(goal_handle, self.generator, GenerateFlexBESM.Request(
            automaton=outcome.automaton, system=task.system,
            initial_conditions=task.initial_conditions, timeout=float(limit), request_id=goal_id),
            'state machine generation', limit,
            on_cancel=lambda: self.cancel_request(self.generator_cancel, goal_id, goal_handle),
            deadline=deadline)
        self.check(generated.error_code)
        outcome.states = list(generated.state_definition)
        feedback(f'Generated a state machine with {count_states(outcome.states)} states', 1.0)

    async def with_initial_conditions(self, goal_handle, task: SynthesisTask, outcome: PipelineOutcome,
                                      feedback, deadline: GoalDeadline) -> SynthesisTask:
        """``task``, with the robot's initial conditions when it names none or ``current``."""
        if not reads_robot_state(task.initial_conditions, task.system, self.settings.config_dir or None):
            return task
        topic = self.robot_state.topic
        timeout = deadline.stage_limit(self.settings.robot_state_timeout, 'reading the robot state')
        feedback(f'Reading the initial conditions from {topic}', 0.02)
        with self.stages.looks.waiting():
            state = await self.robot_state.next_state_async(
                timeout, should_stop=lambda: goal_handle.is_cancel_requested or self._stopping.is_set())
        if goal_handle.is_cancel_requested:
            raise Preempted()
        if self._stopping.is_set():
            raise ServerStoppingError('reading the robot state: the server is shutting down', topic)
        if state is None:
            raise InvalidInitialConditionsError(
                f'no initial conditions given and no robot state on {topic!r} within {timeout:g} s: '
                'name the initial conditions, or start the robot (e.g. atlas-sim-node)', item=topic)
        names = initial_conditions_from_robot_state(state.mode, state.completed_actions, source=topic)
        outcome.notes.append(detected_status(names, topic))
        feedback(outcome.notes[-1], 0.04)
        return replace(task, initial_conditions=names)

    @staticmethod
    def check(code):
        if code.value != code.SUCCESS:
            raise StageFailedError(code)

    async def call(self, goal_handle, client, request, stage: str, timeout: float, on_cancel=None,
                   deadline: GoalDeadline | None = None):
        """Call a stage's service; wait watching for cancel, the stage's and the goal's time
        limit, shutdown and the node."""
        limit = deadline.stage_limit(timeout, stage) if deadline is not None else timeout
        try:
            return await self.stages.call(client, request, stage, limit, self.settings.service_timeout,
                                          cancelled=lambda: goal_handle.is_cancel_requested, on_cancel=on_cancel)
        except StageTimeoutError:
            if deadline is not None and deadline.passed():
                raise deadline.timed_out(stage) from None
            raise

    def cancel_request(self, cancel_client, goal_id: str, goal_handle=None):
        """Tell a stage to stop its work for this goal (fire and forget; ``cancel_client`` calls
        the stage's ``<service>/cancel``). With ``goal_handle``, only for a cancelled goal or at
        shutdown: when the goal's time runs out, that stage's own limit (what was left of it)
        ends the work at the same moment, and a burst of timeouts needs no extra calls."""
        if goal_handle is not None and not (goal_handle.is_cancel_requested or self._stopping.is_set()):
            return
        if cancel_client.service_is_ready():
            cancel_client.call_async(CancelSynthesis.Request(request_id=goal_id))


def main():
    node_main(BehaviorSynthesisServer, 'behavior_synthesis_server')
