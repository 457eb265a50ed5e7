"""Every node's settings, declared once (ROS-free): name, type, default, meaning and limits.

A node declares its ROS parameters from its tuple here (``synthesis_manager.ros.settings``)
and reads them by name (``self.settings.timeout``); the suite's command-line flags
(``serve``, ``gui``, ``demo``, ``execute``, ``export-behavior``: :data:`SUITE_FLAGS`) set
them, their help telling the setting's default; and docs/nodes.md's parameter table is
:func:`settings_table` (``python -m synthesis_manager.settings`` prints it;
test/synthesis_manager/test_settings.py fails when the two differ). Adding a setting is one
:class:`Setting` line in its node's tuple, plus its use.
"""

from __future__ import annotations

import argparse
from dataclasses import dataclass
from typing import Any, Callable

from atlas_sim.simulator.node_names import STATE_TOPIC
from ltl_synthesizer.cache import DEFAULT_MAX_BYTES
from ltl_synthesizer.service import BACKENDS, SynthesisSettings
from respec.robot.files import add_config_dir_argument
from synthesis_manager.byproducts import DEFAULT_KEEP_LAST, default_directory
from synthesis_manager.limits import DEFAULT_MAX_GOAL_TIMEOUT
from synthesis_manager.requests import DEFAULT_SYSTEM


@dataclass(frozen=True)
class Setting:
    """One node setting. ``default``: its value, or a function giving it when a node declares
    it (then ``shown_default`` says it for people); ``limits``: what bounds it or what its
    special values mean; ``choices``: its only values; ``dynamic_typing``: a ROS parameter
    that may take another type than the default's (a list given as a string)."""

    name: str
    type: type
    default: object
    meaning: str
    limits: str = ''
    shown_default: str = ''
    choices: tuple = ()
    dynamic_typing: bool = False

    def default_value(self):
        return self.default() if callable(self.default) else self.default

    def default_text(self) -> str:
        """The default as people read it (docs, help texts)."""
        if self.shown_default:
            return self.shown_default
        if self.type is bool:
            return str(self.default).lower()
        if self.type is float:
            return f'{self.default:g}'
        return (f'{self.default:,}' if self.type is int and isinstance(self.default, int) and abs(self.default) >= 10_000
                else str(self.default))


CONFIG_DIR = Setting('config_dir', str, '', 'directories of robot system files (joined with `:`), searched before '
                     'the shipped `config/`', shown_default="`''`: the shipped `config/` alone")

LTL_COMPILATION = (
    CONFIG_DIR,
    Setting('timeout', float, 30.0, 'seconds: a request with over 64 KB of custom formulas is compiled in a child '
            "process, within this from its arrival, or the request's shorter `timeout` (the server sets it to what "
            "is left of the goal's time)", 'beyond: `TIMEOUT`'),
    Setting('memory_limit_mb', int, 2048, "MiB that child may grow by", 'beyond: `LTL_SPEC_COMPILATION_FAILED` naming it'),
    Setting('parallel_compilations', int, 2, 'compilations at once in child processes'),
    Setting('queued_compilations', int, 200, 'compilations waiting beyond those', 'more: `BUSY`'),
    Setting('repair_time_budget', float, 3.0, 'seconds a `propose_repairs` search takes when the request names none',
            'at most 60'),
    Setting('parallel_repairs', int, 1, 'repair searches at once, each in a child process', '8 more wait, then `BUSY`'),
)

#: The synthesis service's own defaults (ltl_synthesizer.service), the synthesis node's too.
SERVICE = SynthesisSettings()

