"""A recorded run is filmed (issue 35): at least 15 frames per second of robot time between
the key moments, each file named with its robot time, listed as run.frames and on_progress
list them. Wall time against robot time is measured in bench/bench_simulation.py, not here."""

import re

import pytest

from atlas_sim.closed_loop import run_and_check
from atlas_sim.simulated_robot import SimulatedRobot
from atlas_sim.simulator.factory import make_simulator
from atlas_sim.simulator.rendering import MOTION_FPS
from ltl_specification import compile_task
from ltl_synthesizer import synthesize
from respec.automaton import automaton_from_strategy
from respec.robot import robot_system
from sm_generation import generate_state_machine

pytestmark = pytest.mark.mujoco

FRAME_NAME = re.compile(r'^(\d{4})_(\d{4}\.\d{3})s_([A-Za-z0-9_.-]+)\.png$')


@pytest.fixture(scope='module')
def filmed_pickup(tmp_path_factory):
    goals = ['look_down', 'pickup_object']
    spec = compile_task(robot_system('atlas'), ['stand_prep'], goals)
    automaton = automaton_from_strategy(synthesize(spec).strategy, spec)
    states = generate_state_machine(automaton, robot_system('atlas'), initial_conditions=['stand_prep'])
    simulator = make_simulator(robot_system('atlas'), initial_conditions=['stand_prep'])
    progress = []
    run = run_and_check(states, SimulatedRobot(simulator), simulator, robot_system('atlas'), spec, goals,
                        record_dir=tmp_path_factory.mktemp('run'),
                        on_progress=lambda steps, frames: progress.append(list(frames)))
    return run, progress, simulator.time


def test_the_run_is_filmed_at_fifteen_frames_a_robot_second_or_more(filmed_pickup):
    run, _, robot_time = filmed_pickup
    assert MOTION_FPS >= 15
    times = [float(FRAME_NAME.match(path.name).group(2)) for path in run.frames]
    motion = [t for path, t in zip(run.frames, times) if path.name.endswith('_motion.png')]
    assert len(motion) >= 15 * robot_time * 0.95  # the whole run, not just its key moments
    assert max(b - a for a, b in zip(motion, motion[1:])) <= 1 / 15 + 0.011  # no gap a still would fill
    assert times == sorted(times) and times[-1] == pytest.approx(robot_time, abs=0.011)


def test_frame_names_carry_index_robot_time_and_label(filmed_pickup):
    run, _, _ = filmed_pickup
    matches = [FRAME_NAME.match(path.name) for path in run.frames]
    assert all(matches), [p.name for p, m in zip(run.frames, matches) if not m]
    assert [int(m.group(1)) for m in matches] == list(range(len(run.frames)))
    labels = [m.group(3) for m in matches]
    assert labels[0] == 'start' and labels[-1] == 'end'
    assert 'pickup_object_completed' in labels and 'motion' in labels
    assert all(path.read_bytes().startswith(b'\x89PNG') for path in run.frames[::25])


def test_progress_lists_the_frames_as_they_come(filmed_pickup):
    run, progress, _ = filmed_pickup
    counts = [len(frames) for frames in progress]
    assert counts == sorted(counts) and len(set(counts)) > 30  # frames arrive during the run
    assert progress[-1] == run.frames[:len(progress[-1])]
