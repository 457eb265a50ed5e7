"""A refused big goal gives its memory back (issue 48, item 2): a 50 MB goal list left the
server 145 MiB larger for as long as rclpy kept the goal (its result_retention), and five in a
row 290 MiB. Now a finished goal's request is emptied and freed heap pages are returned."""

import time

import pytest
from synthesis_manager.client import make_flexbe_goal, make_goal
from suite_processes import serve_with_clients

pytestmark = pytest.mark.ros
KEPT_AT_MOST_MIB = 100


def resident_mib(pid: int) -> float:
    with open(f'/proc/{pid}/status') as status:
        return next(int(line.split()[1]) for line in status if line.startswith('VmRSS')) / 1024


def test_refused_big_goals_leave_the_server_no_larger_than_100_mib_five_seconds_later(tmp_path):
    with serve_with_clients(tmp_path, 'behavior_synthesis', 'flexbe_synthesis') as (server, (client, flexbe)):
        for _ in range(2):  # imports, discovery, the first synthesis process
            assert client.run(make_goal('atlas', ['stand_prep'], ['look_down'])).succeeded
        before = resident_mib(server.pid)
        for _ in range(3):
            refused = flexbe.run(make_flexbe_goal('atlas', ['stand_prep'], ['g' * 5000] * 10_000), timeout=120)
            assert 'over 4194304 bytes' in refused.message
        answered = time.monotonic()
        while (kept := resident_mib(server.pid) - before) > KEPT_AT_MOST_MIB \
                and time.monotonic() - answered < 5.0:  # the issue's measure: what is kept 5 s later
            time.sleep(0.1)
        print(f'server RSS {before:.0f} MiB before, +{kept:.0f} MiB '
              f'{time.monotonic() - answered:.1f} s after three refused 50 MB goals')
        assert kept <= KEPT_AT_MOST_MIB, f'+{kept:.0f} MiB 5 s after the answers'
        assert client.run(make_goal('atlas', ['stand_prep'], ['look_down', 'pickup_object'])).succeeded
