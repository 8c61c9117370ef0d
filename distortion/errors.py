"""Typed exceptions of the distortion package (all are :class:`raytrace.errors.OrthoscopeError`,
so a caller can catch every project error with one class)."""

from __future__ import annotations

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
