"""Each formula family of the activation-outcomes paradigm against hand-derived formulas."""

from ltl_specification import activation_outcomes as ao
from respec.ltl import to_infix, to_prefix

CF = ['completed', 'failed']
CFP = ['completed', 'failed', 'preempted']


def infix(formulas):
    return [to_infix(f) for f in formulas]


def test_proposition_names():
    assert ao.activation('grasp') == 'grasp_a'
    assert ao.outcome_proposition('grasp', 'failed') == 'grasp_f'
    assert ao.outcome_proposition('grasp', 'preempted') == 'grasp_p'
    assert ao.memory('grasp') == 'grasp_m'


def test_eq3_deactivation_after_each_outcome():
    assert infix(ao.deactivation_after_outcome('dance', CF)) == [
        'dance_a & next(dance_c) -> next(!dance_a)',
        'dance_a & next(dance_f) -> next(!dance_a)',
    ]


def test_eq4_outcome_mutual_exclusion_uses_next():
    assert infix(ao.outcome_mutual_exclusion('dance', CFP)) == [
        'next(dance_c) -> next(!dance_f) & next(!dance_p)',
        'next(dance_f) -> next(!dance_c) & next(!dance_p)',
        'next(dance_p) -> next(!dance_c) & next(!dance_f)',
    ]
    assert ao.outcome_mutual_exclusion('dance', ['completed']) == []


def test_eq5_outcome_constraints():
    assert infix(ao.outcome_constraints('dance', CF)) == [
        '!dance_c & !dance_a -> next(!dance_c)',
        '!dance_f & !dance_a -> next(!dance_f)',
    ]


def test_eq6_outcome_persistence():
    assert infix(ao.outcome_persistence('dance', CF)) == [
        'dance_c & !dance_a -> next(dance_c)',
        'dance_f & !dance_a -> next(dance_f)',
    ]


def test_eq7_action_fairness():
    assert to_infix(ao.action_fairness('dance', CF)) == \
        'dance_a & (next(dance_c) | next(dance_f)) | !dance_a'
    assert to_infix(ao.action_fairness('dance', ['completed'])) == 'dance_a & next(dance_c) | !dance_a'


def test_eq7_retry_variant_promises_completion():
    assert to_infix(ao.action_completion_fairness('dance')) == '!dance_a | next(dance_c)'


def test_eq8_preconditions():
    assert infix(ao.preconditions('pickup', ['template', 'manipulate'])) == \
        ['!template_c | !manipulate_c -> !pickup_a']
    assert infix(ao.preconditions('look', ['stand'])) == ['!stand_c -> !look_a']
    assert ao.preconditions('template', []) == []


def test_mode_activation_phi_and_none():
    modes = ['a', 'b', 'c']
    assert to_infix(ao.mode_activation('b', modes)) == 'b_a & !a_a & !c_a'
    assert to_infix(ao.no_mode_activation(modes)) == '!a_a & !b_a & !c_a'


ADJ = {'r1': ('r1', 'r2'), 'r2': ('r2', 'r1')}


def test_eq9_mode_topology():
    assert infix(ao.mode_topology(ADJ)) == [
        'next(r1_c) -> next(r1_a & !r2_a) | next(r2_a & !r1_a) | next(!r1_a & !r2_a)',
        'next(r2_c) -> next(r2_a & !r1_a) | next(r1_a & !r2_a) | next(!r1_a & !r2_a)',
    ]


def test_eq9_one_way_edge():
    adjacency = {'r1': ('r1', 'r2'), 'r2': ('r2',)}
    assert infix(ao.mode_topology(adjacency))[1] == 'next(r2_c) -> next(r2_a & !r1_a) | next(!r1_a & !r2_a)'


def test_eq10_mode_mutual_exclusion():
    assert infix(ao.mode_mutual_exclusion(['r1', 'r2', 'r3'])) == [
        'next(r1_c) <-> next(!r2_c) & next(!r3_c)',
        'next(r2_c) <-> next(!r1_c) & next(!r3_c)',
        'next(r3_c) <-> next(!r1_c) & next(!r2_c)',
    ]
    assert infix(ao.mode_mutual_exclusion(['only'])) == ['next(only_c)']


