"""Generators of capability robots of realistic size (issue 44), in CNU's capability format.

Each shape is a function ``N -> Robot`` (files to write into a config folder, the request's
initial conditions, goals and state-machine outcomes). Every capability is bound to FlexBE's
``OperatorDecisionState`` (outcomes ``done`` / ``failed``; a scan's ``clear`` / ``blocked``),
the request has empty initial conditions and asks for ``finished,failed``.

- ``chain``: capability i needs what capability i-1 completes; the goal is the last one's
  postcondition.
- ``retry``: the chain, every other capability retries itself on failure.
- ``sensor``: the chain, and a sensor (``blocked``) that a ``scan`` capability reports and a
  ``clear_path`` capability clears (as the delivery rover's battery): the middle capability
  needs a clear scan.
- ``fanout``: a root capability, then N-1 capabilities that each need only the root; the goals
  are all of them (unordered).
- ``diamond``: layers of a fork and two branches and a join: each branch needs the fork, the
  join needs both branches; the goal is the last join.
- ``mix``: a chain whose capabilities alternately retry, with a sensor, a diamond in the middle
  and a fan-out of the last quarter's capabilities as goals.

``per_cell_gridworld`` writes the other family of issue 44 as slugsin text: one
ENV_TRANS and one SYS_TRANS line per cell over binary-encoded positions (one integer each
for the robot and the adversary, both on the same grid graph), the no-swap conjunct
``!((rob' = adv) & (adv' = rob))``, 8 goal regions.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from respec.robot.state_library import StateClass

REQUEST_OUTCOMES = ['finished', 'failed']
# The FlexBE classes the robots use (FlexBE's own signatures), for runs without a workspace.
STATE_LIBRARY = {
    'OperatorDecisionState': StateClass('OperatorDecisionState', 'flexbe_states',
                                        ('outcomes', 'hint', 'suggestion'), ('outcomes',)),
}
MAPPINGS = """sm_outcome_mappings:
  finished: finished
  failed: failed
state_outcome_mappings:
  done: completed
  clear: completed
  blocked: blocked
  failed: failure
transition_outcomes:
  - completed
  - blocked
  - failure
"""


@dataclass
class Robot:
    """A capability robot and the request made of it."""

    name: str
    capabilities: dict = field(default_factory=dict)   # name -> (preconditions, retries, outcomes, postconditions)
    spec: dict = field(default_factory=dict)           # CNU spec-file sections
    goals: list = field(default_factory=list)
    initial_conditions: list = field(default_factory=list)

    def add(self, name: str, needs=(), retries: bool = False, outcomes=('done', 'failed'),
            completes=None, extra=None) -> None:
        self.capabilities[name] = (list(needs), retries, list(outcomes),
                                   [name] if completes is None else completes, extra or {})

    def write(self, config_dir: Path) -> str:
        """Write the system file and its CNU files into ``config_dir``; the system's name."""
        folder = config_dir / self.name
        folder.mkdir(parents=True, exist_ok=True)
        lines = [f"name: '{self.name}'", 'capabilities:']
        for name, (needs, retries, outcomes, completes, extra) in self.capabilities.items():
            lines += [f'  {name}:', '    interface: OperatorDecisionState', '    parameters:',
                      f'      outcomes: [{", ".join(repr(o) for o in outcomes)}]',
                      f"      hint: 'Did {name} succeed?'", f"      suggestion: '{outcomes[0]}'"]
            if needs:
                lines.append(f'    preconditions: [{", ".join(repr(n) for n in needs)}]')
            lines += ['    postconditions:', f'      completed: [{", ".join(repr(c) for c in completes)}]']
            for key, value in extra.get('postconditions', {}).items():
                lines.append(f'      {key}: [{", ".join(repr(v) for v in value)}]')
            relation = dict(extra.get('transition_relation', {}))
            if retries:
                relation['failure'] = [name]
            if relation:
                lines.append('    transition_relation:')
                lines += [f'      {key}: [{", ".join(repr(v) for v in value)}]' for key, value in relation.items()]
        (folder / 'capabilities.yaml').write_text('\n'.join(lines) + '\n')
        (folder / 'mappings.yaml').write_text(MAPPINGS)
        system = [f'system: {self.name}', f'cnu_capabilities: {self.name}/capabilities.yaml',
                  f'cnu_mappings: {self.name}/mappings.yaml']
        if self.spec:
            spec = [f'spec_name: "{self.name}"', 'specs:']
            for section, formulas in self.spec.items():
                spec.append(f'  {section}:')
                spec += [f'    - "{formula}"' for formula in formulas]
            (folder / 'spec.yaml').write_text('\n'.join(spec) + '\n')
            system.append(f'cnu_spec: {self.name}/spec.yaml')
        (config_dir / f'{self.name}.yaml').write_text('\n'.join(system) + '\n')
        return self.name


