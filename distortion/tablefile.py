"""Distortion tables as files: the CSV reader (with clear errors) and writer of a
:class:`~distortion.curve.DistortionCurve`.

A curve is Pestrecov's characteristic distortion in one image plane (Eq. 9): per field point the
abscissa of orthoscopy ``x`` (``tan α`` for an object at infinity, the object height ``y`` in mm
for finite conjugates), the ideal image size ``y0' = K0·x`` with ``K0`` = F0 (mm) or M0, and the
linear distortion ``D0 = y' − y0'`` (mm). The relative distortion ``Dr = D0 / y0'`` is kept as a
fraction internally and printed in per cent as in the paper.

CSV format (one header line, then one row per field; blank lines and lines starting with ``#``
are ignored)::

    # source: Pestrecov 1958, Table I
    alpha_deg, y0p_mm, D0_mm, Dr_pct
    0, 0.000, 0.000, 0.000
    10, 27.103, +0.017, +0.063

Column names are matched loosely (case, spaces, units in parentheses or as ``_mm``/``_deg``/
``_pct`` suffixes, and ``'`` for ``p`` are ignored): the field column is ``alpha`` / ``angle`` /
``field_angle`` (degrees, object at infinity) or ``y`` / ``object_height`` / ``height`` (mm,
finite conjugates); then ``y0p`` (ideal image size, mm), ``D0`` (mm) and optionally ``Dr`` (%).
"""

from __future__ import annotations

import csv
import io
import math
import re
from pathlib import Path

import numpy as np

from .curve import ANGLE, HEIGHT, NOMINAL_ANGLE, DistortionCurve
from .errors import DataError, read_text

_ALIASES = {
    "alpha": "angle",
    "angle": "angle",
    "fieldangle": "angle",
    "field": "angle",
    "a": "angle",
    "y": "height",
    "height": "height",
    "objectheight": "height",
    "y0p": "y0p",
    "idealimagesize": "y0p",
    "d0": "D0",
    "d": "D0",
    "dr": "Dr",
}


def _normalise(name: str) -> str:
    s = name.strip().lower()
    s = re.sub(r"\(.*?\)|\[.*?\]", "", s)
    s = s.replace("'", "p").replace("’", "p")
    s = re.sub(r"[\s_\-]", "", s)
    for suffix in ("mm", "deg", "degrees", "pct", "percent", "%"):
        if s.endswith(suffix) and len(s) > len(suffix):
            s = s[: -len(suffix)]
    return s


def _decimals(text: str) -> int:
    t = text.strip().lower()
    if "e" in t:
        mant, _, exp = t.partition("e")
        return max(0, _decimals(mant) - int(exp))
    return len(t.split(".", 1)[1]) if "." in t else 0