LTL_SYNTHESIS = (
    Setting('byproducts_dir', str, lambda: str(default_directory()),
            'where the synthesizer writes its byproducts (`<spec_name>.structuredslugs`, `.slugsin`, `.json`)',
            'private: created 0700, refused if another user owns it or others can write to it',
            shown_default='`$TMPDIR/behavior_synthesis_byproducts`'),
    Setting('keep_byproducts', int, DEFAULT_KEEP_LAST, "spec names whose byproduct files are kept, newest first",
            '0: keep none'),
    Setting('byproducts_max_age', float, 0.0, 'seconds byproduct files are kept', '0: no age limit'),
    Setting('backend', str, SERVICE.backend, 'the synthesizer: our own, or `slugs_executable` called the original way',
            choices=BACKENDS),
    Setting('slugs_executable', str, SERVICE.slugs_executable, 'the executable of the `slugs` backend'),
    Setting('timeout', float, 60.0, 'seconds per synthesis when a request gives none; waiting for a worker counts'),
    Setting('max_timeout', float, DEFAULT_MAX_GOAL_TIMEOUT, 'the longest time limit a request gets; more is capped',
            '0: no cap'),
    Setting('max_strategy_edges', int, SERVICE.max_strategy_edges,
            'the largest builtin strategy sent back, in transitions', 'beyond: `SYNTHESIS_FAILED` naming its size; '
            '0: no limit'),
    Setting('robotics_semantics', bool, SERVICE.robotics_semantics, "slugs' robotics semantics: every initial state allowed by ENV_INIT "
            'and SYS_INIT must be winning'),
    Setting('memory_limit_mb', int, SERVICE.memory_limit_mb, 'MiB per synthesis', 'beyond: `SYNTHESIS_FAILED` naming the limit'),
    Setting('memory_sum_limit_mb', int, 4096, "MiB of the suite's process and all its child processes together "
            "(syntheses, compilations, repair searches, a GUI's simulations)", 'beyond: the working child holding '
            'the most is ended, `SYNTHESIS_FAILED` naming `memory_sum_limit`; 0: none'),
    Setting('diagnosis_timeout', float, SERVICE.diagnosis_timeout, 'seconds to find why an unrealizable specification cannot be met, '
            'when a request gives none', "never past the request's time limit"),
    Setting('check_well_separation', bool, SERVICE.check_well_separation, 'a realizable specification whose controller can win by forcing '
            'the environment to break its assumptions gets a warning naming them, as its `SUCCESS` message',
            'checked within `diagnosis_timeout` and the time limit'),
    Setting('parallel_syntheses', int, 8, 'syntheses at once'),
    Setting('queued_syntheses', int, 200, 'syntheses waiting beyond those', 'more: `BUSY`'),
    Setting('strategy_cache_mb', float, DEFAULT_MAX_BYTES / 2**20, 'MiB of answers kept for identical requests, '
            'least recently used dropped first (see "Strategy cache" in [limits.md](limits.md))', '0: no cache'),
    Setting('strategy_cache_dir', str, '', 'a private directory where kept answers are kept too, so that a restarted '
            'node answers from it', "`''`: memory only"),
    Setting('strategy_cache_key_file', str, '', "the 0600 key signing the cache directory's entries",
            "`''`: `DIR.key` beside it, made on first use"),
)

SM_GENERATION = (
    CONFIG_DIR,
    Setting('reduce', bool, False, 'merge equivalent automaton states'),
    Setting('timeout', float, 30.0, "seconds: an automaton of over 2,000 states is generated in a child process, "
            "within this from the request's arrival, or the request's shorter `timeout` (the server sets it to what "
            "is left of the goal's time)", 'beyond: `TIMEOUT`'),
    Setting('memory_limit_mb', int, 2048, "MiB that child may grow by", 'beyond: `SM_GENERATION_FAILED` naming it'),
    Setting('parallel_generations', int, 1, 'generations at once in child processes'),
    Setting('queued_generations', int, 50, 'generations waiting beyond those', 'more: `BUSY`'),
)

