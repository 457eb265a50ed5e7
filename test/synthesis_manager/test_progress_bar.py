"""The command line's progress bar: the server's last feedback may reach a client after the
result (a topic and a service travel apart), so the bar ends from the result itself."""

import io

from synthesis_manager.client import SynthesisOutcome
from synthesis_manager.programs.send_goal import ProgressBar


def drawn(stream: io.StringIO) -> list[str]:
    return [line for line in stream.getvalue().split('\r') if line]


def test_a_successful_goal_ends_full_when_its_last_feedback_is_still_on_the_way():
    stream = io.StringIO()
    bar = ProgressBar(stream=stream, width=10)
    bar('Synthesizing', 0.7)
    bar.close(SynthesisOutcome(1, 'SUCCESS', ''))
    bar('Generated a state machine with 3 states', 1.0)  # the late feedback
    lines = drawn(stream)
    assert lines[-1].startswith('[##########] 100% Finished') and lines[-1].endswith('\n')
    assert 'Generated' not in stream.getvalue()  # nothing after the closing newline


def test_a_failed_goal_keeps_the_progress_it_reached():
    stream = io.StringIO()
    bar = ProgressBar(stream=stream, width=10)
    bar('Synthesizing', 0.4)
    bar.close(SynthesisOutcome(6, 'SYNTHESIS_FAILED', 'unrealizable'))
    assert '100%' not in stream.getvalue() and drawn(stream)[-1].startswith('[####......]  40% Synthesizing')


def test_a_bar_already_full_is_not_drawn_twice():
    stream = io.StringIO()
    bar = ProgressBar(stream=stream, width=10)
    bar('Generated a state machine with 3 states', 1.0)
    bar.close(SynthesisOutcome(1, 'SUCCESS', ''))
    bar.close()
    assert len(drawn(stream)) == 1 and stream.getvalue().count('\n') == 1
