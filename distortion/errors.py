"""Typed exceptions of the distortion package (all are :class:`raytrace.errors.OrthoscopeError`,
so a caller can catch every project error with one class)."""

from __future__ import annotations

import os
from pathlib import Path

from raytrace.errors import OrthoscopeError


class DataError(OrthoscopeError):
    """A data table (CSV of distortion values, profiles, a calibration file, ...) is missing
    columns, holds invalid values, or cannot be analysed as asked."""


class CalibrationError(DataError, ValueError):
    """An impossible calibration request (unknown criterion, a field not in the curve, too few
    points, a degenerate fit). A :class:`DataError` and a :class:`ValueError`."""


class UnitWarning(UserWarning):
    """A value that was read in the unit the input defines but looks like another unit (e.g. a
    plain distance read as metres that looks like millimetres)."""


def read_text(path: str | os.PathLike, what: str) -> str:
    """The text of the file ``path`` (UTF-8; a byte-order mark is dropped).

    Raises
    ------
    DataError
        Naming the file: it cannot be read (the system's reason, or larger than
        :data:`raytrace.files.text.MAX_FILE_BYTES`), or it is not UTF-8 text (``what`` names what
        it should hold, e.g. ``"a calibration file"``).
    """
    from raytrace.files.text import read_capped  # not at import: every module imports this one

    p = Path(path)
    try:
        return read_capped(p).decode("utf-8-sig")
    except OSError as e:
        raise DataError(f"{p}: cannot read: {e.strerror or e}") from None
    except UnicodeDecodeError:
        raise DataError(f"{p}: not UTF-8 text; {what} is a text file") from None