BEHAVIOR_SYNTHESIS_SERVER = (
    Setting('default_system', str, DEFAULT_SYSTEM, 'the system of requests naming none or `system_wide`'),
    Setting('config_dir', str, '', "the compilation node's `config_dir`: which systems are CNU's",
            shown_default=CONFIG_DIR.shown_default),
    Setting('service_timeout', float, 5.0, 'seconds to wait for a pipeline service to appear'),
    Setting('compilation_timeout', float, 30.0, 'seconds for the compilation stage'),
    Setting('synthesis_timeout', float, 120.0, 'seconds for the synthesis stage'),
    Setting('generation_timeout', float, 30.0, 'seconds for the state machine generation stage'),
    Setting('diagnosis_timeout', float, 20.0, 'seconds the synthesis node may take to find why an unrealizable task '
            'cannot be done', "within the synthesis's limit"),
    Setting('robot_state_topic', str, STATE_TOPIC, 'where a request naming no initial conditions, or `current`, '
            'reads them (synthesis_msgs/RobotState): synthesis on the fly'),
    Setting('robot_state_timeout', float, 2.0, 'seconds to wait for a robot state'),
    Setting('flexbe_log_topic', str, 'flexbe/log', "FlexBE's operator log, where failures are logged", "`''`: none"),
    Setting('max_active_goals', int, 100, 'goals in progress at once, both actions together',
            'more: `BUSY`; beyond twice that many accepted, goals are rejected'),
    Setting('max_goal_timeout', float, DEFAULT_MAX_GOAL_TIMEOUT, 'the longest time limit a goal may ask for; more is '
            'capped, and the feedback and a timeout result say so', '0: no cap'),
    Setting('result_retention', float, 60.0, "seconds a finished goal's result stays available to its client"),
    Setting('repair_time_budget', float, 3.0, 'seconds to search for up to 3 verified fixes of a goal refused as '
            'impossible (`SPEC_UNSYNTHESIZABLE`, `INVALID_GOALS`, `ABSTRACTION_CONFIG_INVALID`), from '
            '`propose_repairs`: appended to `error_code.message` as "Suggested fix N: ..." and listed in CNU\'s '
            '`messages[]`', '0: none'),
    Setting('max_client_goals', int, 6, "goals of one client running at once (see \"Sharing a server\" in "
            '[limits.md](limits.md))', 'beyond: a goal waits, its feedback giving its place'),
    Setting('max_client_goal_seconds', float, 1200.0, "one client's running goals' time limits together",
            'beyond: a goal waits'),
    Setting('max_client_waiting', int, 50, "goals of one client waiting", 'beyond: `BUSY`'),
)

ATLAS_SIM = (
    Setting('system', str, 'atlas', 'the simulated robot system'),
    Setting('config_dir', str, '', CONFIG_DIR.meaning, shown_default=CONFIG_DIR.shown_default),
    Setting('initial_conditions', str, '', 'where the robot starts (a string array or a comma-separated string)',
            "`''`: the system's", dynamic_typing=True),
    Setting('fail', str, '', 'capabilities that always fail (a string array or a comma-separated string)',
            dynamic_typing=True),
    Setting('fail_first', str, '', "capabilities whose first k attempts fail, 'capability:k'", dynamic_typing=True),
    Setting('seed', int, -1, 'seed of probabilistic faults', "-1: the system file's"),
    Setting('speed', float, 10.0, 'sim seconds per wall second', '0: as fast as possible'),
    Setting('state_rate', float, 10.0, 'Hz of `atlas_sim/state`'),
    Setting('batch_window', float, 0.02, 'wall seconds within which arriving goals start in the same sim instant'),
)

#: Each node's settings, by node name.
NODE_SETTINGS = {
    'ltl_compilation': LTL_COMPILATION,
    'ltl_synthesis': LTL_SYNTHESIS,
    'sm_generation': SM_GENERATION,
    'behavior_synthesis_server': BEHAVIOR_SYNTHESIS_SERVER,
    'atlas_sim': ATLAS_SIM,
}


def setting(node: str, name: str) -> Setting:
    return next(item for item in NODE_SETTINGS[node] if item.name == name)


@dataclass(frozen=True)
class SuiteFlag:
    """A command-line option of the in-process suite's commands that sets node settings.

    ``sets``: the (node, setting) pairs it sets; the first is the one its help and type come
    from. ``help`` may say ``{default}``: that setting's default. A flag ``always`` given
    sets its settings whether typed or not, its default being the first setting's (the help
    formatter shows it); otherwise the nodes' own defaults apply unless it is typed. ``add``:
    a function adding the option itself (one every command shares)."""

    option: str
    sets: tuple[tuple[str, str], ...]
    help: str = ''
    metavar: str | None = None
    always: bool = False
    type: type | None = None
    add: Callable | None = None

    @property
    def dest(self) -> str:
        return self.option.lstrip('-').replace('-', '_')

    def add_to(self, parser) -> None:
        if self.add is not None:
            return self.add(parser)
        first = setting(*self.sets[0])
        kind = self.type or first.type
        options: dict[str, Any] = {'type': kind} if kind is not str else {}
        if first.choices:
            options['choices'] = first.choices
        if self.metavar:
            options['metavar'] = self.metavar
        default = first.default_value() if self.always else ('' if kind is str else None)
        parser.add_argument(self.option, default=default, help=self.help.format(default=first.default_text()),
                            **options)


