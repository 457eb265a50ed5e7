"""Speed figures of atlas_sim (not a test): simulated vs wall-clock time.

Run from the repository root::

    MUJOCO_GL=egl python bench/bench_atlas_sim.py [--render] [--stress SEEDS]
"""

from __future__ import annotations

import argparse
import os
import random
import sys
import tempfile
import time
from pathlib import Path

os.environ.setdefault("MUJOCO_GL", "egl")
sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from atlas_sim.simulator import AtlasSimulator, FrameRenderer


def measure(label: str, sim: AtlasSimulator, names) -> None:
    sim_start, wall_start = sim.time, time.perf_counter()
    outcomes = [sim.execute(name).outcome for name in names]
    sim_elapsed, wall = sim.time - sim_start, time.perf_counter() - wall_start
    print(f"{label:28s} sim {sim_elapsed:6.2f} s  wall {wall:6.3f} s  "
          f"x{sim_elapsed / wall:6.1f} real time  outcomes {outcomes}")


def bench_requests() -> None:
    sim = AtlasSimulator()
    start = time.perf_counter()
    sim = AtlasSimulator()
    print(f"{'construct + reset':28s} wall {time.perf_counter() - start:6.3f} s")
    wall_start = time.perf_counter()
    sim.hold(10.0)
    wall = time.perf_counter() - wall_start
    print(f"{'idle stand_prep':28s} sim  10.00 s  wall {wall:6.3f} s  x{10.0 / wall:6.1f} real time")
    measure("paper sequence", sim, ["stand", "look_down", "manipulate", "object_template", "pickup_object"])
    measure("walk (4 steps)", sim, ["stand", "walk"])
    measure("step in place (2 steps)", sim, ["stand", "step"])
    measure("footstep chain", sim, ["stand", "target_pose", "footstep_goal", "footstep_plan", "footstep_execution"])


def bench_render(frames: int = 30) -> None:
    sim = AtlasSimulator()
    with FrameRenderer(sim, 640, 480) as renderer, tempfile.TemporaryDirectory() as directory:
        renderer.render()  # warm-up (GL context, textures)
        start = time.perf_counter()
        for index in range(frames):
            sim.step()
            renderer.save(Path(directory) / f"{index}.png")
        wall = time.perf_counter() - start
    print(f"{'render+save 640x480 PNG':28s} {frames / wall:6.1f} frames/s ({os.environ['MUJOCO_GL']})")


def bench_stress(seeds: int) -> None:
    """Random request batches (mostly allowed ones); counts falls."""
    falls = completed = total = 0
    start = time.perf_counter()
    for seed in range(seeds):
        rng, sim = random.Random(seed), AtlasSimulator()
        names = list(sim.abstraction.capabilities)
        for _ in range(40):
            allowed = [n for n in names if sim.semantics.refusal(sim.state, n) is None]
            pool = allowed if allowed and rng.random() < 0.8 else names
            batch = rng.sample(pool, min(len(pool), rng.choice([1, 1, 2, 3])))
            results = sim.execute_concurrently(batch)
            total += len(results)
            completed += sum(r.completed for r in results.values())
            if sim.has_fallen():
                falls += 1
                break
    print(f"stress: {seeds} seeds x 40 batches, {completed}/{total} requests completed, "
          f"{falls} falls, wall {time.perf_counter() - start:.1f} s")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--render", action="store_true", help="also measure PNG rendering")
    parser.add_argument("--stress", type=int, default=0, metavar="SEEDS", help="random-sequence fall check")
    args = parser.parse_args()
    bench_requests()
    if args.render:
        bench_render()
    if args.stress:
        bench_stress(args.stress)


if __name__ == "__main__":
    main()
