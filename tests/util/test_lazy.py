"""reflector_opt.util.lazy: each name's module, and a package's lazy ``__getattr__``/``__dir__``."""

import sys
import types

import pytest

from reflector_opt.util.lazy import lazy_exports, lazy_sources


def test_relative_module_names_resolve_against_the_package():
    sources = lazy_sources(
        "reflector_opt.cad", {".export": ("PARTS",), "..design.layout": ("Layout",)}
    )
    assert sources == {"PARTS": "reflector_opt.cad.export", "Layout": "reflector_opt.design.layout"}


def test_a_name_listed_under_two_modules_is_refused():
    with pytest.raises(ValueError, match="'Design' is listed under two modules"):
        lazy_sources("reflector_opt", {".design.design": ("Design",), ".design": ("Design",)})


@pytest.fixture
def package(monkeypatch):
    """A throw-away package module in ``sys.modules`` for lazy_exports to bind to."""
    module = types.ModuleType("lazy_probe")
    monkeypatch.setitem(sys.modules, "lazy_probe", module)
    return module


def test_a_lazy_name_is_its_modules_value_and_is_cached(package):
    names, getattr_, dir_ = lazy_exports(
        "lazy_probe", {"json": ("dumps", "loads"), "math": ("pi",)}
    )
    assert names == ["dumps", "loads", "pi"]
    assert "pi" not in vars(package)
    assert getattr_("pi") == 3.141592653589793
    assert vars(package)["pi"] == 3.141592653589793  # cached on the package after the first use
    assert {"dumps", "loads", "pi"} <= set(dir_())


def test_an_unlisted_lazy_name_is_an_attribute_error(package):
    _, getattr_, _ = lazy_exports("lazy_probe", {"json": ("dumps",)})
    with pytest.raises(AttributeError, match="'lazy_probe' has no attribute 'loads'"):
        getattr_("loads")
