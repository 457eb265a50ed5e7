"""The pre-check for capability robots (ltl_specification.capability_precheck): a goal no capability
can make true, an initial condition that names nothing, a precondition nothing establishes, each
refused before synthesis with its error code and one sentence naming the entry to change. CNU's 11
example pairs, which all synthesize, pass it (test/integration/test_cnu_capabilities.py)."""

import os
import subprocess
import sys
from pathlib import Path

import pytest

from ltl_specification import InvalidGoalsError, UnknownPropositionError, compile_task
from ltl_synthesizer import synthesize
from respec.robot.cnu import CapabilityConfigError
from respec.robot import robot_system

from courier_robot import LIBRARY, courier

ROOT = Path(__file__).resolve().parents[2]


def compiled(config_dir, initial_conditions, goals):
    return compile_task(robot_system('courier', config_dir), initial_conditions, goals, state_library=LIBRARY)


def test_a_possible_task_passes_and_synthesizes(tmp_path):
    spec = compiled(courier(tmp_path), [], ['deliver', 'bin=1', '!parcel'])
    assert synthesize(spec).realizable


@pytest.mark.parametrize('goal, unset', [('pick', 'pick_m true'), ('bin=2', 'bin to 2'),
                                          ('signature', 'signature_m true')])
def test_a_goal_no_capability_makes_true_is_named_with_the_file_to_change(tmp_path, goal, unset):
    with pytest.raises(InvalidGoalsError) as refused:
        compiled(courier(tmp_path), [], ['deliver', goal])
    assert refused.value.code == 'INVALID_GOALS' and refused.value.item == goal
    assert str(refused.value).startswith(f"Goal '{goal}' can never be reached: no capability sets {unset} ")
    assert 'courier_capabilities.yaml' in str(refused.value) and str(refused.value).count('. ') == 0


def test_a_goal_that_holds_initially_is_possible(tmp_path):
    assert compiled(courier(tmp_path), ['signature'], ['signature', 'deliver'])
    assert compiled(courier(tmp_path, {'SYS_INIT': ['bin=2']}), [], ['bin=2'])


def test_an_initial_condition_that_names_nothing_is_named_with_its_entry(tmp_path):
    with pytest.raises(UnknownPropositionError) as request:
        compiled(courier(tmp_path), ['parcle'], ['deliver'])
    assert request.value.code == 'UNKNOWN_PROPOSITION' and request.value.item == 'parcle'
    assert str(request.value).startswith("Initial condition 'parcle' names nothing of courier (no capability, ")
    assert "called parcle; did you mean parcel?): change the request's initial conditions" in str(request.value)
    with pytest.raises(UnknownPropositionError) as spec_file:
        compiled(courier(tmp_path, {'SYS_INIT': ['!ghost']}), [], ['deliver'])
    assert spec_file.value.item == '!ghost' and 'change specs.SYS_INIT in courier_spec.yaml' in str(spec_file.value)


def test_a_precondition_nothing_establishes_names_its_capability(tmp_path):
    unsigned = {'interface': 'LogState', 'parameters': {'text': 'signing'}, 'preconditions': ['signature | bin=2'],
                'postconditions': ['parcel']}
    with pytest.raises(CapabilityConfigError) as refused:
        compiled(courier(tmp_path, sign=unsigned), [], ['deliver'])
    assert refused.value.code == 'ABSTRACTION_CONFIG_INVALID' and refused.value.item == 'sign.preconditions'
    assert str(refused.value).startswith("Capability 'sign' can never start: nothing establishes its precondition "
                                         "'signature | bin=2' (signature_m true is set by no postcondition")
    assert 'change sign.preconditions or add a postcondition that sets it in courier_capabilities.yaml' \
        in str(refused.value)
    # An initial value establishes it: the request's initial condition, as the compiler sets it.
    assert compiled(courier(tmp_path, sign=unsigned), ['signature'], ['deliver'])


@pytest.mark.flexbe
def test_the_command_line_says_the_compilers_sentence(tmp_path, flexbe):
    """`behavior-synthesis compile` exits 1 with the same sentence, code and item on one line."""
    courier(tmp_path)
    with pytest.raises(InvalidGoalsError) as refused:
        compiled(tmp_path, [], ['deliver', 'pick'])
    environment = dict(os.environ, PYTHONPATH=str(ROOT), AMENT_PREFIX_PATH=str(flexbe))
    result = subprocess.run([str(Path(sys.executable).parent / 'behavior-synthesis'), 'compile', '--config-dir',
                             str(tmp_path), '--system', 'courier', '--goals', 'deliver,pick'],
                            env=environment, capture_output=True, text=True, timeout=120)
    assert result.returncode == 1 and result.stdout == ''
    assert result.stderr.strip().splitlines() == [f"error: INVALID_GOALS: {refused.value} [item: 'pick']"]
