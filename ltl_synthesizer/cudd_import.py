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
from typing import Any

#: A BDD of ``dd.cudd`` (a ``dd.cudd.Function``: dd has no type hints, so it is Any to mypy).
Node = Any


def _import_cudd() -> Any:  # the dd.cudd module
    if 'dd.cudd' in sys.modules or 'networkx' in sys.modules:
        from dd import cudd
        return cudd
    placeholder = types.ModuleType('networkx')
    setattr(placeholder, 'MultiDiGraph', type('MultiDiGraph', (), {}))  # dd reads it for a type alias
    sys.modules['networkx'] = placeholder
    try:
        from dd import cudd
    finally:
        del sys.modules['networkx']
    utils = sys.modules.get('dd._utils')
    if utils is not None and getattr(utils, '_nx', None) is placeholder:
        setattr(utils, '_nx', _lazy_module('networkx'))  # dd keeps its networkx import there
    return cudd


def _lazy_module(name: str) -> types.ModuleType | None:
    """``name`` as a module that loads on first attribute access (None if not installed)."""
    spec = importlib.util.find_spec(name)
    if spec is None:
        return None
    assert spec.loader is not None  # an installed module's
    spec.loader = importlib.util.LazyLoader(spec.loader)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


cudd = _import_cudd()
