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

from respec.errors import CodedError, ExitStatus, exit_status_help
from respec.naming import parse_names

from ltl_specification.cli import add_task_arguments, read_custom_ltl
from ltl_specification.repair import DEFAULT_MAX_PROPOSALS, DEFAULT_TIME_BUDGET, Proposal, TaskRequest, propose_repairs


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
    """Search and print; 0 when the task can be done as asked or a fix was found, 1 otherwise."""
    if args.time_budget <= 0 or args.max_proposals < 1:
        print('error: --time-budget must be positive and --max-proposals at least 1', file=sys.stderr)
        return ExitStatus.USAGE
    request = TaskRequest(args.system, tuple(parse_names(args.initial_conditions)), tuple(parse_names(args.goals)),
                          tuple(parse_names(args.sm_outcomes)), args.unordered)
    print(f'Searching for changes that make the task possible (at most {args.time_budget:g} s)...',
          file=sys.stderr, flush=True)

    def found(proposal: Proposal) -> None:
        print(f'  found: {proposal.summary}', file=sys.stderr, flush=True)

    try:
        repairs = propose_repairs(args.system, request, read_custom_ltl(args.custom_ltl), args.config_dir,
                                  args.time_budget, args.max_proposals, on_proposal=found)
    except CodedError as error:
        print(f'error: {error.code}: {" ".join(str(error).split())} [item: {error.item!r}]', file=sys.stderr)
        return ExitStatus.FAILED
    if args.json:
        print(json.dumps(repairs.to_dict(), indent=2))
    else:
        print(_text(repairs))
    return ExitStatus.OK if repairs.realizable or repairs.proposals else ExitStatus.FAILED


def _text(repairs) -> str:
    if repairs.realizable:
        return 'The task can be done as asked: nothing to repair.'
    lines = [f'The task cannot be done: {repairs.problem}', '']
    if not repairs.proposals:
        lines.append(f'No verified change found ({repairs.tried} tried in {repairs.seconds:.1f} s).')
    for number, proposal in enumerate(repairs.proposals, start=1):
        lines.append(f'{number}. {proposal.summary}')
        if proposal.request is not None:
            request = proposal.request
            lines.append(f'   --initial-conditions {",".join(request.initial_conditions)} '
                         f'--goals {",".join(request.goals)} --sm-outcomes {",".join(request.sm_outcomes)}'
                         + (' --unordered' if request.unordered else ''))
        if proposal.custom_ltl is not None:
            lines.append(f'   custom LTL: {json.dumps(proposal.custom_ltl)}')
        if proposal.config_patch is not None:
            patch = proposal.config_patch
            lines.append(f'   in {patch.file}, set {".".join(patch.path)}: {json.dumps(patch.value)} '
                         f'(was {json.dumps(patch.previous)}); a change of the robot, not applied')
        lines.append(f'   verified: realizable, synthesized in {proposal.synthesis_seconds * 1000:.0f} ms')
    if repairs.note:
        lines += ['', repairs.note]
    return '\n'.join(lines)
