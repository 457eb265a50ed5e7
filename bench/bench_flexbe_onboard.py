"""The 5-goal behavior on FlexBE's own onboard executive, N times in a row: outcomes, hangs, run times.

    FLEXBE_SOURCES=../shared/third_party .venv/bin/python bench/bench_flexbe_onboard.py \
        [--runs 100] [--markdown bench/results/flexbe_onboard.md]

Issue 37 saw one run in 13 hang: the robot reported ``pregrasp`` complete and FlexBE's
``ProxyActionClient`` never delivered the result. Our ``CapabilityRequest`` now gives up on a
capability after ``RESULT_TIMEOUT`` seconds with the state's failure outcome, so every run must
reach an outcome. Each run exports nothing new: the behavior is exported and installed once (as
a user without colcon does), then every run starts fresh processes on a domain of its own (the
robot at speed 20, the headless operator, ``flexbe_onboard.start_behavior``), starts the behavior
as be_launcher does, and waits for its end on ``flexbe/status``. A run with no end within
``--hang-after`` seconds counts as hung. Figures: outcomes, hangs, the runs in which a finished
capability's result was late and asked for again, the runs that gave up on a capability (the
onboard log names both), and the distribution of the behavior's run time (from the
BehaviorSelection to its end) and of the whole run (start-up included).
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / 'bench'))

from flexbe_onboard_system import Operator, OnboardSystem, exported_and_installed

BEHAVIOR = 'Bench Five Goals'
FIVE_GOALS = ['--system', 'atlas', '--initial-conditions', 'stand_prep',
              '--goals', 'look_down,pregrasp,pickup_object,approach_object,footstep_execution']
GAVE_UP = 'giving up on it'  # CapabilityRequest's log line when a result never came
ASKED_AGAIN = 'asking for it again'  # its line when a finished goal's result is late and asked for again


def one_run(prefix: Path, flexbe_prefix: Path, logs: Path, hang_after: float) -> dict:
    """Fresh processes on a domain of their own, the behavior started once; what happened."""
    from flexbe_msgs.msg import BEStatus

    from synthesis_manager.ros.harness import RosHarness

    started = time.perf_counter()
    with RosHarness() as ros:
        system = OnboardSystem(ros, prefix, flexbe_prefix, logs)
        try:
            operator = Operator(ros)
            operator.wait_for_servers()
            operator.wait_until(lambda: any(s.code == BEStatus.READY for s in operator.statuses), 60,
                                'READY from onboard')
            selected = time.perf_counter()
            try:
                status = operator.start_behavior(BEHAVIOR, timeout=hang_after)
                outcome = list(status.args)[0] if status.code == BEStatus.FINISHED and status.args else \
                    f'status {status.code}'
            except AssertionError:
                outcome = 'hung'
            behavior_seconds = time.perf_counter() - selected
        finally:
            system.stop()
        lines = (operator.log_text() + '\n' + system.log('onboard')).splitlines()
        gave_up = [line for line in lines if GAVE_UP in line]
        asked_again = [line for line in lines if ASKED_AGAIN in line]
    return {'outcome': outcome, 'behavior_s': behavior_seconds, 'total_s': time.perf_counter() - started,
            'gave_up': gave_up[:1], 'asked_again': asked_again[:1]}


def distribution(values: list[float]) -> str:
    """min / median / p90 / max in seconds."""
    ordered = sorted(values)
    p90 = ordered[min(len(ordered) - 1, int(round(0.9 * (len(ordered) - 1))))]
    return (f'{ordered[0]:.1f} / {statistics.median(ordered):.1f} / {p90:.1f} / {ordered[-1]:.1f}')


def report(runs: list[dict], hang_after: float) -> str:
    outcomes = {}
    for run in runs:
        outcomes[run['outcome']] = outcomes.get(run['outcome'], 0) + 1
    ended = [r for r in runs if r['outcome'] != 'hung']
    lines = [f'| runs | reached an outcome | hung (no end within {hang_after:g} s) | outcomes | '
             'asked again for a late result | gave up on a capability |',
             '|---|---|---|---|---|---|',
             f"| {len(runs)} | {len(ended)} | {outcomes.get('hung', 0)} | "
             + ', '.join(f'{name} {count}' for name, count in sorted(outcomes.items())) + ' | '
             + str(sum(1 for r in runs if r['asked_again'])) + ' | '
             + str(sum(1 for r in runs if r['gave_up'])) + ' |',
             '',
             '| seconds (min / median / p90 / max) | value |',
             '|---|---|']
    if ended:
        lines.append(f"| behavior run (BehaviorSelection to end) | {distribution([r['behavior_s'] for r in ended])} |")
    lines.append(f"| whole run (processes up, run, stopped) | {distribution([r['total_s'] for r in runs])} |")
    for number, run in enumerate(runs, 1):
        if run['asked_again']:
            lines.append(f"\nrun {number}, {run['outcome']}, asked again: {run['asked_again'][0].strip()}")
        if run['gave_up']:
            lines.append(f"\nrun {number}, {run['outcome']}, gave up: {run['gave_up'][0].strip()}")
    return '\n'.join(lines) + '\n'


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--runs', type=int, default=100, help='runs in a row (default 100)')
    parser.add_argument('--hang-after', type=float, default=300.0,
                        help='seconds without an end after which a run counts as hung (default 300)')
    parser.add_argument('--markdown', help='also write the tables to this file')
    args = parser.parse_args()

    from synthesis_manager.ros.env import prepare_ros_environment

    prepare_ros_environment()  # DDS on loopback here and in every process the runs start
    flexbe_prefix = Path(sys.prefix) / 'flexbe'
    with tempfile.TemporaryDirectory(prefix='bench_flexbe_onboard_') as folder:
        work = Path(folder)
        prefix = exported_and_installed(work, [*FIVE_GOALS, '--name', BEHAVIOR])
        # This process's BehaviorLibrary (the operator finds the behavior's key and source as be_launcher does).
        os.environ['AMENT_PREFIX_PATH'] = os.pathsep.join([str(prefix), str(flexbe_prefix), sys.prefix])
        sys.path.insert(0, str(prefix / 'lib' / f'python{sys.version_info.major}.{sys.version_info.minor}'
                                / 'site-packages'))
        runs = []
        for index in range(args.runs):
            logs = work / f'run{index}'
            logs.mkdir()
            runs.append(one_run(prefix, flexbe_prefix, logs, args.hang_after))
            run = runs[-1]
            print(f"run {index + 1}/{args.runs}: {run['outcome']} in {run['behavior_s']:.1f} s "
                  f"(whole run {run['total_s']:.1f} s)", flush=True)
            if run['outcome'] != 'finished':
                print((logs / 'onboard.log').read_text(errors='replace')[-2000:], flush=True)
    table = report(runs, args.hang_after)
    print(table)
    if args.markdown:
        Path(args.markdown).write_text(table, encoding='utf-8')


if __name__ == '__main__':
    main()
