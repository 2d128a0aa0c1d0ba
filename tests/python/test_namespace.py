"""The package's namespace holds its API only: `__all__` names every public object,
`dir(smoothtrace)` lists exactly `__all__`, `from smoothtrace import *` imports exactly it,
and no helper import (numpy, os, typing names) leaks as a public attribute."""

import types

import smoothtrace


def public_attributes(module):
    return sorted(n for n in vars(module) if not n.startswith("_"))


OPTIONAL_SUBMODULES = ("dask",)


def test_dir_lists_the_api_only():
    assert dir(smoothtrace) == sorted(smoothtrace.__all__)


def test_every_public_attribute_is_in_all_and_every_name_in_all_exists():
    # Submodules imported by their own `import smoothtrace.x` become attributes too;
    # they belong to the API only when `__all__` names them, except the optional
    # `smoothtrace.dask` (it needs the `[dask]` extra, so `import *` must not load it).
    leaked = [
        n
        for n in public_attributes(smoothtrace)
        if n not in smoothtrace.__all__ and n not in OPTIONAL_SUBMODULES
    ]
    assert leaked == [], f"public names outside __all__: {leaked}"
    missing = [n for n in smoothtrace.__all__ if not hasattr(smoothtrace, n)]
    assert missing == [], f"__all__ names that do not exist: {missing}"
    assert len(set(smoothtrace.__all__)) == len(smoothtrace.__all__), "a name twice in __all__"


def test_no_helper_module_or_typing_name_is_exported():
    for name in ["np", "numpy", "os", "numbers", "typing", "Any", "List", "Optional"]:
        assert not hasattr(smoothtrace, name), f"smoothtrace.{name} is visible"
    modules = [n for n in smoothtrace.__all__ if isinstance(getattr(smoothtrace, n), types.ModuleType)]
    for n in modules:
        assert getattr(smoothtrace, n).__name__ == f"smoothtrace.{n}", n


def test_star_import_gives_exactly_all():
    namespace = {}
    exec("from smoothtrace import *", namespace)
    del namespace["__builtins__"]
    assert sorted(namespace) == sorted(smoothtrace.__all__)


def test_every_public_callable_is_documented():
    for n in smoothtrace.__all__:
        obj = getattr(smoothtrace, n)
        if callable(obj):
            assert (obj.__doc__ or "").strip(), f"smoothtrace.{n} has no docstring"
