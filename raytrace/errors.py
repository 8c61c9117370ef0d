"""Typed exceptions of the optics engine.

Every error a person can cause (a broken file, an impossible lens, a field the lens cannot pass)
is one of these, with a message that names the file, line and surface where they are known.
The CLI turns them into one line on stderr and exit status 2. Errors of distortion data tables
are :class:`distortion.errors.DataError`, also an :class:`OrthoscopeError`.
"""

from __future__ import annotations


class OrthoscopeError(Exception):
    """Base class of every error the project raises on purpose."""


class PrescriptionError(OrthoscopeError):
    """A lens file cannot be read or describes an invalid lens.

    Attributes
    ----------
    path, line, surface:
        Where the problem is, when known (``line`` is 1-based; ``surface`` is the 1-based
        surface number as printed in listings).
    """

    def __init__(
        self,
        message: str,
        *,
        path: str | None = None,
        line: int | None = None,
        surface: int | None = None,
    ) -> None:
        self.path = path
        self.line = line
        self.surface = surface
        self.reason = message
        where = []
        if path is not None:
            where.append(str(path) + (f":{line}" if line is not None else ""))
        elif line is not None:
            where.append(f"line {line}")
        if surface is not None:
            where.append(f"surface {surface}")
        prefix = ", ".join(where)
        super().__init__(f"{prefix}: {message}" if prefix else message)


class LensError(OrthoscopeError):
    """The lens model is physically impossible or unusable (e.g. no stop, afocal where a focus is
    needed, a surface the paraxial ray cannot pass)."""


class TraceError(OrthoscopeError):
    """A trace request is invalid (bad field, image plane behind the last surface, ...)."""


class OutputError(OrthoscopeError):
    """An output file cannot or must not be written (it is an input, it exists and overwriting
    was not asked for, its folder is missing or read-only, the disk is full)."""
