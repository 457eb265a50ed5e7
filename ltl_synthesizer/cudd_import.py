"""``dd.cudd`` without the modules it loads only for features the synthesizer never uses.

dd imports at start-up, for graph conversions, its pure-Python BDDs, its expression parser
(ply), copying and dumping (json, shelve, pickle), pretty-printing, running Graphviz
(subprocess, shlex) and its messages (textwrap), modules that cost more than the rest of a
tiny synthesis: networkx 0.4 s of CPU, the others about 15 ms (``python -X importtime``).
While dd loads, a stand-in takes the place of each of them that is not loaded yet; dd keeps
the stand-ins, and a stand-in loads its module by the ordinary import (so there is only ever
one copy) the first time dd uses it. Any other ``import`` of those modules, later, gets the
real module.
"""

from __future__ import annotations

import importlib
import sys
import types
from typing import Any

#: A BDD of ``dd.cudd`` (a ``dd.cudd.Function``: dd has no type hints, so it is Any to mypy).
Node = Any

#: What dd imports that the synthesizer never uses (dd.cudd, dd._utils and dd.bdd import them at
#: the top, but only functions that the synthesizer does not call use them).
_DEFERRED = ('networkx', 'dd.autoref', 'dd.bdd', 'dd._copy', 'dd._parser',
             'pickle', 'pprint', 'subprocess', 'shlex', 'textwrap', 'logging')


class _StandIn(types.ModuleType):
    """Stands in for the module of its name; loads it on the first use of an attribute."""

    def __getattr__(self, attribute: str) -> Any:
        if sys.modules.get(self.__name__) is self:  # used while dd loads: the real one now
            del sys.modules[self.__name__]
        return getattr(sys.modules.get(self.__name__) or _import_deferring(self.__name__), attribute)


class _LoggingStandIn(_StandIn):
    """Stands in for ``logging``: dd asks it for its loggers as it loads (and logs at info level
    on each new BDD), which alone would load logging."""

    def getLogger(self, name: str) -> Any:  # logging's name
        return _DeferredLogger(name)


class _DeferredLogger:
    """dd's logger of this name, loaded on first use but for debug and info messages: while
    logging is not loaded nothing can have configured it, and the root logger's default level
    (WARNING) drops those."""

    def __init__(self, name: str) -> None:
        self.name = name

    def __getattr__(self, method: str) -> Any:
        logging = sys.modules.get('logging')
        if method in ('debug', 'info') and (logging is None or isinstance(logging, _StandIn)):
            return _dropped
        return getattr(importlib.import_module('logging').getLogger(self.name), method)


def _dropped(*args: Any, **kwargs: Any) -> None:
    """A debug or info message that unconfigured logging would drop."""


def _import_deferring(name: str) -> Any:
    """The module ``name``, imported with stand-ins for the _DEFERRED modules not loaded yet (so
    dd.bdd, which dd.cudd needs to enumerate cubes, comes without dd's parser too)."""
    stand_ins = {deferred: (_LoggingStandIn if deferred == 'logging' else _StandIn)(deferred)
                 for deferred in _DEFERRED if deferred != name and deferred not in sys.modules}
    graphs: Any = stand_ins.get('networkx', types.SimpleNamespace())
    graphs.MultiDiGraph = None  # dd reads it as it loads, for a type alias only
    sys.modules.update(stand_ins)
    try:
        return importlib.import_module(name)
    finally:
        del graphs.MultiDiGraph  # read from networkx from now on
        for deferred, stand_in in stand_ins.items():
            if sys.modules.get(deferred) is stand_in:
                del sys.modules[deferred]


cudd = _import_deferring('dd.cudd')
