"""A goal's pipeline: compilation -> synthesis -> state machine generation, each stage an
asynchronous call to its service node, awaited by the goal's coroutine
(synthesis_manager.ros.stage_calls): a waiting goal holds no executor thread. Cancel requests,
the stage's time limit, shutdown and the stage's node going away end the wait; a cancel is
forwarded to the stage. A task naming no initial conditions (or ``current``) reads them from
the robot's state first; a task refused as impossible gets verified fixes suggested.
"""

from __future__ import annotations

import threading
from dataclasses import replace

from ltl_specification.errors import InvalidInitialConditionsError
from ltl_specification.initial_conditions import (asks_for_robot_state, detected_status,
                                                  initial_conditions_from_robot_state, reads_robot_state)
from respec.vocabulary.errors import CodedError, ErrorCode
from respec.robot import RobotSystem, robot_system
from synthesis_manager.goals import (MAX_SUGGESTED_FIXES, SYNTHESIS_ANSWER_GRACE, PipelineOutcome, byproduct_name,
                                     repair_wait, wants_fixes)
from synthesis_manager.limits import MAX_STRING_BYTES, GoalDeadline, GoalTimeoutError, utf8_length
from synthesis_manager.requests import InvalidRequestError, SynthesisTask
from synthesis_manager.ros.conversions import error_code, error_name, is_empty_spec
from synthesis_manager.ros.qos import service_qos
from synthesis_manager.ros.robot_state import RobotStateListener
from synthesis_manager.summary import generated_summary
from synthesis_manager.ros.stage_calls import (Preempted, ServerStoppingError, StageCaller, StageFailedError,
                                              StageTimeoutError)
from synthesis_msgs.msg import LTLSpecification
from synthesis_msgs.srv import (CancelSynthesis, GenerateFlexBESM, GenerateLTLSpecification, ProposeRepairs,
                                SynthesizeAutomaton)


def check(code):
    """Raise StageFailedError unless a stage's error ``code`` is SUCCESS."""
    if code.value != code.SUCCESS:
        raise StageFailedError(code)


