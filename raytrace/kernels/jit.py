"""The one decorator every numba kernel uses: ``@kernel(...)`` = ``numba.njit(cache=True, ...)``
with two guarantees numba alone does not give (docs/design.md, "Performance"):

1. **Consistent cache across the kernel modules.** Numba keys a cached kernel on the stamp of
   the file that defines it only, so a kernel of :mod:`.bulk` that inlines a function of
   :mod:`.surface` would keep stale machine code after :mod:`.surface` changes. Here every
   kernel of this package is stamped with the modification times and sizes of *all* kernel
   modules: changing any of them recompiles all.
2. **A cache that cannot be written is not an error.** Numba raises at decoration time when it
   finds no writable cache folder (a read-only install with no writable home). The kernels then
   fall back to the user cache folder, and failing that to compilation without a cache, with
   one :class:`KernelCacheWarning` (the CLI prints it as one line on stderr).

The locator subclasses numba's own in-tree / user-wide locators (``numba.core.caching``); if a
future numba renames them, the decorator falls back to plain ``cache=True``.
"""

from __future__ import annotations

import os
import warnings
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numba

_HERE = Path(__file__).resolve().parent


class KernelCacheWarning(UserWarning):
    """The numba kernel cache cannot be written: kernels compile on every run."""


def _stamp() -> tuple:
    out = []
    for p in sorted(_HERE.glob("*.py")):
        st = p.stat()
        out.append((p.name, st.st_mtime, st.st_size))
    return tuple(out)


KERNEL_STAMP = _stamp()


def _install_locator() -> bool:
    """Put a locator for this package's kernels first in numba's list; False if impossible."""
    try:
        from numba.core import caching
    except ImportError:  # pragma: no cover - numba without the caching module
        return False
    impl = getattr(caching, "CacheImpl", None) or getattr(caching, "_CacheImpl", None)
    intree = getattr(caching, "InTreeCacheLocator", None) or getattr(
        caching, "_InTreeCacheLocator", None
    )
    userwide = getattr(caching, "UserWideCacheLocator", None) or getattr(
        caching, "_UserWideCacheLocator", None
    )
    userdir = getattr(caching, "UserProvidedCacheLocator", None) or getattr(
        caching, "_UserProvidedCacheLocator", None
    )
    if impl is None or intree is None or userwide is None:  # pragma: no cover
        return False

    def ours(py_file: str) -> bool:
        try:
            return Path(py_file).resolve().parent == _HERE
        except OSError:  # pragma: no cover
            return False

    def stamped(base: type) -> type:
        class Locator(base):
            def get_source_stamp(self) -> Any:
                return KERNEL_STAMP

            @classmethod
            def from_function(cls, py_func, py_file):
                if not ours(py_file):
                    return None
                return super().from_function(py_func, py_file)

        Locator.__name__ = f"Orthoscope{base.__name__}"
        return Locator

    mine = [stamped(b) for b in (userdir, intree, userwide) if b is not None]
    classes = impl._locator_classes
    if not any(c.__name__.startswith("Orthoscope") for c in classes):
        impl._locator_classes = mine + list(classes)
    return True


_LOCATOR = _install_locator()
_warned = False


def kernel(**options: Any) -> Callable:
    """``numba.njit(cache=True, **options)``, with the consistent cache stamp of this package and
    a fallback to an uncached kernel (one :class:`KernelCacheWarning`) when no cache folder can
    be written."""

    def decorate(func: Callable) -> Callable:
        global _warned
        try:
            return numba.njit(cache=True, **options)(func)
        except RuntimeError as e:
            if "cannot cache" not in str(e):
                raise
            if not _warned:
                _warned = True
                warnings.warn(
                    "no writable folder for the numba kernel cache (install folder and "
                    f"{os.path.expanduser('~')} are read-only): kernels compile on every run; "
                    "set NUMBA_CACHE_DIR to a writable folder",
                    KernelCacheWarning,
                    stacklevel=3,
                )
            return numba.njit(cache=False, **options)(func)

    return decorate


def cache_is_warm(*dispatchers) -> bool:
    """True when every kernel in ``dispatchers`` has a cached compilation for the current sources
    (so the first call loads machine code instead of compiling). Uses numba's cache index; when
    that cannot be inspected the answer is True (nothing is claimed)."""
    try:
        return all(bool(d._cache._cache_file._load_index()) for d in dispatchers)
    except Exception:  # noqa: BLE001 - a private numba API: never fail because of it
        return True
