"""``dd.cudd`` without its 0.4 s import of networkx.

dd imports networkx at start-up only for graph conversions the synthesizer never uses, and that
import is most of a tiny synthesis's CPU time (``python -X importtime``). While dd loads, a
placeholder stands in for networkx; dd is then given networkx as a lazy module, so its
conversions still work (loading networkx on first use), and any later ``import networkx``
elsewhere gets the real module.
"""

from __future__ import annotations

import importlib.util
import sys
import types


def _import_cudd():
    if 'dd.cudd' in sys.modules or 'networkx' in sys.modules:
        from dd import cudd
        return cudd
    placeholder = types.ModuleType('networkx')
    placeholder.MultiDiGraph = type('MultiDiGraph', (), {})  # dd reads it for a type alias
    sys.modules['networkx'] = placeholder
    try:
        from dd import cudd
    finally:
        del sys.modules['networkx']
    utils = sys.modules.get('dd._utils')
    if getattr(utils, '_nx', None) is placeholder:
        utils._nx = _lazy_module('networkx')  # noqa: SLF001 - dd keeps its networkx import there
    return cudd


def _lazy_module(name: str):
    """``name`` as a module that loads on first attribute access (None if not installed)."""
    spec = importlib.util.find_spec(name)
    if spec is None:
        return None
    spec.loader = importlib.util.LazyLoader(spec.loader)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


cudd = _import_cudd()
