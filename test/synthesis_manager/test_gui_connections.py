"""The GUI under descriptor pressure (issue 48, item 6): with a 1,024 open-files limit, 1,100
idle connections left normal requests unanswered and 222 MB of EMFILE tracebacks in 15 s.
Connections are now bounded (the oldest idle one makes room), idle ones time out, and a
repeated error is logged once with a count."""

import contextlib
import resource
import socket
import time

import httpx
import pytest

from suite_processes import BIN, GUI_URL, loopback_domain, started

pytestmark = pytest.mark.ros


def test_a_normal_request_is_answered_beside_1100_idle_connections_under_a_1024_descriptor_limit(tmp_path):
    soft, hard = resource.getrlimit(resource.RLIMIT_NOFILE)
    resource.setrlimit(resource.RLIMIT_NOFILE, (max(soft, min(hard, 4096)), hard))  # this process holds 1,100
    idle = []
    with loopback_domain() as (_, environment):
        with started(['prlimit', '--nofile=1024:1024', '--', BIN / 'behavior-synthesis', 'gui', '--port', '0'],
                     environment) as (gui, output):
            url = output.wait_for(GUI_URL).group(1)
            host, port = httpx.URL(url).host, httpx.URL(url).port
            try:
                for _ in range(1100):
                    connection = socket.create_connection((host, port), timeout=5)
                    idle.append(connection)
                answered = []
                for _ in range(3):
                    began = time.monotonic()
                    response = httpx.get(f'{url}api/info', timeout=10)
                    answered.append(time.monotonic() - began)
                    assert response.status_code == 200
                print(f'normal requests beside 1,100 idle connections: {", ".join(f"{s:.2f}" for s in answered)} s')
                assert max(answered) < 5.0
            finally:
                for connection in idle:
                    with contextlib.suppress(OSError):
                        connection.close()
            assert gui.poll() is None, 'the GUI stopped'
            log = output.text()
            assert len(log) < 100_000, f'{len(log)} characters of log: {log[-500:]}'


def test_a_burst_of_the_same_error_is_logged_once_then_with_its_count(monkeypatch):
    import logging

    from synthesis_manager import http_connections

    clock = [100.0]
    monkeypatch.setattr(http_connections.time, 'monotonic', lambda: clock[0])
    repeats = http_connections.RepeatedRecords(window=10.0)

    def record():
        return logging.LogRecord('asyncio', logging.ERROR, __file__, 1, 'socket.accept() out of system resource',
                                 None, None)
    assert repeats.filter(record())
    assert not any(repeats.filter(record()) for _ in range(5000))
    clock[0] += 11
    later = record()
    assert repeats.filter(later) and '(and 5000 more like it in the last 11 s)' in later.getMessage()
