"""Package names loaded from their modules on first use: the one mechanism behind ``sixdof``,
``sixdof.plots`` and ``sixdof.validation``, so that importing a package costs none of its heavy modules
(JAX, matplotlib, scipy.signal) until a name that needs one is used."""

from __future__ import annotations

import sys
from collections.abc import Callable, Iterable, Mapping
from importlib import import_module


def lazy_names(package: str, public: Mapping[str, str], exported: Iterable[str]) -> tuple[Callable, Callable]:
    """The module-level ``__getattr__`` and ``__dir__`` of ``package`` (its ``__name__``), whose ``public``
    names (name -> submodule, relative) are imported when first used and then kept in its namespace;
    ``exported`` is its ``__all__``."""
    exported = tuple(exported)

    def __getattr__(name: str):
        if name in public:
            value = getattr(import_module(f".{public[name]}", package), name)
            setattr(sys.modules[package], name, value)
            return value
        raise AttributeError(f"module {package!r} has no attribute {name!r}")

    def __dir__() -> list[str]:
        return sorted({*vars(sys.modules[package]), *exported})

    return __getattr__, __dir__
