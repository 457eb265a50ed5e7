"""The synthesis service (ltl_synthesizer.service) without ROS: a request's answer and its
byproduct files, the strategy cache's entries (a hit is the fresh answer, under the new spec
name), stops, the backend switch and the diagnosis of an unrealizable specification."""

import contextlib
import json
import threading
import time
from dataclasses import replace
from pathlib import Path

import pytest

from ltl_specification.diagnosis import CORE_NOT_COMPUTED, explain_unsynthesizable, explain_well_separation
from ltl_specification.provenance import provenance_from_json
from ltl_synthesizer.isolated import SynthesisProcesses
from ltl_synthesizer.service import (Explainers, KeptAnswer, SynthesisJob, SynthesisService, SynthesisSettings,
                                     answer_cache, unrealizable_head)
from respec.automaton import automaton_from_strategy
from respec.vocabulary.errors import ErrorCode
from respec.ltl import Next, Not, iff, implies, var
from respec.spec import GR1Specification

EXPLAINERS = Explainers(explain_unsynthesizable, explain_well_separation, provenance_from_json, CORE_NOT_COMPUTED)
# The system follows its input: realizable.
FOLLOWER = GR1Specification(env_props=['x'], sys_props=['y'], sys_trans=[iff(Next(var('y')), Next(var('x')))],
                            sys_liveness=[var('y')], env_liveness=[var('x')])
# The system must keep y and never have it: unrealizable.
IMPOSSIBLE = GR1Specification(env_props=['x'], sys_props=['y'], sys_trans=[Not(Next(var('y')))],
                              sys_liveness=[var('y')])


class FolderStore:
    """Byproduct files in one folder, as the service writes them (synthesis_manager.byproducts'
    protocol: ``open_set(spec_name)`` -> a set with ``write``, ``paths`` and ``name``)."""

    def __init__(self, folder: Path):
        self.folder = folder

    @contextlib.contextmanager
    def open_set(self, spec_name: str):
        yield FolderSet(self.folder, spec_name)


class FolderSet:
    def __init__(self, folder: Path, name: str):
        self.name = name
        self.paths = {kind: folder / f'{name}.{kind}' for kind in ('structuredslugs', 'slugsin', 'json')}

    def write(self, kind: str, text: str) -> Path:
        self.paths[kind].write_text(text)
        return self.paths[kind]


@pytest.fixture(scope='module')
def processes():
    pool = SynthesisProcesses()
    yield pool
    pool.close()


def make_service(tmp_path, processes, cache_bytes: int = 2**20, **settings) -> SynthesisService:
    warnings = []
    service = SynthesisService(lambda: SynthesisSettings(**settings), lambda: FolderStore(tmp_path),
                               answer_cache(cache_bytes), processes, EXPLAINERS, warnings.append)
    service.warnings = warnings
    return service


def job_of(spec: GR1Specification, spec_name: str = 'task', timeout: float = 60.0, **fields) -> SynthesisJob:
    return SynthesisJob(spec.to_text_sections(), spec_name, timeout, time.monotonic() + timeout, **fields)


def test_a_realizable_specification_is_answered_with_its_automaton_and_byproducts(tmp_path, processes):
    service = make_service(tmp_path, processes, check_well_separation=False)
    answer = service.answer(job_of(FOLLOWER))
    assert (answer.code, answer.message, answer.synthesizable) == (ErrorCode.SUCCESS, '', True)
    strategy = json.loads((tmp_path / 'task.json').read_text())
    assert answer.automaton == automaton_from_strategy(strategy, FOLLOWER)
    assert (tmp_path / 'task.slugsin').read_text() == FOLLOWER.to_slugsin()
    assert (tmp_path / 'task.structuredslugs').read_text() == FOLLOWER.to_structuredslugs()


def test_a_kept_answer_is_the_fresh_one_under_the_new_spec_name(tmp_path, processes):
    fresh = make_service(tmp_path / 'fresh', processes, cache_bytes=0)
    cached = make_service(tmp_path / 'cached', processes)
    for folder in ('fresh', 'cached'):
        (tmp_path / folder).mkdir()
    for spec in (FOLLOWER, IMPOSSIBLE):
        first = cached.answer(job_of(spec, 'first_robot'), cached.cached_answer(job_of(spec))[1])
        hit, key = cached.cached_answer(job_of(spec, 'second_robot'))
        assert key is not None and hit is not None
        assert hit == fresh.answer(job_of(spec, 'second_robot'))
        assert first.code == hit.code
        for kind in ('structuredslugs', 'slugsin'):
            assert (tmp_path / 'cached' / f'second_robot.{kind}').read_text() == \
                (tmp_path / 'fresh' / f'second_robot.{kind}').read_text()
    assert cached.cache.statistics.hits == 2 and cached.cache.statistics.misses == 2
    assert unrealizable_head('second_robot') in hit.message and 'first_robot' not in hit.message