def read_distortion_table(
    path: str | Path,
    constant: float | None = None,
    *,
    name: str | None = None,
    text: str | None = None,
) -> DistortionCurve:
    """Read a distortion table CSV (format in the module docstring) into a :class:`DistortionCurve`.

    ``constant`` is F0 (mm, angle tables) or M0 (height tables). When omitted it is inferred
    from ``y0' / tan α`` (or ``y0' / y``) by least squares. Either way every row must agree with
    ``y0' = K0·x`` to the rounding of the printed ``y0'``; an optional ``Dr`` column (per cent)
    must agree with ``100·D0/y0'`` to the rounding of the printed numbers.

    Parameters
    ----------
    path : str or Path
        The CSV file; with ``text`` only used in messages and for the default name.
    constant : float, optional
        K0 of Pestrecov's Eq. (8): F0 in mm (angle tables, object at infinity) or M0 (height
        tables, finite conjugates); finite and nonzero. Default: inferred.
    name : str, optional
        The curve's name; default the file name's stem.
    text : str, optional
        The file's content, read instead of the file.

    Returns
    -------
    DistortionCurve
        Fields (degrees or mm), x (tan α or y), y0' = K0·x recomputed exactly (mm), D0 (mm, Eq. 9:
        y' − y0'), K0, the file's comments as ``source``; ``extra`` holds the path and the data
        lines.

    Raises
    ------
    DataError
        Naming the file and line, for: an unreadable file, a missing header or column, an
        unknown or duplicated column, an unparseable number, NaN/inf, a row with the wrong number
        of cells, non-monotonic fields, a field angle not below 90°, fewer than two off-axis
        rows, a ``constant`` that is zero or not finite, inconsistent y0' or Dr, |D0| ≥ |y0'|
        (a D0 column in µm).
    """
    where = str(path)
    if text is None:
        text = read_text(path, "a distortion table")
    rows: list[tuple[int, list[str]]] = []
    comments: list[str] = []
    for lineno, line in enumerate(text.splitlines(), start=1):
        s = line.strip()
        if not s:
            continue
        if s.startswith("#"):
            comments.append(s.lstrip("#").strip())
            continue
        cells = next(csv.reader([s]))
        rows.append((lineno, [c.strip() for c in cells]))
    if not rows:
        raise DataError(f"{where}: no header line and no data (a distortion table needs both)")
    hline, header = rows[0]
    roles: dict[str, int] = {}
    for i, h in enumerate(header):
        role = _ALIASES.get(_normalise(h))
        if role is None:
            sep = next((c for c in ";\t|" if c in h), None)
            hint = (
                f" (columns separated by {sep!r}: separate them with commas)"
                if sep
                else " (an empty column: a trailing comma?)"
                if not h
                else ""
            )
            raise DataError(
                f"{where}:{hline}: unknown column {h!r}{hint}; expected a field column "
                "(alpha_deg or y_mm), then y0p_mm, D0_mm and optionally Dr_pct"
            )
        if role in roles or (
            role in ("angle", "height") and ("angle" in roles or "height" in roles)
        ):
            raise DataError(f"{where}:{hline}: column {h!r} duplicates another column")
        roles[role] = i
    field_role = "angle" if "angle" in roles else "height" if "height" in roles else None
    missing = [
        label
        for role, label in (
            (field_role, "a field column (alpha_deg or y_mm)"),
            ("y0p", "y0p_mm"),
            ("D0", "D0_mm"),
        )
        if role is None or role not in roles
    ]
    if missing:
        raise DataError(
            f"{where}:{hline}: missing column(s): {', '.join(missing)} (header has: "
            f"{', '.join(header)})"
        )
    data: dict[str, list[float]] = {r: [] for r in roles}
    decs: dict[str, list[int]] = {r: [] for r in roles}
    lines: list[int] = []
    for lineno, cells in rows[1:]:
        if len(cells) != len(header):
            raise DataError(
                f"{where}:{lineno}: {len(cells)} value(s) but the header has {len(header)} columns"
            )
        for role, i in roles.items():
            cell = cells[i]
            try:
                v = float(cell)
            except ValueError:
                raise DataError(
                    f"{where}:{lineno}: cannot read {cell!r} as a number (column {header[i]!r})"
                ) from None
            if not math.isfinite(v):
                raise DataError(
                    f"{where}:{lineno}: {cell!r} is not a finite number (column {header[i]!r})"
                )
            data[role].append(v)
            decs[role].append(_decimals(cell))
        lines.append(lineno)
    fld = np.array(data[field_role])
    if np.count_nonzero(fld) < 2:
        raise DataError(
            f"{where}: {fld.size} data row(s) with {np.count_nonzero(fld)} off the axis; a "
            "distortion table needs at least two off-axis field points"
        )
    d = np.diff(fld)
    if not (np.all(d > 0) or np.all(d < 0)):
        bad = int(np.nonzero(d * (1 if d[0] > 0 else -1) <= 0)[0][0]) + 1
        raise DataError(
            f"{where}:{lines[bad]}: field values must be strictly increasing or decreasing "
            f"({fld[bad - 1]:g} then {fld[bad]:g})"
        )
    kind = ANGLE if field_role == "angle" else HEIGHT
    if kind == ANGLE and np.any(np.abs(fld) >= 90.0):
        i = int(np.nonzero(np.abs(fld) >= 90.0)[0][0])
        raise DataError(f"{where}:{lines[i]}: field angle {fld[i]:g}° is not below 90°")
    x = np.tan(np.radians(fld)) if kind == ANGLE else fld.copy()
    y0p = np.array(data["y0p"])
    D0 = np.array(data["D0"])
    tol_y = 0.5 * 10.0 ** -np.array(decs["y0p"], dtype=float) + 1e-12 * np.abs(y0p)
    sym = "F0" if kind == ANGLE else "M0"
    on = x != 0.0
    # field angles are nominal values (10°, 37.5°); object heights printed with decimals are
    # computed values rounded to their last digit (a projector's y for a given y0'), and half
    # that digit moves K·y by |K| times it
    dec_f = np.array(decs[field_role], dtype=float)
    dx = np.where(dec_f > 0, 0.5 * 10.0**-dec_f, 0.0) if kind == HEIGHT else np.zeros_like(x)
    if constant is None:
        K = float(np.dot(x[on], y0p[on]) / np.dot(x[on], x[on]))
        tol = 2.0 * (tol_y + abs(K) * dx)
        origin = f"{sym} = {K:.6g} inferred from y0'/x"
    else:
        K = float(constant)
        if not math.isfinite(K) or K == 0.0:
            raise DataError(f"{where}: {sym} must be a finite nonzero number, got {constant!r}")
        tol = tol_y + abs(K) * dx
        origin = f"{sym} = {K:.6g}"
    bad = np.nonzero(np.abs(y0p - K * x) > tol)[0]
    if bad.size:
        i = int(bad[0])
        raise DataError(
            f"{where}:{lines[i]}: y0' = {y0p[i]:.10g} mm is inconsistent with {origin} "
            f"({sym}·{'tan α' if kind == ANGLE else 'y'} = {K * x[i]:.10g} mm, beyond the "
            "rounding of the printed numbers)"
        )
    big = np.nonzero(on & (np.abs(D0) >= np.abs(y0p)))[0]
    if big.size:  # a distortion of 100 % or more: a unit slip, not a lens
        i = int(big[0])
        raise DataError(
            f"{where}:{lines[i]}: D0 = {D0[i]:g} mm is as large as the ideal image height y0' = "
            f"{y0p[i]:g} mm (a distortion of {100.0 * D0[i] / y0p[i]:.3g} %): is the "
            f"{header[roles['D0']]!r} column in micrometres? It must be in mm"
        )
    if "Dr" in roles:
        dr = np.array(data["Dr"])
        with np.errstate(divide="ignore", invalid="ignore"):
            calc = np.where(y0p != 0, 100.0 * D0 / np.where(y0p != 0, y0p, 1.0), 0.0)
            tol_r = (
                0.5 * 10.0 ** -np.array(decs["Dr"], dtype=float)
                + 100.0
                * 0.5
                * 10.0 ** -np.array(decs["D0"], dtype=float)
                / np.abs(np.where(y0p != 0, y0p, np.inf))
                + np.abs(calc) * tol_y / np.abs(np.where(y0p != 0, y0p, np.inf))
                + 1e-12
            )
        bad = np.nonzero(np.abs(dr - calc) > tol_r)[0]
        if bad.size:
            i = int(bad[0])
            raise DataError(
                f"{where}:{lines[i]}: Dr = {dr[i]:g} % is inconsistent with 100·D0/y0' = "
                f"{calc[i]:.4f} %"
            )
    # the printed y0' is a rounding of K0·x (checked above); use the exact ideal image size so
    # that D0 = y' − K0·x holds exactly (Eq. 9)
    y0p = K * x
    src = "; ".join(c for c in comments if c)
    return DistortionCurve(
        fields=fld,
        field_kind=kind,
        x=x,
        y0p=y0p,
        D0=D0,
        constant=K,
        name=name if name is not None else Path(where).stem,
        plane="",
        source=src,
        decimals=max(decs["D0"]) if decs["D0"] else 4,
        extra={"path": where, "lines": lines},
    )


def dumps_table(curve: DistortionCurve, *, decimals: int | None = None) -> str:
    """CSV text readable by :func:`read_distortion_table` (a '#' line records name, plane, K0)."""
    dec = curve.decimals if decimals is None else decimals
    buf = io.StringIO()
    head = "alpha_deg" if curve.field_kind != HEIGHT else "y_mm"
    buf.write(
        f"# {curve.name} {curve.plane}; {curve.symbol}0 = {float(curve.constant)!r}\n".replace(
            "  ", " "
        )
    )
    if curve.field_kind == NOMINAL_ANGLE:
        buf.write("# field column holds nominal angles; object heights y = p0 tan(alpha)\n")
        head = "y_mm"
        fields = curve.x
    else:
        fields = curve.fields
    buf.write(f"{head},y0p_mm,D0_mm,Dr_pct\n")
    for f, y, d, r in zip(fields, curve.y0p, curve.D0, 100.0 * curve.Dr, strict=True):
        buf.write(f"{float(f)!r},{y:.{dec + 3}f},{d:.{dec + 3}f},{r:.{dec + 3}f}\n")
    return buf.getvalue()
