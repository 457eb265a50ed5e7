"""The package's entry points stay what they are once every submodule has been imported."""

import importlib
import pkgutil

import ltl_synthesizer


def test_exported_names_are_not_shadowed_by_submodules():
    for module in pkgutil.iter_modules(ltl_synthesizer.__path__):
        if module.name != '__main__':
            importlib.import_module(f'ltl_synthesizer.{module.name}')  # sets the package's attribute
    for name in ltl_synthesizer.__all__:
        value = getattr(ltl_synthesizer, name)
        assert not isinstance(value, type(ltl_synthesizer)), f'ltl_synthesizer.{name} is a module'
