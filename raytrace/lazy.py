"""Public names that load on first use: the module-level ``__getattr__`` and ``__dir__`` that the
packages :mod:`raytrace.trace` and :mod:`distortion` share (PEP 562), so that importing a
package costs only what a command uses (docs/design.md, "Performance"). :mod:`orthoscope` keeps
its own: importing it must not import numpy, which any module of this package does."""

from __future__ import annotations

import importlib
import sys
from collections.abc import Callable, Mapping
from typing import Any


def lazy_names(
    package: str, names: Mapping[str, str]
) -> tuple[Callable[[str], Any], Callable[[], list[str]]]:
    """``(__getattr__, __dir__)`` for ``package``, whose public ``names`` map each name to the
    module that defines it (absolute, or relative to ``package`` with a leading dot). A name is
    imported on first access and then kept in the package's namespace; an unknown name raises
    :class:`AttributeError` as a module does."""

    def __getattr__(name: str) -> Any:
        mod = names.get(name)
        if mod is None:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        value = getattr(importlib.import_module(mod, package), name)
        setattr(sys.modules[package], name, value)
        return value

    def __dir__() -> list[str]:
        return sorted(set(vars(sys.modules[package])) | set(names))

    return __getattr__, __dir__