def compiled_spec(shape: str, size: int, config_dir: Path):
    """The project's specification of the ``shape`` robot of ``size`` capabilities, its files
    written into ``config_dir`` (a respec GR(1) specification)."""
    from ltl_specification import compile_task
    from respec.robot import robot_system

    robot = SHAPES[shape](size)
    robot.write(config_dir)
    return compile_task(robot_system(robot.name, str(config_dir)), robot.initial_conditions, robot.goals,
                        sm_outcomes=REQUEST_OUTCOMES, state_library=STATE_LIBRARY)


def _name(index: int) -> str:
    return f'c{index:03d}'


def chain(n: int, retry_every: int = 0, name: str = 'chain') -> Robot:
    robot = Robot(f'{name}_{n}')
    for index in range(n):
        robot.add(_name(index), needs=[_name(index - 1)] if index else [],
                  retries=bool(retry_every) and index % retry_every == retry_every - 1)
    robot.goals = [_name(n - 1)]
    return robot


def retry(n: int) -> Robot:
    return chain(n, retry_every=2, name='retry')


def _add_sensor(robot: Robot, needed_by: str) -> None:
    """A ``blocked`` sensor that ``scan`` reports and ``clear_path`` clears; ``needed_by``
    needs a clear scan (the delivery rover's battery pattern)."""
    robot.add('scan', outcomes=('clear', 'blocked'),
              extra={'postconditions': {'blocked': ['!scan']}, 'transition_relation': {'blocked': ['clear_path']}})
    robot.add('clear_path', needs=['!scan'], completes=['scan'])
    needs, retries, outcomes, completes, extra = robot.capabilities[needed_by]
    robot.capabilities[needed_by] = (needs + ['scan'], retries, outcomes, completes, extra)
    robot.spec = {'INPUT': ['blocked'],
                  'ENV_TRANS': ["scan_b' <-> (scan_a & blocked')", "scan_c' <-> (scan_a & !blocked')",
                                "clear_path_c' -> !blocked'"],
                  'ENV_LIVENESS': ['!blocked']}