def test_eq11_single_step_change_and_self_loop():
    assert infix(ao.single_step_mode_change(ADJ, CF)) == [
        'r1_c & r1_a & !r2_a -> next(r1_c) | next(r1_f)',
        'r1_c & r2_a & !r1_a -> next(r1_c) | next(r2_c) | next(r2_f)',
        'r2_c & r2_a & !r1_a -> next(r2_c) | next(r2_f)',
        'r2_c & r1_a & !r2_a -> next(r2_c) | next(r1_c) | next(r1_f)',
    ]


def test_eq12_mode_outcome_persistence():
    assert infix(ao.mode_outcome_persistence(['r1', 'r2'], CF)) == [
        'r1_c & !r1_a & !r2_a -> next(r1_c)',
        'r1_f & !r1_a & !r2_a -> next(r1_f)',
        'r2_c & !r1_a & !r2_a -> next(r2_c)',
        'r2_f & !r1_a & !r2_a -> next(r2_f)',
    ]


def test_eq13_mode_fairness_is_one_formula():
    assert to_infix(ao.mode_fairness(['r1', 'r2'], CF)) == (
        'r1_a & !r2_a & (next(r1_c) | next(r1_f)) | r2_a & !r1_a & (next(r2_c) | next(r2_f))'
        ' | !r1_a & !r2_a')
    assert to_infix(ao.mode_completion_fairness(['r1', 'r2'])) == \
        'r1_a & !r2_a & next(r1_c) | r2_a & !r1_a & next(r2_c) | !r1_a & !r2_a'


def test_eq14_environment_initial_conditions():
    assert infix(ao.environment_initial_conditions(['stand', 'grasp'], ['stand'], CF)) == \
        ['stand_c', '!stand_f', '!grasp_c', '!grasp_f']


def test_eq15_system_initial_conditions():
    assert infix(ao.system_initial_conditions(['stand', 'grasp'])) == ['!stand_a', '!grasp_a']


def test_eq16_and_sm_outcome_initial_conditions():
    assert infix(ao.goal_memory_initial_conditions(['g1', 'g2'])) == ['!g1_m', '!g2_m']
    assert infix(ao.sm_outcome_initial_conditions(['finished', 'failed'])) == ['!finished', '!failed']


def test_eq17_goal_memory():
    assert infix(ao.goal_memory(['g1', 'g2'])) == [
        'next(g1_c) | g1_m <-> next(g1_m)',
        'next(g2_c) | g2_m <-> next(g2_m)',
    ]


def test_eq18_sm_outcomes():
    assert to_infix(ao.success_outcome(['g1', 'g2'])) == 'finished <-> g1_m & g2_m'
    assert to_infix(ao.failure_outcome(['a_f', 'b_f'])) == 'failed <-> a_f | b_f'
    assert infix(ao.sm_outcome_persistence(['finished', 'failed'])) == \
        ['finished -> next(finished)', 'failed -> next(failed)']


def test_eq19_single_liveness():
    assert to_infix(ao.single_liveness(['finished', 'failed'])) == 'finished | failed'
    assert to_infix(ao.single_liveness(['finished'])) == 'finished'


def test_eq20_strict_goal_order_chains_memories():
    assert infix(ao.strict_goal_order(['g1', 'g2', 'g3'])) == [
        'g1_a & next(g1_c) | g1_m <-> next(g1_m)',
        'g2_a & next(g2_c) & g1_m | g2_m <-> next(g2_m)',
        'g3_a & next(g3_c) & g2_m | g3_m <-> next(g3_m)',
    ]


def test_formulas_print_as_slugsin():
    formula = ao.deactivation_after_outcome('dance', ['completed'])[0]
    assert to_prefix(formula) == "| ! & dance_a dance_c' ! dance_a'"
