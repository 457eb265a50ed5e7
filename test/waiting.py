"""Waiting on events in tests: poll a condition until it holds, with a deadline, and fail naming
what never happened (instead of sleeping for as long as it usually takes)."""

import time

POLL_SECONDS = 0.05


def wait_until(condition, deadline_s: float, what: str, poll_s: float = POLL_SECONDS):
    """``condition()``'s first truthy answer, asked every ``poll_s`` seconds; fails the test
    with "``what`` did not happen within ``deadline_s`` s" when none comes in time."""
    deadline = time.monotonic() + deadline_s
    while True:
        answer = condition()
        if answer:
            return answer
        if time.monotonic() > deadline:
            raise AssertionError(f'{what} did not happen within {deadline_s:g} s')
        time.sleep(poll_s)
