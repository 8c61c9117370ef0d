"""The one decorator every numba kernel uses: ``@kernel(...)`` = ``numba.njit(cache=True, ...)``
with three things numba alone does not give (docs/design.md, "Performance"):

1. **Consistent cache across the kernel modules.** Numba keys a cached kernel on the stamp of
   the file that defines it only, so a kernel of :mod:`.bulk` that inlines a function of
   :mod:`.surface` would keep stale machine code after :mod:`.surface` changes. Here every
   kernel of this package is stamped with the modification times and sizes of *all* kernel
   modules: changing any of them recompiles all.
2. **A cache that cannot be written is not an error.** Numba raises when it finds no writable
   cache folder (a read-only install with no writable home; at decoration, or here when the
   kernel's cache is first used: it is made lazily, as finding and testing the folder costs
   about 0.5 ms per kernel). The kernels then fall back to the user cache folder, and failing
   that to compilation without a cache, with one :class:`KernelCacheWarning` (the CLI prints
   it as one line on stderr).
3. **A cached kernel loads without numba's registry set-up.** Numba's cache calls
   ``target_context.refresh()`` before loading any cached function: it imports and installs
   every typing and lowering registry (``numba.np.arraymath``, ``npyimpl``, the typed
   containers, ...), a fifth of a second of every command-line run, and all of it needed only
   to *compile*. Loading machine code needs only the symbols it links to: numba's C helpers
   (set up with the target context), the NRT (``rtsys.initialize``, done here), the parallel
   back end (re-run by the cached code's own ``reload_init``), and the hash secret, which
   ``numba.cpython.hashing`` registers when it is imported: a cached kernel whose object code
   names it, or that is not cached as object code, gets numba's full refresh. A cache miss
   compiles as before (numba's compiler refreshes the contexts itself). Used with the numba
   versions whose loading code this was checked against (0.58 ≤ numba < 0.70; checked in
   0.68.1); other versions load the numba way.

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
_moved = False


def _kernel_cache_class() -> type | None:
    """numba's ``FunctionCache`` with the light load of point 3 above, or None where this numba
    version is not one the light load was checked against (then ``cache=True`` as usual)."""
    try:
        from numba.core import caching
        from numba.core.runtime import rtsys

        version = tuple(int(v) for v in numba.__version__.split(".")[:2])
    except Exception:  # noqa: BLE001 - private numba API: fall back to numba's own loading
        return None
    base = getattr(caching, "FunctionCache", None)
    impl = getattr(caching, "CompileResultCacheImpl", None)
    if (
        base is None
        or impl is None
        or not (0, 58) <= version < (0, 70)
        or not all(
            hasattr(base, a) for a in ("_load_overload", "_guard_against_spurious_io_errors")
        )
    ):
        return None

    class KernelCacheImpl(impl):
        def rebuild(self, target_context, payload):
            try:  # payload[0]: the serialized library (name, kind, (object code, bitcode))
                _, kind, data = payload[0]
                light = kind == "object" and b"_numba_hashsecret_" not in data[0]
            except Exception:  # noqa: BLE001
                light = False
            if not light:
                target_context.refresh()
            return super().rebuild(target_context, payload)

    class KernelCache(base):
        _impl_class = KernelCacheImpl

        def load_overload(self, sig, target_context):
            rtsys.initialize(target_context)
            with self._guard_against_spurious_io_errors():
                return self._load_overload(sig, target_context)
            return None  # an I/O error that numba's guard swallows: compile

    return KernelCache


_KERNEL_CACHE = _kernel_cache_class()


def _warn_uncached() -> None:
    global _warned
    if not _warned:
        _warned = True
        asked = numba.config.CACHE_DIR
        where = (
            f"NUMBA_CACHE_DIR ({asked}), the install folder and {os.path.expanduser('~')} "
            "cannot be written"
            if asked
            else f"the install folder and {os.path.expanduser('~')} are read-only"
        )
        warnings.warn(
            f"no writable folder for the numba kernel cache ({where}): kernels compile on every "
            f"run (about a minute); set NUMBA_CACHE_DIR to a writable folder",
            KernelCacheWarning,
            stacklevel=4,
        )


def _check_asked_folder(cache) -> None:
    """One :class:`KernelCacheWarning` when NUMBA_CACHE_DIR is set but the cache went elsewhere
    (numba passes over a folder it cannot write without a word)."""
    global _moved
    asked = numba.config.CACHE_DIR
    path = getattr(cache, "_cache_path", None)
    if _moved or not asked or path is None:
        return
    try:
        inside = Path(path).resolve().is_relative_to(Path(asked).resolve())
    except OSError:  # pragma: no cover
        return
    if not inside:
        _moved = True
        warnings.warn(
            f"NUMBA_CACHE_DIR ({asked}) is not a writable folder: the numba kernel cache is in "
            f"{path} instead; set NUMBA_CACHE_DIR to a writable folder (or unset "
            "it)",
            KernelCacheWarning,
            stacklevel=5,
        )


def uncached() -> bool:
    """True once a kernel found no writable cache folder (it compiles on every run; the
    :class:`KernelCacheWarning` has said so)."""
    return _warned


class _LazyKernelCache:
    """A kernel's cache (:data:`_KERNEL_CACHE`), made when the dispatcher first uses it: numba
    makes it at decoration, where finding and testing the cache folder costs about 0.5 ms per
    kernel of every imported module, most of which a command never calls. A folder that cannot
    be written gives an uncached kernel and one :class:`KernelCacheWarning`, as at decoration."""

    __slots__ = ("_py_func", "_made")

    def __init__(self, py_func: Callable) -> None:
        self._py_func = py_func
        self._made = None

    def _get(self):
        if self._made is None:
            try:
                self._made = _KERNEL_CACHE(self._py_func)
                _check_asked_folder(self._made)
            except RuntimeError as e:
                if "cannot cache" not in str(e):
                    raise
                from numba.core.caching import NullCache

                _warn_uncached()
                self._made = NullCache()
        return self._made

    def __getattr__(self, name: str) -> Any:
        return getattr(self._get(), name)


def kernel(**options: Any) -> Callable:
    """``numba.njit(cache=True, **options)``, with the consistent cache stamp of this package, the
    light cached load (point 3 above, cache made on first use) and a fallback to an uncached
    kernel (one :class:`KernelCacheWarning`) when no cache folder can be written."""

    def decorate(func: Callable) -> Callable:
        if _KERNEL_CACHE is not None:
            dispatcher = numba.njit(**options)(func)
            dispatcher._cache = _LazyKernelCache(dispatcher.py_func)  # what cache=True does
            return dispatcher
        try:
            return numba.njit(cache=True, **options)(func)
        except RuntimeError as e:
            if "cannot cache" not in str(e):
                raise
            _warn_uncached()
            return numba.njit(cache=False, **options)(func)

    return decorate
