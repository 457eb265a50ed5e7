"""``behavior-synthesis repair``: verified changes that make a refused task possible (ROS-free).

    behavior-synthesis repair --system atlas --initial-conditions stand_prep \\
        --goals look_down,stand_prep [--sm-outcomes ...] [--unordered] [--config-dir DIR] \\
        [--custom-ltl FILE] [--json] [--time-budget S] [--max-proposals N]

Each proposal was compiled and synthesized, and found realizable, before it is shown. The text
form names the problem and numbers the proposals; ``--json`` prints one object (``proposals``,
each with ``kind``, ``summary``, ``request`` / ``custom_ltl`` / ``config_patch`` as changed,
``verified`` and ``synthesis_seconds``) for scripts. Progress goes to stderr as proposals are
found.
"""

from __future__ import annotations

import argparse
import json
import sys
from typing import Any

from respec.vocabulary.errors import CodedError, ExitStatus, exit_status_help
from respec.vocabulary.naming import parse_names
from respec.robot import robot_system

from ltl_specification.cli import add_task_arguments, read_custom_ltl
from ltl_specification.repair import DEFAULT_MAX_PROPOSALS, DEFAULT_TIME_BUDGET, TaskRequest
from ltl_specification.repair_process import RepairSearch, RepairSearchError, repair_settings


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Add the ``repair`` options to ``parser``."""
    parser.epilog = exit_status_help(ExitStatus.OK, ExitStatus.FAILED, ExitStatus.USAGE)
    add_task_arguments(parser)
    parser.add_argument('--json', action='store_true', help='print the proposals as one JSON object')
    parser.add_argument('--time-budget', type=float, default=DEFAULT_TIME_BUDGET, metavar='S',
                        help='seconds to search for proposals')
    parser.add_argument('--max-proposals', type=int, default=DEFAULT_MAX_PROPOSALS, metavar='N',
                        help='stop after this many verified proposals')


def run(args: argparse.Namespace) -> int:
    """Search and print; 0 when the task can be done as asked or a fix was found, 1 otherwise.

    The search runs in a child process (``repair_process.RepairSearch``): its time budget bounds
    it whole, the first check included, and it has a synthesis' memory limit."""
    if args.time_budget <= 0 or args.max_proposals < 1:
        print('error: --time-budget must be positive and --max-proposals at least 1', file=sys.stderr)
        return ExitStatus.USAGE
    try:
        system = robot_system(args.system, args.config_dir)
        request = TaskRequest(system.name, tuple(parse_names(args.initial_conditions)),
                              tuple(parse_names(args.goals)), tuple(parse_names(args.sm_outcomes)), args.unordered)
        search = RepairSearch(repair_settings(system, request.to_dict(), read_custom_ltl(args.custom_ltl),
                                              args.time_budget, args.max_proposals))
    except CodedError as error:
        return _refused(error)
    print(f'Searching for changes that make the task possible (at most {args.time_budget:g} s)...',
          file=sys.stderr, flush=True)
    found: list[dict[str, Any]] = []

    def on_proposal(proposal: dict[str, Any]) -> None:
        found.append(proposal)
        print(f'  found: {proposal["summary"]}', file=sys.stderr, flush=True)

    try:
        repairs = search.run(on_proposal)
    except CodedError as error:
        return _refused(error)
    except RepairSearchError as error:  # killed at its deadline or memory limit: what it verified stands
        verified = 'The proposals above were verified before that.' if found else 'Nothing was verified before that.'
        repairs = {'realizable': False, 'problem': 'not known: the search was ended before it could tell',
                   'proposals': found, 'tried': None, 'seconds': args.time_budget, 'note': f'{error}. {verified}'}
    if args.json:
        print(json.dumps(repairs, indent=2))
    else:
        print(_text(repairs))
    return ExitStatus.OK if repairs['realizable'] or repairs['proposals'] else ExitStatus.FAILED


def _refused(error: CodedError) -> int:
    print(f'error: {error.code}: {" ".join(str(error).split())} [item: {error.item!r}]', file=sys.stderr)
    return ExitStatus.FAILED


def _text(repairs: dict[str, Any]) -> str:
    """``Repairs.to_dict()`` as the lines the command prints."""
    if repairs['realizable']:
        return 'The task can be done as asked: nothing to repair.'
    lines = [f'The task cannot be done: {repairs["problem"]}', '']
    if not repairs['proposals']:
        tried = '' if repairs['tried'] is None else f'{repairs["tried"]} tried '
        lines.append(f'No verified change found ({tried}in {repairs["seconds"]:.1f} s).')
    for number, proposal in enumerate(repairs['proposals'], start=1):
        lines.append(f'{number}. {proposal["summary"]}')
        if 'request' in proposal:
            request = proposal['request']
            lines.append(f'   --initial-conditions {",".join(request["initial_conditions"])} '
                         f'--goals {",".join(request["goals"])} --sm-outcomes {",".join(request["sm_outcomes"])}'
                         + (' --unordered' if request['unordered'] else ''))
        if 'custom_ltl' in proposal:
            lines.append(f'   custom LTL: {json.dumps(proposal["custom_ltl"])}')
        if 'config_patch' in proposal:
            patch = proposal['config_patch']
            lines.append(f'   in {patch["file"]}, set {".".join(patch["path"])}: {json.dumps(patch["value"])} '
                         f'(was {json.dumps(patch["previous"])}); a change of the robot, not applied')
        lines.append(f'   verified: realizable, synthesized in {proposal["synthesis_seconds"] * 1000:.0f} ms')
    if repairs['note']:
        lines += ['', repairs['note']]
    return '\n'.join(lines)
