"""Unit tests of atlas_sim's physics-free parts: config, discrete rules, faults, IK."""

import math
import subprocess
import sys
from pathlib import Path

import pytest

from atlas_sim.simulator.config import DEFAULT_CONFIG, SystemConfig, load_system_config
from respec.robot.abstraction import AbstractionConfigError
from atlas_sim.simulator.discrete import COMPLETED, FAILED, DiscreteSemantics
from atlas_sim.simulator.faults import FaultInjector, FaultSpec
from atlas_sim.simulator.kinematics import LegGeometry, POSTURES, sagittal_leg_ik
from atlas_sim.simulator.motions import GaitMotion, KeyframeMotion, OperatorInputMotion, build_motion

REPO = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def atlas():
    return load_system_config(DEFAULT_CONFIG)


@pytest.fixture
def semantics(atlas):
    sim = atlas.simulation
    return DiscreteSemantics(atlas.abstraction, sim.invalidations)


def run(semantics, state, name, outcome=COMPLETED):
    """Start and finish one request at the discrete level; returns the refusal."""
    refusal = semantics.refusal(state, name)
    if refusal is None:
        semantics.begin(state, name)
        semantics.finish(state, name, outcome)
    return refusal


# ------------------------------------------------------------------ config
def test_atlas_config_has_a_simulation_entry_for_every_capability(atlas):
    sim = atlas.simulation
    assert (sim.initial_mode or atlas.abstraction.initial_mode) == "stand_prep"
    assert set(sim.modes) == set(atlas.abstraction.control_modes)
    assert set(sim.actions) == set(atlas.abstraction.actions)
    assert sim.scenario.operator_inputs == {"object_template": True, "target_pose": True}


def test_every_configured_motion_builds(atlas):
    geometry = LegGeometry()
    entries = {**atlas.simulation.modes, **atlas.simulation.actions}
    motions = {name: build_motion(entry, geometry) for name, entry in entries.items()}
    assert isinstance(motions["walk"], GaitMotion)
    assert isinstance(motions["look_down"], KeyframeMotion)
    assert isinstance(motions["object_template"], OperatorInputMotion)
    assert motions["pickup_object"].effects["holding_object"] is True
    assert all(m.duration > 0 for m in motions.values())


def test_unknown_motion_kind_is_rejected():
    with pytest.raises(ValueError, match="unknown motion kind"):
        build_motion({"motion": "teleport"}, LegGeometry())