SUITE_FLAGS = (
    SuiteFlag('--config-dir', (('ltl_compilation', 'config_dir'), ('sm_generation', 'config_dir'),
                               ('behavior_synthesis_server', 'config_dir')), add=add_config_dir_argument),
    SuiteFlag('--byproducts-dir', (('ltl_synthesis', 'byproducts_dir'),),
              'where the synthesizer writes its byproducts'),
    SuiteFlag('--keep-byproducts', (('ltl_synthesis', 'keep_byproducts'),),
              "keep the newest N spec names' byproduct files (default {default}; 0: none)", metavar='N'),
    SuiteFlag('--backend', (('ltl_synthesis', 'backend'),),
              'synthesizer: our own (builtin) or a slugs executable on PATH', always=True),
    SuiteFlag('--slugs-executable', (('ltl_synthesis', 'slugs_executable'),), 'the executable for --backend slugs',
              always=True),
    SuiteFlag('--synthesis-timeout', (('behavior_synthesis_server', 'synthesis_timeout'), ('ltl_synthesis', 'timeout')),
              'seconds per synthesis', always=True),
    SuiteFlag('--strategy-cache-mb', (('ltl_synthesis', 'strategy_cache_mb'),),
              'MiB of synthesis answers kept for identical requests, least recently used dropped first '
              '(default {default}; 0: no cache)', metavar='MB'),
    SuiteFlag('--strategy-cache-dir', (('ltl_synthesis', 'strategy_cache_dir'),),
              'keep the strategy cache in this private directory too, so that a restarted server finds it '
              '(default: memory only)', metavar='DIR'),
    SuiteFlag('--strategy-cache-key-file', (('ltl_synthesis', 'strategy_cache_key_file'),),
              "the 0600 key that signs the cache directory's entries (default: DIR.key beside it, made on first "
              'use; give a fleet the same file)', metavar='FILE'),
    SuiteFlag('--memory-sum-limit-mb', (('ltl_synthesis', 'memory_sum_limit_mb'),),
              'MiB that the suite and all its synthesis, compilation and repair processes may hold together; '
              'beyond it the working one holding the most is ended (default {default}; 0: none)', metavar='MB'),
    SuiteFlag('--service-timeout', (('behavior_synthesis_server', 'service_timeout'),),
              'seconds to wait for a pipeline service to appear', always=True),
    SuiteFlag('--default-system', (('behavior_synthesis_server', 'default_system'),),
              'system for requests naming none or "system_wide" (default: {default})'),
    SuiteFlag('--robot-state-topic', (('behavior_synthesis_server', 'robot_state_topic'),),
              'where requests naming no initial conditions (or "current") read them (synthesis_msgs/RobotState; '
              'default: {default})'),
    SuiteFlag('--robot-state-timeout', (('behavior_synthesis_server', 'robot_state_timeout'),),
              'seconds to wait for a robot state (default: {default})'),
    SuiteFlag('--repair-time-budget', (('behavior_synthesis_server', 'repair_time_budget'),),
              'seconds to search for verified fixes of a goal refused as impossible, suggested in its result '
              '(default: {default}; 0: none)', metavar='S'),
)


def add_suite_flags(parser) -> None:
    """The suite's settings as command-line options (``serve``, ``gui``, ``demo``, ``execute``, ``export-behavior``)."""
    group = parser.add_argument_group('suite settings')
    for flag in SUITE_FLAGS:
        flag.add_to(group)


def node_overrides(args: argparse.Namespace | None, node: str) -> dict:
    """The settings of ``node`` that the command line ``args`` sets: {name: value}."""
    values = {}
    for flag in SUITE_FLAGS:
        value = getattr(args, flag.dest, None)
        for target, name in flag.sets:
            if target == node and value not in ('', None):
                values[name] = value
    return values


def settings_table() -> str:
    """docs/nodes.md's parameter table: every node's settings, in declaration order."""
    flags = {target: flag.option for flag in SUITE_FLAGS for target in flag.sets}
    rows = ['| node | parameter | type | default | meaning |', '|---|---|---|---|---|']
    for node, settings in NODE_SETTINGS.items():
        for item in settings:
            meaning = item.meaning
            if item.choices:
                meaning += f" (one of {', '.join(f'`{choice}`' for choice in item.choices)})"
            if item.limits:
                meaning += f'; {item.limits}'
            if (node, item.name) in flags:
                meaning += f'; `serve {flags[node, item.name]}`'
            default = item.default_text()
            if not default.startswith('`'):
                default = f'`{default}`' if default else "`''`"
            rows.append(f'| `{node}` | `{item.name}` | {item.type.__name__} | {default} | {meaning} |')
    return '\n'.join(rows) + '\n'


if __name__ == '__main__':
    print(settings_table(), end='')
