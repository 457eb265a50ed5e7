"""Each client's share of a shared server (issue 48, item 1): the sender read from the goal id,
bounds on a client's running goals and on their time limits together, the waiting order."""

import os

import pytest

from synthesis_manager.client_shares import ClientShares, goal_origin, new_origin, tagged_goal_id
from synthesis_manager.limits import BusyError

pytestmark = pytest.mark.ros


def test_our_goal_ids_name_their_client_and_others_are_clients_of_their_own():
    origin = new_origin()
    first, second = tagged_goal_id(origin), tagged_goal_id(origin)
    assert first != second and len(first) == 16
    assert goal_origin(first) == goal_origin(second) == origin.hex()
    assert first[6] >> 4 == 8 and first[8] >> 6 == 2  # an RFC 9562 version-8 UUID
    assert goal_origin(tagged_goal_id(new_origin())) != origin.hex()
    random_v4 = bytearray(os.urandom(16))
    random_v4[6] = 0x40 | (random_v4[6] & 0x0F)
    random_v4[8] = 0x80 | (random_v4[8] & 0x3F)
    assert goal_origin(bytes(random_v4)) == bytes(random_v4).hex()  # rclpy's own ids: one client per goal


def test_a_client_runs_at_most_max_running_goals_and_the_rest_wait_in_order():
    shares = ClientShares(max_running=2, max_seconds=1000, max_waiting=10)
    tickets = [shares.join('a', 10) for _ in range(4)]
    assert [shares.admit(ticket) for ticket in tickets] == [0, 0, 1, 2]
    other = shares.join('b', 10)
    assert shares.admit(other) == 0  # another client is not held up
    shares.leave(tickets[0])
    assert shares.admit(tickets[3]) == 2 and shares.admit(tickets[2]) == 0 and shares.admit(tickets[3]) == 1
    assert shares.running('a') == 2


def test_the_time_limits_of_a_clients_running_goals_are_bounded_together():
    shares = ClientShares(max_running=8, max_seconds=1200, max_waiting=10)
    runaways = [shares.join('a', 300) for _ in range(8)]
    assert [shares.admit(ticket) for ticket in runaways] == [0, 0, 0, 0, 1, 2, 3, 4]
    huge = ClientShares(max_running=8, max_seconds=100, max_waiting=10)
    alone = huge.join('c', 500)
    assert huge.admit(alone) == 0  # one goal always runs, whatever its limit


def test_beyond_max_waiting_a_clients_next_goal_is_busy_and_leaving_forgets_it():
    shares = ClientShares(max_running=1, max_seconds=100, max_waiting=2)
    running = shares.join('a', 1)
    assert shares.admit(running) == 0
    first, second = shares.join('a', 1), shares.join('a', 1)
    with pytest.raises(BusyError, match='max_client_waiting 2'):
        shares.join('a', 1)
    shares.leave(first)  # gave up waiting (its deadline, a cancel)
    assert shares.admit(second) == 1
    shares.leave(running)
    shares.leave(second)
    assert shares.running('a') == 0 and shares.join('a', 1) is not None
