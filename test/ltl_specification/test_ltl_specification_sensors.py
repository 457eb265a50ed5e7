"""A sensor nothing reports (issue 45, item 4): a capability robot whose spec declares an INPUT
that no assumption ties to anything the robot does got SPEC_UNSYNTHESIZABLE with a core of
formula numbers, and `repair` offered only changes to the task. The diagnosis now names the
sensor, what reads it and the fix in the files' terms, and `repair` proposes a verified,
well-separated assumption for it."""

import yaml

from ltl_specification import compile_task
from ltl_specification.diagnosis import diagnose
from ltl_specification.repair import ADD_ASSUMPTION, TaskRequest, patched_text, propose_repairs, unreported_spec_inputs
from ltl_synthesizer import synthesize
from ltl_synthesizer.synthesizer import solve
from ltl_synthesizer.well_separation import is_well_separated
from respec.robot import robot_system, robot_system_from_files

from courier_robot import LIBRARY, courier

# The courier's door: deliver needs it open, and nothing reports it.
DOOR = {'INPUT': ['door_open']}
DELIVER_THROUGH_THE_DOOR = {'interface': 'LogState', 'parameters': {'text': 'delivering'},
                            'preconditions': ['parcel', 'door_open'], 'postconditions': ['deliver', '!parcel']}


def test_the_diagnosis_names_the_sensor_nothing_reports_what_reads_it_and_the_fix(tmp_path):
    courier(tmp_path, DOOR, deliver=DELIVER_THROUGH_THE_DOOR)
    system = robot_system('courier', tmp_path)
    assert unreported_spec_inputs(system.capabilities) == ['door_open']
    spec = compile_task(system, [], ['deliver'], state_library=LIBRARY)
    assert not synthesize(spec).realizable
    sentence = diagnose(spec).sentence
    assert sentence.startswith("The task needs the sensor 'door_open'") and 'nothing reports it' in sentence
    assert 'next(door_open)' in sentence  # what reads it: deliver's precondition
    assert 'ENV_TRANS' in sentence and 'ENV_LIVENESS: door_open' in sentence


def test_a_reported_sensor_is_not_named(tmp_path):
    courier(tmp_path, {**DOOR, 'ENV_TRANS': ["pick_c' -> door_open'"]}, deliver=DELIVER_THROUGH_THE_DOOR)
    assert unreported_spec_inputs(robot_system('courier', tmp_path).capabilities) == []


def test_repair_proposes_a_verified_well_separated_assumption_about_the_sensor(tmp_path):
    # The courier runs one capability at a time: it waits for the door by looking at it.
    courier(tmp_path, DOOR, deliver=DELIVER_THROUGH_THE_DOOR, look={'interface': 'LogState', 'parameters': {'text': 'looking'}})
    system = robot_system('courier', tmp_path)
    repairs = propose_repairs(system, TaskRequest('courier', (), ('deliver',)), time_budget=20, max_proposals=10,
                              state_library=LIBRARY)
    assumptions = [p for p in repairs.proposals if p.kind == ADD_ASSUMPTION]
    assert assumptions, [p.summary for p in repairs.proposals]
    proposal = assumptions[0]
    assert 'door_open' in proposal.summary and proposal.verified and proposal.config_patch.file.endswith('courier_spec.yaml')
    # Applied to the file, the task synthesizes, and the robot cannot win by cheating.
    files = {**system.files, 'courier_spec.yaml': patched_text(system.files['courier_spec.yaml'], proposal.config_patch)}
    patched = robot_system_from_files('courier', files, str(system.path))
    assert 'door_open' in yaml.safe_dump(yaml.safe_load(files['courier_spec.yaml'])['specs'].get('ENV_LIVENESS'))
    solved = solve(compile_task(patched, [], ['deliver'], state_library=LIBRARY))
    assert solved.realizable and is_well_separated(solved.game)