def test_kept_answers_survive_their_entry_encoding(tmp_path, processes):
    service = make_service(tmp_path, processes)
    for spec in (FOLLOWER, IMPOSSIBLE):
        answer, kept = service._synthesize(job_of(spec), service.settings(), keep=True)
        assert kept is not None
        entry = kept.to_entry()
        assert all(isinstance(value, bytes) for value in entry.values())
        assert KeptAnswer.from_entry(entry) == kept
        assert kept.answer('task') == answer


def test_the_key_covers_the_settings_that_change_the_answer(tmp_path, processes):
    job = job_of(FOLLOWER)
    key = make_service(tmp_path, processes).cache_key(job)
    assert make_service(tmp_path, processes).cache_key(replace(job, spec_name='other', timeout=1.0)) == key
    for settings in ({'robotics_semantics': False}, {'check_well_separation': False}, {'max_strategy_edges': 5}):
        assert make_service(tmp_path, processes, **settings).cache_key(job) != key
    assert make_service(tmp_path, processes).cache_key(replace(job, provenance='{}')) != key
    assert make_service(tmp_path, processes, backend='slugs').cache_key(job) is None
    assert make_service(tmp_path, processes, cache_bytes=0).cache_key(job) is None


def test_a_stopped_job_says_why_and_is_not_kept(tmp_path, processes):
    service = make_service(tmp_path, processes)
    cancelled = job_of(FOLLOWER, cancel=threading.Event())
    cancelled.cancel.set()
    answer = service.answer(cancelled)
    assert (answer.code, answer.message) == (ErrorCode.PREEMPTED, 'synthesis stopped: cancelled (time limit 60 s)')
    late = job_of(FOLLOWER, timeout=2.0)
    late.deadline = time.monotonic() - 1
    assert service.answer(late).code == ErrorCode.SYNTHESIS_TIMEOUT
    assert len(service.cache) == 0


def test_an_unknown_backend_is_a_synthesis_failure_naming_it(tmp_path, processes):
    answer = make_service(tmp_path, processes, backend='nusmv').answer(job_of(FOLLOWER))
    assert answer.code == ErrorCode.SYNTHESIS_FAILED and "unknown backend 'nusmv'" in answer.message


def test_an_unrealizable_specification_is_diagnosed_by_its_formulas(tmp_path, processes):
    answer = make_service(tmp_path, processes).answer(job_of(IMPOSSIBLE, 'impossible'))
    assert answer.code == ErrorCode.SPEC_UNSYNTHESIZABLE and not answer.synthesizable
    assert answer.automaton is None
    assert unrealizable_head('impossible') in answer.message
    assert explain_unsynthesizable('', IMPOSSIBLE, None).splitlines()[0] in answer.message


def test_unreadable_provenance_is_warned_about_and_the_formulas_explain(tmp_path, processes):
    service = make_service(tmp_path, processes)
    answer = service.answer(job_of(IMPOSSIBLE, provenance='not json'))
    assert answer.code == ErrorCode.SPEC_UNSYNTHESIZABLE
    # read once for the job (the well-separation check and the diagnosis share it): one warning
    assert sum(warning.startswith('request.provenance ignored') for warning in service.warnings) == 1
    assert service.answer(job_of(CHEATING, provenance='not json')).message == explain_well_separation(CHEATING)
    assert sum(warning.startswith('request.provenance ignored') for warning in service.warnings) == 2


# y forces the next x, which the environment promises to leave infinitely often: a controller
# that keeps y wins by cheating (not well-separated), and is realizable.
CHEATING = GR1Specification(env_props=['x'], sys_props=['y'], env_trans=[implies(var('y'), Next(var('x')))],
                            env_liveness=[Not(var('x'))], sys_liveness=[var('y')])


def test_the_well_separation_warning_comes_from_the_synthesis_child_as_from_a_check_of_its_own(tmp_path, processes):
    # The builtin backend checks the game its child solved (issue 44): the same warning.
    answer = make_service(tmp_path, processes).answer(job_of(CHEATING))
    assert (answer.code, answer.synthesizable) == (ErrorCode.SUCCESS, True)
    assert answer.message == explain_well_separation(CHEATING) != ''
    assert make_service(tmp_path, processes).answer(job_of(FOLLOWER)).message == ''


def test_a_well_separation_check_out_of_time_leaves_the_automaton_unwarned_and_unkept(tmp_path, processes):
    service = make_service(tmp_path, processes)
    answer, kept = service._synthesize(job_of(CHEATING, diagnosis_timeout=1e-9), service.settings(), keep=True)
    assert (answer.code, answer.message, answer.synthesizable) == (ErrorCode.SUCCESS, '', True)
    assert answer.automaton is not None and kept is None
    assert service.warnings == ['well-separation not checked: synthesis timeout while checking well-separation '
                                '(1 inputs and 1 outputs)']
