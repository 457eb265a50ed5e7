"""Closed-loop runs of a job's state machine on the simulated robot (atlas_sim)."""

from __future__ import annotations

import importlib.util
from dataclasses import dataclass, field
from pathlib import Path


@dataclass
class Simulation:
    """One closed-loop run of a job's state machine on the simulated robot (atlas_sim)."""

    id: str
    job_id: str
    fail_first: tuple[str, ...] = ()   # capabilities whose first attempt fails (a capability robot's: always)
    sensors: dict = field(default_factory=dict)  # a capability robot's sensors as the run starts
    sensor_names: tuple[str, ...] = ()  # the sensors an operator may set (a capability robot's)
    state: str = 'running'             # running -> finished
    steps: list[dict] = field(default_factory=list)  # atlas_sim TraceStep dicts so far
    robot_time: float = 0.0
    frames: list[Path] = field(default_factory=list, repr=False)
    timeline_png: Path | None = field(default=None, repr=False)
    outcome: str | None = None         # the SM outcome reached
    error: dict | None = None          # {'code', 'item', 'message'} if the run broke off
    check: dict | None = None          # atlas_sim trace check report
    wall_seconds: float = 0.0
    operator: dict = field(default_factory=dict)   # RuntimeControl status: autonomy, paused, waiting
    operator_events: list[dict] = field(default_factory=list)  # the operator's commands, once finished
    revision: int = 0

    def to_dict(self) -> dict:
        return {'id': self.id, 'job_id': self.job_id, 'fail_first': list(self.fail_first),
                'sensors': dict(self.sensors),
                'state': self.state, 'steps': list(self.steps), 'robot_time': round(self.robot_time, 3),
                'frames': [{'index': i, 'label': p.stem} for i, p in enumerate(self.frames)],
                'timeline': self.timeline_png is not None, 'outcome': self.outcome,
                'error': self.error, 'check': self.check, 'wall_seconds': round(self.wall_seconds, 3),
                'operator': self.operator, 'operator_events': list(self.operator_events)}


def simulation_available() -> bool:
    """Whether MuJoCo, which atlas_sim simulates with, is installed."""
    return importlib.util.find_spec('mujoco') is not None