def test_discrete_modules_do_not_import_mujoco():
    code = (
        "import sys, atlas_sim, atlas_sim.simulator.discrete, atlas_sim.simulator.faults, atlas_sim.simulator.motions;"
        "print('mujoco' in sys.modules)"
    )
    out = subprocess.run([sys.executable, "-c", code], cwd=REPO, capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


# ---------------------------------------------------------- control modes
def test_initial_state_is_the_configured_mode(semantics):
    state = semantics.initial_state("stand_prep")
    assert state.mode == "stand_prep" and state.pending_mode is None and not state.completed


@pytest.mark.parametrize(
    "current, target, allowed",
    [
        ("stand_prep", "stand", True),
        ("stand_prep", "stand_prep", True),  # self-loop implied
        ("stand_prep", "manipulate", False),
        ("stand", "walk", True),
        ("walk", "manipulate", False),
        ("stand", "stand_prep", False),
    ],
)
def test_mode_transitions_follow_the_transition_system(semantics, current, target, allowed):
    state = semantics.initial_state(current)
    refusal = semantics.refusal(state, target)
    assert (refusal is None) == allowed
    if not allowed:
        assert "not allowed" in refusal


def test_mode_changes_only_when_the_transition_completes(semantics):
    state = semantics.initial_state("stand")
    semantics.begin(state, "manipulate")
    assert state.mode == "stand" and state.pending_mode == "manipulate"
    assert "in progress" in semantics.refusal(state, "walk")
    assert "stand" in semantics.refusal(state, "look_down")  # mode precondition is pending
    semantics.finish(state, "manipulate", FAILED)
    assert state.mode == "stand" and state.pending_mode is None
    run(semantics, state, "manipulate")
    assert state.mode == "manipulate"


# ---------------------------------------------------------------- actions
def test_action_needs_its_mode_and_prior_actions(semantics):
    state = semantics.initial_state("stand")
    refusal = semantics.refusal(state, "pickup_object")
    assert "object_template" in refusal and "manipulate" in refusal
    assert run(semantics, state, "object_template") is None
    assert "manipulate" in semantics.refusal(state, "pickup_object")
    run(semantics, state, "manipulate")
    assert semantics.refusal(state, "pickup_object") is None


def test_running_capability_cannot_start_twice(semantics):
    state = semantics.initial_state("stand")
    semantics.begin(state, "look_down")
    assert "already running" in semantics.refusal(state, "look_down")


def test_failed_attempt_invalidates_the_action_and_its_dependents(semantics):
    state = semantics.initial_state("stand")
    for name in ("object_template", "pregrasp_pose", "pregrasp_plan"):
        run(semantics, state, name)
    assert state.completed_actions() == ["object_template", "pregrasp_pose", "pregrasp_plan"]
    run(semantics, state, "object_template", FAILED)
    assert state.completed_actions() == []


def test_configured_invalidation_consumes_the_footstep_plan(semantics):
    state = semantics.initial_state("stand")
    for name in ("target_pose", "footstep_goal", "footstep_plan", "footstep_execution"):
        assert run(semantics, state, name) is None
    assert "footstep_plan" not in state.completed
    assert "footstep_execution" in state.completed
    assert "footstep_plan" in semantics.refusal(state, "footstep_execution")


def test_unknown_names_are_refused_or_rejected(semantics):
    state = semantics.initial_state("stand")
    assert "unknown capability" in semantics.refusal(state, "fly")
    with pytest.raises(AbstractionConfigError, match="unknown precondition"):
        SystemConfig.from_dict({"abstraction": {"control_modes": {"a": []}, "actions": {"x": ["nope"]}}})


# ----------------------------------------------------------------- faults
def test_fault_always_and_first_k():
    injector = FaultInjector(faults={"a": FaultSpec(always=True), "b": FaultSpec(fail_first=2)})
    assert all(injector.fault_for_attempt("a") for _ in range(5))
    assert [bool(injector.fault_for_attempt("b")) for _ in range(4)] == [True, True, False, False]
    assert injector.fault_for_attempt("c") is None
    assert injector.attempts("b") == 4


def test_probabilistic_faults_are_reproducible_per_seed():
    def outcomes(seed, interleave=False):
        injector = FaultInjector(seed, {"a": FaultSpec(probability=0.5)})
        result = []
        for _ in range(40):
            if interleave:
                injector.fault_for_attempt("other")
            result.append(injector.fault_for_attempt("a") is None)
        return result

    assert outcomes(7) == outcomes(7)
    assert outcomes(7) == outcomes(7, interleave=True)  # independent of other capabilities
    assert outcomes(7) != outcomes(8)
    assert 5 < sum(outcomes(7)) < 35


def test_fault_spec_validation():
    with pytest.raises(ValueError):
        FaultSpec(probability=1.5)
    with pytest.raises(ValueError):
        FaultSpec.from_dict({"sometimes": True})


# ------------------------------------------------------------- kinematics
@pytest.mark.parametrize("forward, down", [(0.0, 0.75), (0.2, 0.7), (-0.15, 0.6), (0.0, 0.57)])
def test_leg_ik_reaches_the_target_with_a_flat_foot(forward, down):
    geometry = LegGeometry()
    hip, knee, ankle = sagittal_leg_ik(geometry, forward, down)
    # Forward kinematics: positive pitch swings the limb backwards (about +y).
    thigh_angle = -hip
    shin_angle = thigh_angle - knee
    x = geometry.thigh_length * math.sin(thigh_angle) + geometry.shin_length * math.sin(shin_angle)
    z = geometry.thigh_length * math.cos(thigh_angle) + geometry.shin_length * math.cos(shin_angle)
    assert x == pytest.approx(forward, abs=1e-9)
    assert z == pytest.approx(down, abs=1e-9)
    assert hip + knee + ankle == pytest.approx(0.0, abs=1e-12)
    assert knee >= 0.0


def test_crouch_is_lower_than_stand():
    geometry = LegGeometry()
    assert POSTURES["crouch"].hip_height < POSTURES["stand"].hip_height - 0.1
    assert POSTURES["crouch"].targets(geometry)["left_knee"] > POSTURES["stand"].targets(geometry)["left_knee"]


def test_simulation_section_typos_are_rejected():
    from atlas_sim.simulator.config import SimulationConfig

    with pytest.raises(ValueError, match="unknown keys"):
        SimulationConfig.from_dict({"fautls": {}})


@pytest.mark.parametrize("section", [5, ["modes"], "modes"])
def test_a_simulation_section_that_is_no_mapping_is_refused_naming_it(section):
    from atlas_sim.simulator.config import SimulationConfig, SimulationConfigError

    with pytest.raises(SimulationConfigError, match="must be a mapping") as raised:
        SimulationConfig.from_dict(section)
    assert raised.value.item == "simulation"
