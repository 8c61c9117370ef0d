"""The one way the project writes a file: atomically, never onto an input, never over an existing
file unless asked (docs/design.md, "Errors and files").

:func:`write_atomic` writes the whole content to a temporary file in the destination folder,
flushes and fsyncs it, then renames it over the destination with :func:`os.replace` (atomic on
POSIX and Windows). A full disk, a read-only folder or an interrupt leaves the old file intact and
no fragment behind. Every writer (lens files, CSV, JSON, plots, design runs) goes through it.
"""

from __future__ import annotations

import contextlib
import os
import tempfile
from collections.abc import Iterable
from pathlib import Path

from ..errors import OutputError


def same_file(a: str | os.PathLike, b: str | os.PathLike) -> bool:
    """True when ``a`` and ``b`` name the same existing file (``os.path.samefile``: hard links,
    symlinks and ``./x`` vs ``x`` included)."""
    try:
        return os.path.samefile(a, b)
    except OSError:
        return False


def check_output(
    path: str | os.PathLike,
    *,
    inputs: Iterable[str | os.PathLike] = (),
    overwrite: bool = False,
    flag: str = "overwrite=True",
) -> Path:
    """Refuse an output that cannot or must not be written, before any work is done.

    Raises :class:`~raytrace.errors.OutputError` when ``path`` is ``-`` (standard output, which
    is no file), ends in a path separator (it names a folder), is the same file as one of
    ``inputs``, exists and ``overwrite`` is false (``flag`` names how to allow it: ``--force``
    on the command line), is a directory, or its folder does not exist or cannot take a new
    file (tried by creating and removing an empty one: permission bits do not tell — root passes
    them, yet cannot write in /proc or on a read-only mount).
    """
    text = os.fspath(path)
    if text in ("-", b"-"):  # the Unix sign for standard output, which a writer here never is
        raise OutputError(
            "-: names standard output, which this writes no file to; give a file name (the "
            "text, JSON or CSV output goes to standard output without -o)"
        )
    if isinstance(text, str) and text.endswith(tuple(c for c in (os.sep, os.altsep) if c)):
        raise OutputError(f"{text}: ends in {text[-1]!r}, so it names a folder; give a file name")
    p = Path(path)
    for src in inputs:
        if src is not None and same_file(p, src):
            raise OutputError(
                f"{p}: this is the input file {src}; refusing to overwrite it — choose another "
                "output name"
            )
    if p.is_dir():
        raise OutputError(f"{p}: is a directory; give a file name")
    if p.exists() and not overwrite:
        raise OutputError(f"{p}: the file exists; give {flag} to replace it")
    parent = p.resolve().parent
    if not parent.is_dir():
        blocker = next((a for a in (parent, *parent.parents) if a.exists()), None)
        if blocker is not None and not blocker.is_dir():
            raise OutputError(f"{p}: {blocker} is a file, not a folder")
        raise OutputError(f"{p}: the folder {parent} does not exist")
    try:
        fd, probe = tempfile.mkstemp(prefix=".orthoscope-probe-", dir=parent)
    except OSError as e:
        raise OutputError(
            f"{p}: the folder {parent} does not take new files ({e.strerror or e}); choose "
            "another folder"
        ) from None
    os.close(fd)
    with contextlib.suppress(OSError):  # the folder took the file; its removal is not the output
        os.unlink(probe)
    return p


def _mode(p: Path) -> int:
    """The permissions the written file gets: those of the file it replaces, else the usual
    0666 less the process umask (a temporary file starts at 0600)."""
    try:
        return p.stat().st_mode & 0o7777
    except OSError:
        umask = os.umask(0)
        os.umask(umask)
        return 0o666 & ~umask


def write_atomic(
    path: str | os.PathLike,
    data: bytes | str,
    *,
    inputs: Iterable[str | os.PathLike] = (),
    overwrite: bool = False,
    encoding: str = "utf-8",
    flag: str = "overwrite=True",
) -> Path:
    """Write ``data`` (bytes, or text encoded with ``encoding``) to ``path`` atomically.

    The checks of :func:`check_output` apply first. On any OS error the destination is left as it
    was and :class:`~raytrace.errors.OutputError` names the file and the reason.
    """
    p = check_output(path, inputs=inputs, overwrite=overwrite, flag=flag)
    raw = data.encode(encoding) if isinstance(data, str) else bytes(data)
    fd = -1
    tmp = None
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{p.name}.", suffix=".part", dir=p.resolve().parent)
        with os.fdopen(fd, "wb") as fh:
            fd = -1
            fh.write(raw)
            fh.flush()
            os.fsync(fh.fileno())
        if p.exists() and not overwrite:  # appeared while we were writing
            raise OutputError(f"{p}: the file appeared while writing; give {flag} to replace it")
        os.chmod(tmp, _mode(p))
        os.replace(tmp, p)
        tmp = None
    except OSError as e:
        raise OutputError(f"{p}: cannot write: {e.strerror or e}") from None
    finally:
        if fd >= 0:
            with contextlib.suppress(OSError):
                os.close(fd)
        if tmp is not None:
            with contextlib.suppress(OSError):
                os.unlink(tmp)
    return p


def check_reads_back(text: str, loads, path: str | Path) -> None:
    """Raise LensError when ``text``, about to be written to ``path``, does not read back with
    ``loads`` (a writer's bug: nothing is written then)."""
    import warnings

    from ..errors import LensError, OrthoscopeError

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            loads(text)
    except OrthoscopeError as e:
        raise LensError(
            f"{path}: not written: the file would not read back ({e}); please report it"
        ) from None
