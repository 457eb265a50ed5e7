"""A filmed simulation, as the GUI's Simulate runs it: wall time against robot time, frames.

Each task is synthesized (ROS-free cores), then run once in closed loop on the in-process
simulator with frames recorded (``run_and_check(record_dir=...)``: key moments and the motion
at ``MOTION_FPS`` frames per robot second). Printed per run: start-up (imports of the
simulator and renderer, ``make_simulator``, the first frame), the run's wall time, its robot
time, the frames and motion frames per robot second, and whether wall <= robot time + start-up
(issue 35: a run plays at robot speed, so it must be simulated and filmed at least that fast).

    MUJOCO_GL=egl .venv/bin/python bench/bench_simulation.py            # both tasks
    MUJOCO_GL=egl .venv/bin/python bench/bench_simulation.py --tasks pickup
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time
from pathlib import Path

from bench_closed_loop import synthesized_machine

TWELVE_GOALS = ['look_down', 'approach_object', 'pregrasp', 'grasp_object', 'pickup_object',
                'footstep_execution', 'object_template', 'pregrasp_pose', 'footstep_plan', 'target_pose',
                'pregrasp_plan', 'footstep_goal']
# name, initial conditions, goals
TASKS = {
    'pickup': (['stand_prep'], ['look_down', 'pickup_object']),
    '12 goals': (['stand_prep'], TWELVE_GOALS),
}


def filmed_run(initial_conditions, goals, record_dir: Path) -> dict:
    spec, states = synthesized_machine(initial_conditions, goals, ('finished', 'failed'))
    started = time.monotonic()
    from atlas_sim.closed_loop import run_and_check
    from atlas_sim.simulated_robot import SimulatedRobot
    from atlas_sim.simulator.factory import make_simulator
    from atlas_sim.simulator.rendering import MOTION_FPS
    from respec.robot import robot_system

    simulator = make_simulator(robot_system('atlas'), initial_conditions=initial_conditions)
    first_frame = []

    def on_progress(steps, frames):
        if frames and not first_frame:
            first_frame.append(time.monotonic())

    run = run_and_check(states, SimulatedRobot(simulator), simulator, robot_system('atlas'), spec, goals,
                        record_dir=record_dir, on_progress=on_progress)
    finished = time.monotonic()
    robot = simulator.time
    motion = sum(1 for path in run.frames if path.name.endswith('_motion.png'))
    start_up = (first_frame[0] if first_frame else finished) - started
    run_wall = finished - start_up - started
    return {'outcome': run.result.outcome, 'check': 'ok' if run.check.ok else 'violations',
            'start_up': start_up, 'wall': run_wall, 'robot': robot, 'frames': len(run.frames),
            'motion_fps': motion / robot if robot else 0.0, 'target_fps': MOTION_FPS,
            'within': run_wall <= robot}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--tasks', default=','.join(TASKS), help='comma-separated: ' + ', '.join(TASKS))
    args = parser.parse_args()
    os.environ.setdefault('MUJOCO_GL', 'egl')
    print('| task | outcome | check | start-up s | run wall s | robot s | wall / robot | frames | '
          'motion frames per robot s | wall <= robot + start-up |')
    print('|---|---|---|---|---|---|---|---|---|---|')
    for name in args.tasks.split(','):
        initial_conditions, goals = TASKS[name]
        with tempfile.TemporaryDirectory() as folder:
            row = filmed_run(initial_conditions, goals, Path(folder))
        print(f"| {name} | {row['outcome']} | {row['check']} | {row['start_up']:.2f} | {row['wall']:.2f} | "
              f"{row['robot']:.2f} | {row['wall'] / row['robot']:.2f} | {row['frames']} | "
              f"{row['motion_fps']:.1f} (target {row['target_fps']}) | {'yes' if row['within'] else 'NO'} |",
              flush=True)


if __name__ == '__main__':
    main()
