"""Hand-made state machines for ATLAS (a root, a state configured as config/atlas.yaml has it)
and a robot without physics whose capabilities end after scripted numbers of ticks."""

from atlas_sim.executive.robot import CapabilityResult
from respec.robot import robot_system
from sm_generation.config import flexbe_config

FLEXBE = flexbe_config(robot_system('atlas'))
MODES = ['stand_prep', 'stand', 'manipulate', 'step', 'walk']


def root(initial, outcomes=('finished', 'failed')):
    return {'state_path': '/', 'state_class': ':STATEMACHINE', 'initial_state_name': initial,
            'outcomes': list(outcomes), 'transitions': list(outcomes)}


def state(path, proposition, **transitions):
    """A state configured for ``proposition`` (class and parameters from config/atlas.yaml);
    ``transitions`` map its outcomes to the next state or machine outcome."""
    config = FLEXBE.states[proposition]
    return {'state_path': path, 'state_class': config.state_class, 'behavior_class': config.behavior_class,
            'parameter_names': list(config.parameter_names), 'parameter_values': list(config.parameter_values),
            'outcomes': list(transitions), 'transitions': list(transitions.values())}


class ScriptedRobot:
    """A robot without physics: each capability ends after a scripted number of ticks."""

    def __init__(self, script, mode='stand_prep', sensors_at=None):
        # capability -> (ticks, outcome), or a list of them, one per attempt; missing: never ends
        self.script = {c: list(v) if isinstance(v, list) else [v] for c, v in script.items()}
        self.mode, self.tick = mode, 0
        self.sensors_at = sensors_at or {}  # sensor -> tick from which it reads true
        self.started = []
        self.control_modes = MODES

    def start_concurrently(self, capabilities):
        handles = []
        for capability in capabilities:
            attempts = self.script.get(capability, [(None, None)])
            ticks, outcome = attempts.pop(0) if len(attempts) > 1 else attempts[0]
            handles.append({'capability': capability, 'ends': None if ticks is None else self.tick + ticks,
                            'outcome': outcome, 'applied': False})
            self.started.append((self.tick, capability))
        self.handles = getattr(self, 'handles', []) + handles
        return handles

    def step(self):
        self.tick += 1
        for handle in self.handles:
            if handle['ends'] == self.tick and handle['capability'] in MODES and handle['outcome'] == 'completed':
                self.mode = handle['capability']

    def result(self, handle):
        if handle['ends'] is None or self.tick < handle['ends']:
            return None
        return CapabilityResult(handle['capability'], handle['outcome'], 'scripted', handle['ends'] / 10)

    def snapshot(self):
        return {'time': self.tick / 10, 'mode': self.mode, 'completed_actions': [], 'pelvis_height': 0.8,
                'fallen': False, 'sensors': {s: self.tick >= t for s, t in self.sensors_at.items()}}
