"""Modules imported when first used: ``signal = lazy_module("scipy.signal")`` at a module's
top costs nothing until ``signal.lfilter`` is first read (importing scipy.signal takes about
1 s: most of a cold ``mjeap show``, which never needs it)."""
from __future__ import annotations

import importlib.util
import sys
from types import ModuleType

__all__ = ["lazy_module"]


def lazy_module(name: str) -> ModuleType:
    """The module ``name``, loaded at its first attribute access (importlib's LazyLoader);
    the module itself where it is already imported."""
    if name in sys.modules:
        return sys.modules[name]
    spec = importlib.util.find_spec(name)
    if spec is None or spec.loader is None:
        raise ModuleNotFoundError(f"No module named {name!r}", name=name)
    loader = importlib.util.LazyLoader(spec.loader)
    spec.loader = loader
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    loader.exec_module(module)
    return module
