"""``ltl_specification.repair`` in a child process with a deadline, for servers (the GUI's
"Suggest fixes", the fixes the synthesis action's result proposes).

A repair search compiles and synthesizes dozens of candidate tasks for up to its time budget:
in a server's own process it would hold Python's GIL (one CUDD operation can run for seconds),
so every other request would wait. It therefore runs in a child process of its own
(``respec.child_processes.runner.ChildProcess``, which preloads this module), killed when the server
stops or the search overruns its deadline. The child gets the robot system's files as the
server read them (perhaps from a suite on another machine), not a name to read again, and
reports each verified proposal as it is found.

    search = RepairSearch(repair_settings(system, request, custom_ltl, budget, count))
    repairs = search.run(on_proposal)        # search.stop() from another thread ends it
"""

from __future__ import annotations

import time
from typing import Any, Callable

from respec.robot import RobotSystem

from ltl_synthesizer.errors import SynthesisError
from ltl_synthesizer.interrupt import DEFAULT_MEMORY_LIMIT
from ltl_synthesizer.isolated import SYNTHESIS_PROCESS
from respec.child_processes.errors import ChildWorkError, WorkTimeoutError
from respec.child_processes.runner import SERVER_CHILD_NICENESS, ChildProcess

#: Seconds a child may take beyond its search's time budget to answer (the kill comes
#: runner.DEADLINE_GRACE_SECONDS later still: 0.5 s in all). The budget counts from
#: the search's creation in the parent, so the child's start (0.2-0.3 s measured) comes out of
#: it, not on top of it (``search`` stops at ``ends_at``, a time.monotonic() value: one clock for
#: every process of the machine). A candidate's compilation or synthesis that outlives the
#: deadline (one CUDD operation can run for a minute on a BDD bomb) is ended by the kill; what
#: was verified before is kept.
ANSWER_GRACE = 0.2


class RepairSearchError(Exception):
    """The child ended (killed, crashed, overran its deadline) without an answer."""


def repair_settings(system: RobotSystem, request: dict[str, Any], custom_ltl: Any, time_budget: float,
                    max_proposals: int, memory_limit: int | None = DEFAULT_MEMORY_LIMIT) -> dict[str, Any]:
    """What a child needs for a search of ``request`` (``TaskRequest.to_dict()``) on ``system``
    (a RobotSystem: its files travel, not its name); ``memory_limit``: bytes the child may grow
    by, as a synthesis may (None: no limit)."""
    return {'system': system.name, 'files': dict(system.files), 'config_file': system.config_file,
            'request': request, 'custom_ltl': custom_ltl, 'time_budget': time_budget,
            'max_proposals': max_proposals, 'memory_limit': memory_limit}


class RepairSearch:
    """One search in its child process. ``settings``: ``system``, ``files``, ``config_file`` (the
    RobotSystem's), ``request`` (TaskRequest.to_dict()), ``custom_ltl``, ``time_budget``,
    ``max_proposals``."""

    def __init__(self, settings: dict[str, Any]) -> None:
        ends_at = time.monotonic() + settings['time_budget']
        self.settings = {**settings, 'ends_at': ends_at}
        self.deadline = ends_at + ANSWER_GRACE
        self.child = ChildProcess(niceness=SERVER_CHILD_NICENESS, preload=__name__, name=SYNTHESIS_PROCESS)

    def run(self, on_proposal: Callable[[dict[str, Any]], None] | None = None) -> dict[str, Any]:
        """The search's ``Repairs.to_dict()``; ``on_proposal(proposal dict)`` as each is verified.
        A refusal of the system's files is raised as the CodedError it is. The whole search,
        its first check and the diagnosis included, ends within its time budget and ANSWER_GRACE
        (counted from this object's creation), and within its memory limit."""
        try:
            answer: dict[str, Any] = self.child.call(
                search, (self.settings,), on_progress=on_proposal or (lambda _: None),
                deadline=self.deadline, memory_limit=self.settings.get('memory_limit'))
            return answer
        except WorkTimeoutError:  # the runner's, or the search's own synthesis timeout
            raise RepairSearchError(f'the repair search was ended at its time budget of '
                                    f'{self.settings["time_budget"]:g} s (a check was still running)') from None
        except (ChildWorkError, SynthesisError) as error:  # died, stopped, its memory limit
            raise RepairSearchError(f'the repair search ended without an answer ({error})') from error
        finally:
            self.child.kill()

    def stop(self) -> None:
        """End the child now, from any thread (the GUI stops)."""
        if self.child.process.poll() is None:
            self.child.process.kill()


def search(settings: dict[str, Any], progress: Callable[[dict[str, Any]], None]) -> dict[str, Any]:
    """In the child: the verified proposals for the settings' task on the GUI's robot system."""
    from ltl_specification.repair import TaskRequest, propose_repairs
    from respec.robot import robot_system_from_files

    system = robot_system_from_files(settings['system'], settings['files'], settings['config_file'])
    repairs = propose_repairs(system, TaskRequest.from_dict(settings['request']), settings['custom_ltl'],
                              time_budget=max(0.0, settings['ends_at'] - time.monotonic()),
                              max_proposals=settings['max_proposals'],
                              on_proposal=lambda proposal: progress(proposal.to_dict()))
    return repairs.to_dict()