class GoalPipeline:
    """The stages of ``node``'s goals (its settings, QuickLogger ``log`` and ``stopping`` event:
    set at shutdown, when waiting goals give up), called through its service clients."""

    def __init__(self, node, log, stopping: threading.Event, group):
        self.node, self.settings, self.log, self.stopping = node, node.settings, log, stopping
        self.stages = StageCaller(node)

        def client(service_type, name):
            return node.create_client(service_type, name, callback_group=group, qos_profile=service_qos())
        self.compiler = client(GenerateLTLSpecification, 'ltl_compilation')
        self.synthesizer = client(SynthesizeAutomaton, 'ltl_synthesis')
        self.synthesis_cancel = client(CancelSynthesis, 'ltl_synthesis/cancel')
        self.compiler_cancel = client(CancelSynthesis, 'ltl_compilation/cancel')
        self.generator_cancel = client(CancelSynthesis, 'sm_generate/cancel')
        self.generator = client(GenerateFlexBESM, 'sm_generate')
        self.repairer = client(ProposeRepairs, 'propose_repairs')
        self.robot_state = RobotStateListener(node, self.settings.robot_state_topic, callback_group=group)

    def stop(self):
        """Make goals that are waiting on a stage give up (at shutdown)."""
        self.stopping.set()
        self.stages.stop()

    async def suggest_fixes(self, goal_handle, task: SynthesisTask, outcome: PipelineOutcome, feedback,
                            deadline: GoalDeadline | None):
        """For a task refused as impossible: the best verified fixes (``ltl_specification.repair``,
        searched by the compilation node within ``repair_time_budget``): after the message in
        BehaviorSynthesis' ``error_code.message``, one per line after the failure in CNU's
        FlexBESynthesis ``messages[]``.
        Without an answer in time the refusal stands as it is."""
        budget = self.settings.repair_time_budget
        if not wants_fixes(budget, outcome, task) or goal_handle.is_cancel_requested \
                or (deadline is not None and deadline.passed()):
            return
        feedback('Looking for changes that make the task possible')
        try:
            found = await self.call(goal_handle, self.repairer, ProposeRepairs.Request(
                system=task.system, goals=task.goals, initial_conditions=task.initial_conditions,
                sm_outcomes=task.sm_outcomes, custom_ltl=task.custom_ltl or LTLSpecification(),
                unordered_goals=task.unordered_goals, time_budget=float(budget), max_proposals=MAX_SUGGESTED_FIXES),
                'repair search', repair_wait(budget), deadline=deadline)
        except (CodedError, Preempted) as error:  # the refusal is the answer; the fixes were a help
            self.log.info(f'no fixes suggested: {error}'[:300])
            return
        if error_name(found.error_code.value) != ErrorCode.SUCCESS or not found.summaries:
            return
        outcome.suggest(found.summaries)

    async def run(self, goal_handle, task: SynthesisTask, outcome: PipelineOutcome, feedback,
                  deadline: GoalDeadline | None = None):
        """Run ``task``'s stages (as far as its option asks) into ``outcome``, telling ``feedback``."""
        deadline = deadline or GoalDeadline(task.timeout)
        goal_id = bytes(goal_handle.goal_id.uuid).hex()
        spec_name = byproduct_name(task, goal_id)

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
            check(compiled.error_code)
            outcome.ltl_specification = compiled.ltl_specification
            provenance = compiled.provenance
            if utf8_length(provenance) > MAX_STRING_BYTES:  # the synthesizer would refuse the request
                self.node.get_logger().warning(f'the provenance of {spec_name} ({utf8_length(provenance)} bytes) is '
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
        check(synthesized.error_code)
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
        check(generated.error_code)
        outcome.states = list(generated.state_definition)
        feedback(generated_summary(outcome.states), 1.0)

    def readable_system(self, name: str) -> RobotSystem | None:
        """The robot system of that name, or None when it cannot be read (compiling the task reports why)."""
        try:
            return robot_system(name, self.settings.config_dir or None)
        except CodedError:
            return None

    async def with_initial_conditions(self, goal_handle, task: SynthesisTask, outcome: PipelineOutcome,
                                      feedback, deadline: GoalDeadline) -> SynthesisTask:
        """``task``, with the robot's initial conditions when it names none or ``current``."""
        asks = asks_for_robot_state(task.initial_conditions)   # read the system file only then
        if not reads_robot_state(task.initial_conditions, self.readable_system(task.system) if asks else None):
            return task
        topic = self.robot_state.topic
        timeout = deadline.stage_limit(self.settings.robot_state_timeout, 'reading the robot state')
        feedback(f'Reading the initial conditions from {topic}', 0.02)
        with self.stages.looks.waiting():
            state = await self.robot_state.next_state_async(
                timeout, should_stop=lambda: goal_handle.is_cancel_requested or self.stopping.is_set())
        if goal_handle.is_cancel_requested:
            raise Preempted()
        if self.stopping.is_set():
            raise ServerStoppingError('reading the robot state: the server is shutting down', topic)
        if state is None:
            raise InvalidInitialConditionsError(
                f'no initial conditions given and no robot state on {topic!r} within {timeout:g} s: '
                'name the initial conditions, or start the robot (e.g. atlas-sim-node)', item=topic)
        names = initial_conditions_from_robot_state(state.mode, state.completed_actions, source=topic)
        outcome.notes.append(detected_status(names, topic))
        feedback(outcome.notes[-1], 0.04)
        return replace(task, initial_conditions=names)

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
        if goal_handle is not None and not (goal_handle.is_cancel_requested or self.stopping.is_set()):
            return
        if cancel_client.service_is_ready():
            cancel_client.call_async(CancelSynthesis.Request(request_id=goal_id))
