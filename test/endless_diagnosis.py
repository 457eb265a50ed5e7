"""A diagnosis that never ends by itself, for the server's diagnosis tests.

The server runs its diagnosis in a child process, where a test's monkeypatching cannot reach:
tests point the server at this module (importable through PYTHONPATH). It writes its process
id to $ENDLESS_DIAGNOSIS_PID_FILE, so that a test can check the process is gone afterwards.
"""

import os


def endless_diagnosis(*_, **__):
    with open(os.environ['ENDLESS_DIAGNOSIS_PID_FILE'], 'w') as pid_file:
        pid_file.write(str(os.getpid()))
    while True:  # ignores its deadline: only killing the process ends it
        pass
