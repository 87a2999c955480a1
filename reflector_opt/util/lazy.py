"""Lazy re-exports of a package's public names (PEP 562).

A package lists the modules its public names live in; the module that defines a name is
imported the first time the name is used, so ``import reflector_opt`` and the command
line's ``--help`` do not pay for numba, SciPy, matplotlib or trimesh until they are needed.
"""

from __future__ import annotations

import importlib
import importlib.util
import sys

__all__ = ["lazy_exports", "lazy_sources"]


def lazy_sources(package, modules):
    """Each lazily re-exported name and the absolute name of the module that defines it.

    Parameters
    ----------
    package : str
        The package's ``__name__``, against which relative module names resolve.
    modules : dict of str to tuple of str
        Each module (absolute, or relative to `package` as in ``from .design import``) and
        the public names it gives, e.g. ``{".design": ("Design", "load_design")}``.

    Returns
    -------
    dict of str to str
        Each name and its module's absolute name, in the order of `modules`.

    Raises
    ------
    ValueError
        If a name is listed under two modules.
    """
    sources = {}
    for module, names in modules.items():
        absolute = importlib.util.resolve_name(module, package)
        for name in names:
            if name in sources:
                raise ValueError(f"{package}: {name!r} is listed under two modules")
            sources[name] = absolute
    return sources


def lazy_exports(package, modules):
    """``__all__``, module-level ``__getattr__`` and ``__dir__`` for lazily re-exported names.

    Parameters
    ----------
    package : str
        The package's ``__name__``.
    modules : dict of str to tuple of str
        Each module (absolute, or relative to `package`) and the public names it gives, as
        in :func:`lazy_sources`.

    Returns
    -------
    all : list of str
        The public names, grouped by module in the order given; the package's ``__all__``.
    getattr, dir : callable
        To be bound to ``__getattr__`` and ``__dir__`` in the package. The first access to a
        name imports its module and caches the value on the package, so later accesses cost
        nothing; ``dir(package)`` lists the lazy names beside those already loaded.

    Examples
    --------
    In a package's ``__init__.py``::

        _MODULES = {".design": ("Design", "load_design"), ".defaults": ("default_design",)}
        __all__, __getattr__, __dir__ = lazy_exports(__name__, _MODULES)
    """
    sources = lazy_sources(package, modules)

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

    return list(sources), __getattr__, __dir__
