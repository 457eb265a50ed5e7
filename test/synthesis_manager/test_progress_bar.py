"""The command line's progress bar: the server's last feedback may reach a client after the
result (a topic and a service travel apart), so the bar's full line is drawn from the result,
the same whichever comes first."""

import io

import pytest

from synthesis_manager.client import SynthesisOutcome
from synthesis_manager.programs.send_goal import ProgressBar

MACHINE = [{'state_path': '/look_down', 'state_class': 'LookDownState'}]  # one state's StateInstantiation entry
LAST_FEEDBACK = ('Generated a state machine with 1 states', 1.0)  # the server's, just before its result


def drawn(stream: io.StringIO) -> list[str]:
    return [line for line in stream.getvalue().split('\r') if line]


@pytest.mark.parametrize('last_feedback_first', [True, False])
def test_a_successful_goal_ends_with_the_same_full_line_whether_its_last_feedback_comes_first_or_not(
        last_feedback_first):
    stream = io.StringIO()
    bar = ProgressBar(stream=stream, width=10)
    bar('Generating the state machine', 0.7)
    if last_feedback_first:
        bar(*LAST_FEEDBACK)
    bar.close(SynthesisOutcome(1, 'SUCCESS', '', states=MACHINE))
    if not last_feedback_first:
        bar(*LAST_FEEDBACK)
    assert drawn(stream) == ['[#######...]  70% ' + f'{"Generating the state machine":<60}',
                             '[##########] 100% ' + f'{"Generated a state machine with 1 states":<60}' + '\n']


def test_a_goal_that_stops_before_generation_ends_full_when_it_succeeds():
    stream = io.StringIO()
    bar = ProgressBar(stream=stream, width=10)
    bar('Compiling the specification', 0.1)
    bar.close(SynthesisOutcome(1, 'SUCCESS', ''))  # --compile-only: no state machine
    assert drawn(stream)[-1].startswith('[##########] 100% Finished')


def test_a_failed_goal_keeps_the_progress_it_reached():
    stream = io.StringIO()
    bar = ProgressBar(stream=stream, width=10)
    bar('Synthesizing', 0.4)
    bar.close(SynthesisOutcome(6, 'SYNTHESIS_FAILED', 'unrealizable'))
    bar.close()
    assert '100%' not in stream.getvalue() and drawn(stream)[-1].startswith('[####......]  40% Synthesizing')
    assert stream.getvalue().count('\n') == 1
