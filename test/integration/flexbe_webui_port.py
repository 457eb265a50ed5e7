"""The port the FlexBE WebUI 4.0.3 page needs (8000), taken in turns by runs on one machine."""

import contextlib
import fcntl
import socket
import tempfile
import time
from pathlib import Path

import pytest


# The WebUI 4.0.3 page opens its topic subscriptions at ws://localhost:8000 whatever port it is
# served from, so it only fully works on 8000; runs on one machine take turns (a lock file).
WEBUI_PORT = 8000


@contextlib.contextmanager
def port_for_this_run(port: int, timeout: float = 600):
    """Wait until no other run on this machine uses ``port``, then hold it for this run."""
    with open(Path(tempfile.gettempdir()) / f'flexbe_webui_port_{port}.lock', 'w') as lock:
        deadline = time.monotonic() + timeout
        while True:
            try:
                fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
                break
            except BlockingIOError:
                if time.monotonic() > deadline:
                    pytest.fail(f'port {port} stayed taken by another FlexBE WebUI run for {timeout:g} s')
                time.sleep(1.0)
        with socket.socket() as probe:
            probe.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)  # as uvicorn binds it
            try:
                probe.bind(('127.0.0.1', port))
            except OSError:
                pytest.fail(f'port {port} is in use; the FlexBE WebUI 4.0.3 page needs it')
        yield port