def sensor(n: int) -> Robot:
    robot = chain(n - 2, name='sensor')
    robot.name = f'sensor_{n}'
    _add_sensor(robot, _name((n - 2) // 2))
    return robot


def fanout(n: int) -> Robot:
    robot = Robot(f'fanout_{n}')
    robot.add(_name(0))
    for index in range(1, n):
        robot.add(_name(index), needs=[_name(0)])
    robot.goals = [_name(index) for index in range(1, n)]
    return robot


def diamond(n: int) -> Robot:
    """Forks and joins: c0 -> (c1, c2) -> c3 -> (c4, c5) -> c6 ...; ``n`` rounded to 3k+1."""
    robot = Robot(f'diamond_{n}')
    robot.add(_name(0))
    join = 0
    while join + 3 < n:
        left, right, next_join = join + 1, join + 2, join + 3
        robot.add(_name(left), needs=[_name(join)])
        robot.add(_name(right), needs=[_name(join)])
        robot.add(_name(next_join), needs=[_name(left), _name(right)])
        join = next_join
    robot.goals = [_name(join)]
    return robot


def mix(n: int) -> Robot:
    """A chain (every third capability retries), a diamond in its middle, a sensor, and the
    last quarter's capabilities fanning out of the chain's end as goals."""
    robot = Robot(f'mix_{n}')
    spine = n - 2 - n // 4
    for index in range(spine):
        needs = [_name(index - 1)] if index else []
        if index >= 3 and index == spine // 2:  # a diamond: index-2 forks into index-1 and index
            needs = [_name(index - 2)]
        robot.add(_name(index), needs=needs, retries=index % 3 == 2)
    middle = spine // 2
    if middle >= 3:
        needs, retries, outcomes, completes, extra = robot.capabilities[_name(middle + 1)]
        robot.capabilities[_name(middle + 1)] = ([_name(middle - 1), _name(middle)], retries, outcomes,
                                                 completes, extra)
    leaves = [_name(index) for index in range(spine, spine + n // 4)]
    for leaf in leaves:
        robot.add(leaf, needs=[_name(spine - 1)])
    _add_sensor(robot, _name(spine // 4))
    robot.goals = leaves or [_name(spine - 1)]
    return robot


SHAPES = {'chain': chain, 'retry': retry, 'sensor': sensor, 'fanout': fanout, 'diamond': diamond, 'mix': mix}


# --- the per-cell gridworld -------------------------------------------------------------------

def per_cell_gridworld(width: int, height: int, goals: int = 8, realizable: bool = True) -> str:
    """A robot (``rob``) must visit ``goals`` regions infinitely often on a ``width`` x
    ``height`` grid; an adversary (``adv``) moves on the same grid graph. Positions are cell
    numbers, binary-encoded as structured slugs stores integers (``rob@0.0.303``, ``rob@1``,
    ...); each cell has one ENV_TRANS line (the adversary's moves from it) and one SYS_TRANS
    line (the robot's). The two never share a cell nor swap: ``rob' != adv'`` and
    ``!((rob' = adv) & (adv' = rob))``. Written as slugsin directly: structured slugs'
    comparison of two 9-bit integers (over 2^16 valuations) is too large for our parser.

    Realizable: the goal regions are 2x2 squares and the adversary must return to its home
    corner infinitely often. Unrealizable: one goal region is a single cell and the adversary
    may stay on it forever.
    """
    cells = width * height
    width_bits = max(1, (cells - 1).bit_length())
    rob = [f'rob@0.0.{cells - 1}'] + [f'rob@{k}' for k in range(1, width_bits)]
    adv = [f'adv@0.0.{cells - 1}'] + [f'adv@{k}' for k in range(1, width_bits)]

    def cell(x, y):
        return y * width + x

    def moves(x, y):
        around = [(x, y), (x + 1, y), (x - 1, y), (x, y + 1), (x, y - 1)]
        return [cell(a, b) for a, b in around if 0 <= a < width and 0 <= b < height]

    env_trans, sys_trans = [], []
    for y in range(height):
        for x in range(width):
            here = cell(x, y)
            env_trans.append(_implies(_equals(adv, here), _any([_equals(adv, m, True) for m in moves(x, y)])))
            sys_trans.append(_implies(_equals(rob, here), _any([_equals(rob, m, True) for m in moves(x, y)])))
    same_next = _all([f"! ^ {r}' {a}'" for r, a in zip(rob, adv)])
    swap = _all([f"! ^ {r}' {a}" for r, a in zip(rob, adv)] + [f"! ^ {a}' {r}" for r, a in zip(rob, adv)])
    sys_trans += [f'! {same_next}', f'! {swap}', _at_most(rob, cells - 1, True)]
    env_trans.append(_at_most(adv, cells - 1, True))
    regions = []
    for index in range(goals):
        x0 = min(width - 2, round(index * (width - 2) / max(goals - 1, 1)))
        y0 = 0 if index % 2 == 0 else height - 2
        regions.append([cell(x0, y0), cell(x0 + 1, y0), cell(x0, y0 + 1), cell(x0 + 1, y0 + 1)])
    if not realizable:
        regions[-1] = [cell(width // 2, height // 2)]
    sections = {
        'INPUT': adv, 'OUTPUT': rob,
        'ENV_INIT': [_equals(adv, cell(width // 2, height // 2))], 'SYS_INIT': [_equals(rob, 0)],
        'ENV_TRANS': env_trans, 'SYS_TRANS': sys_trans,
        'ENV_LIVENESS': [_equals(adv, cell(0, height - 1))] if realizable else [],
        'SYS_LIVENESS': [_any([_equals(rob, c) for c in region]) for region in regions]}
    return ''.join(f'[{section}]\n' + ''.join(f'{line}\n' for line in lines) + '\n'
                   for section, lines in sections.items())


def _equals(bits: list[str], value: int, next_step: bool = False) -> str:
    mark = "'" if next_step else ''
    return _all([f'{b}{mark}' if value >> k & 1 else f'! {b}{mark}' for k, b in enumerate(bits)])


def _at_most(bits: list[str], bound: int, next_step: bool = False) -> str:
    """value <= bound, most significant bit first (slugsin prefix)."""
    mark = "'" if next_step else ''
    formula = '1'
    for k, b in enumerate(bits):  # least significant first: each step wraps the lower bits
        formula = f'| ! {b}{mark} {formula}' if bound >> k & 1 else f'& ! {b}{mark} {formula}'
    return formula


def _all(parts: list[str]) -> str:
    return _nary('&', parts, '1')


def _any(parts: list[str]) -> str:
    return _nary('|', parts, '0')


def _nary(operator: str, parts: list[str], empty: str) -> str:
    if not parts:
        return empty
    text = parts[-1]
    for part in reversed(parts[:-1]):
        text = f'{operator} {part} {text}'
    return text


def _implies(left: str, right: str) -> str:
    return f'| ! {left} {right}'
