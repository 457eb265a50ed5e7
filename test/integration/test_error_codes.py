"""One error idiom: every user-facing error is a CodedError subclass whose class-level
``code`` is an ErrorCode; ErrorCode, the .msg file and the generated message agree."""

from __future__ import annotations

import ast
import importlib
import re
from pathlib import Path

import pytest

from respec.vocabulary.errors import CodedError, ErrorCode
from synthesis_msgs.msg import SynthesisErrorCodes

ROOT = Path(__file__).resolve().parents[2]
PACKAGES = ('respec', 'ltl_specification', 'ltl_synthesizer', 'sm_generation', 'atlas_sim', 'synthesis_manager')
MSG_CONSTANTS = dict(re.findall(r'^int32 ([A-Z_]+) = (-?\d+)', (ROOT / 'synthesis_msgs' / 'msg' /
                                                                 'SynthesisErrorCodes.msg').read_text(), re.M))


def project_modules():
    """Every module of the project's packages (ROS package folders inside them excepted)."""
    ros_folders = [path.parent for package in PACKAGES for path in (ROOT / package).rglob('package.xml')]
    names = []
    for package in PACKAGES:
        for path in sorted((ROOT / package).rglob('*.py')):
            if path.stem == '__main__' or any(folder in path.parents for folder in ros_folders):
                continue
            parts = path.relative_to(ROOT).with_suffix('').parts
            names.append('.'.join(parts[:-1] if parts[-1] == '__init__' else parts))
    return [importlib.import_module(name) for name in names]


def all_subclasses(cls):
    for sub in cls.__subclasses__():
        yield sub
        yield from all_subclasses(sub)


MODULES = project_modules()
CODED = sorted({cls for cls in all_subclasses(CodedError)
                if cls.__module__.split('.')[0] in PACKAGES}, key=lambda c: f'{c.__module__}.{c.__qualname__}')


def test_the_msg_file_and_the_generated_constants_agree():
    assert MSG_CONSTANTS and all(getattr(SynthesisErrorCodes, name) == int(value)
                                 for name, value in MSG_CONSTANTS.items())


def test_error_code_is_the_msg_files_constants_by_name_and_number():
    assert {code.name: code.number for code in ErrorCode} == {name: int(value) for name, value in MSG_CONSTANTS.items()}
    assert all(code == code.name and ErrorCode.from_number(code.number) is code for code in ErrorCode)


def test_an_unknown_code_is_refused_by_name_and_shown_by_number():
    with pytest.raises(ValueError):
        ErrorCode('NO_SUCH_CODE')
    with pytest.raises(ValueError):
        ErrorCode.from_number(12345)
    assert ErrorCode.name_of(12345) == '12345' and ErrorCode.name_of(-21) == 'SPEC_UNSYNTHESIZABLE'


def test_there_are_many_coded_errors():
    assert len(CODED) >= 40  # the check below sees the whole project


@pytest.mark.parametrize('error', CODED, ids=lambda c: f'{c.__module__}.{c.__qualname__}')
def test_every_coded_error_has_a_class_level_synthesis_error_code(error):
    assert isinstance(vars(CodedError)['code'], ErrorCode)
    code = next(vars(cls)['code'] for cls in error.__mro__ if 'code' in vars(cls))
    assert isinstance(code, ErrorCode), code


def test_exceptions_with_a_code_are_coded_errors():
    with_code = [cls for module in MODULES for cls in vars(module).values()
                 if isinstance(cls, type) and issubclass(cls, BaseException) and 'code' in vars(cls)
                 and cls.__module__ == module.__name__]
    assert with_code and [c.__qualname__ for c in with_code if not issubclass(c, CodedError)] == []


# The one error relaying another node's answer: its code is that answer's.
RELAYS = {'StageFailedError'}


def test_no_error_sets_its_code_per_instance():
    offenders = []
    for package in PACKAGES:
        for path in (ROOT / package).rglob('*.py'):
            tree = ast.parse(path.read_text())
            relays = [node for node in ast.walk(tree) if isinstance(node, ast.ClassDef) and node.name in RELAYS]
            relayed = {id(node) for relay in relays for node in ast.walk(relay)}
            for node in ast.walk(tree):
                if id(node) not in relayed and isinstance(node, ast.Assign) and any(
                        isinstance(t, ast.Attribute) and t.attr == 'code' and isinstance(t.value, ast.Name)
                        and t.value.id == 'self' for t in node.targets):
                    offenders.append(f'{path.relative_to(ROOT)}:{node.lineno}')
    assert offenders == []


def test_no_exception_class_name_is_used_twice():
    defined = {}
    for module in MODULES:
        for cls in vars(module).values():
            if isinstance(cls, type) and issubclass(cls, BaseException) and cls.__module__ == module.__name__:
                defined.setdefault(cls.__name__, set()).add(module.__name__)
    assert len(defined) >= 40 and {name: where for name, where in defined.items() if len(where) > 1} == {}


def test_a_relayed_answer_keeps_its_code_and_an_unknown_number_is_named():
    from synthesis_manager.ros.stage_calls import StageFailedError
    from synthesis_msgs.msg import SynthesisErrorCodes

    known = StageFailedError(SynthesisErrorCodes(value=SynthesisErrorCodes.SPEC_UNSYNTHESIZABLE, message='no way'))
    assert known.code is ErrorCode.SPEC_UNSYNTHESIZABLE and str(known) == 'no way'
    unknown = StageFailedError(SynthesisErrorCodes(value=777, message='odd'))
    assert unknown.code is ErrorCode.BEHAVIOR_SYNTHESIS_FAILED and 'unknown error code 777: odd' in str(unknown)


def test_the_readme_lists_every_exit_status_with_its_meaning():
    from respec.vocabulary.errors import ExitStatus

    readme = (ROOT / 'README.md').read_text()
    assert all(f'| {int(status)} | {status.meaning} |' in readme for status in ExitStatus)
    assert ExitStatus.for_error('SPEC_UNSYNTHESIZABLE') == ExitStatus.FAILED == ExitStatus.for_error('777')
    assert ExitStatus.for_error(ErrorCode.SYNTHESIS_TIMEOUT) == ExitStatus.TIMED_OUT
    assert ExitStatus.for_error(ErrorCode.BUSY) == ExitStatus.UNAVAILABLE


def test_errors_end_in_error_and_every_other_exception_is_a_documented_control_flow_signal():
    from respec.vocabulary.errors import ControlFlowSignal

    exceptions = {cls for module in MODULES for cls in vars(module).values()
                  if isinstance(cls, type) and issubclass(cls, BaseException) and cls.__module__ == module.__name__}
    assert [c.__name__ for c in CODED if not c.__name__.endswith('Error')] == []
    signals = {c for c in exceptions if not c.__name__.endswith('Error')}
    assert signals and all(issubclass(c, ControlFlowSignal) and 'not an error' in c.__doc__.lower()
                           for c in signals), signals
