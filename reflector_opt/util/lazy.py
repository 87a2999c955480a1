"""Lazy re-exports of a package's public names (PEP 562).

A package lists where each public name lives; the module that defines it is imported the
first time the name is used, so ``import reflector_opt`` and the command line's ``--help``
do not pay for numba, SciPy, matplotlib or trimesh until they are needed.
"""

from __future__ import annotations

import importlib
import sys

__all__ = ["lazy_exports"]


def lazy_exports(package, sources):
    """Module-level ``__getattr__`` and ``__dir__`` for lazily re-exported names.

    Parameters
    ----------
    package : str
        The package's ``__name__``.
    sources : dict of str to str
        Each public name and the module that defines it, e.g.
        ``{"Design": "reflector_opt.design.design"}``.

    Returns
    -------
    getattr, dir : callable
        To be bound to ``__getattr__`` and ``__dir__`` in the package. The first access to a
        name imports its module and caches the value on the package, so later accesses cost
        nothing; ``dir(package)`` lists the lazy names beside those already loaded.

    Examples
    --------
    In a package's ``__init__.py``::

        _SOURCES = {"Design": "reflector_opt.design.design"}
        __all__ = sorted(_SOURCES)
        __getattr__, __dir__ = lazy_exports(__name__, _SOURCES)
    """

    def __getattr__(name):
        try:
            source = sources[name]
        except KeyError:
            raise AttributeError(f"module {package!r} has no attribute {name!r}") from None
        value = getattr(importlib.import_module(source), name)
        setattr(sys.modules[package], name, value)
        return value

    def __dir__():
        return sorted(set(vars(sys.modules[package])) | set(sources))

    return __getattr__, __dir__
