"""One error idiom: every user-facing error is a CodedError subclass whose class-level
``code`` names a SynthesisErrorCodes constant (the .msg file and the generated message agree)."""

from __future__ import annotations

import ast
import importlib
import re
from pathlib import Path

import pytest

from respec.errors import CodedError
from synthesis_msgs.msg import SynthesisErrorCodes

ROOT = Path(__file__).resolve().parent.parent
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


def test_there_are_many_coded_errors():
    assert len(CODED) >= 40  # the check below sees the whole project


@pytest.mark.parametrize('error', CODED, ids=lambda c: f'{c.__module__}.{c.__qualname__}')
def test_every_coded_error_has_a_class_level_synthesis_error_code(error):
    assert isinstance(vars(CodedError)['code'], str)
    code = next(vars(cls)['code'] for cls in error.__mro__ if 'code' in vars(cls))
    assert isinstance(code, str) and code in MSG_CONSTANTS, code


def test_exceptions_with_a_code_are_coded_errors():
    with_code = [cls for module in MODULES for cls in vars(module).values()
                 if isinstance(cls, type) and issubclass(cls, BaseException) and 'code' in vars(cls)
                 and cls.__module__ == module.__name__]
    assert with_code and [c.__qualname__ for c in with_code if not issubclass(c, CodedError)] == []


def test_no_error_sets_its_code_per_instance():
    offenders = []
    for package in PACKAGES:
        for path in (ROOT / package).rglob('*.py'):
            for node in ast.walk(ast.parse(path.read_text())):
                if isinstance(node, ast.Assign) and any(
                        isinstance(t, ast.Attribute) and t.attr == 'code' and isinstance(t.value, ast.Name)
                        and t.value.id == 'self' for t in node.targets):
                    offenders.append(f'{path.relative_to(ROOT)}:{node.lineno}')
    assert offenders == []
