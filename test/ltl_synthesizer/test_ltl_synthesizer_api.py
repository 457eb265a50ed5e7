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


def test_a_strategy_over_its_edge_budget_is_refused_while_it_is_extracted():
    """Free inputs make a strategy explode; with max_edges the extraction stops at the budget
    instead of extracting every edge first (and the strategy within it is the same as without)."""
    import pytest

    from ltl_synthesizer import synthesize
    from ltl_synthesizer.errors import StrategyTooLargeError
    from respec.parsing import spec_from_text_sections

    inputs = [f'x{i}' for i in range(6)]
    spec = spec_from_text_sections({'env_props': inputs, 'sys_props': ['y'], 'env_init': [], 'sys_init': [],
                                    'env_trans': [], 'sys_trans': ["y' <-> x0'"], 'env_liveness': [],
                                    'sys_liveness': ['y | !y']})
    whole = synthesize(spec)
    edges = sum(len(node['trans']) for node in whole.strategy['nodes'].values())
    assert edges > 1000
    with pytest.raises(StrategyTooLargeError, match='over 100 transitions') as refused:
        synthesize(spec, max_edges=100)
    assert refused.value.item == 'max_strategy_edges'
    assert synthesize(spec, max_edges=edges).strategy == whole.strategy
