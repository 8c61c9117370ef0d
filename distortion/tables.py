"""Distortion curves as data: the :class:`DistortionCurve` model, a CSV reader with clear errors,
and writers (text in the paper's layout, CSV, JSON-ready dicts).

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
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from raytrace.errors import DataError

ANGLE = "angle"
HEIGHT = "height"
NOMINAL_ANGLE = "nominal-angle"
FIELD_KINDS = (ANGLE, HEIGHT, NOMINAL_ANGLE)


@dataclass(frozen=True)
class DistortionCurve:
    """Characteristic (or any reference) distortion curve in one image plane.

    fields:     field values as given: angles in degrees (``field_kind="angle"`` or
                ``"nominal-angle"``) or object heights in mm (``"height"``).
    field_kind: ``"angle"`` (object at infinity), ``"height"`` or ``"nominal-angle"`` (finite
                conjugates; a nominal angle α stands for the object height ``y = p0·tan α``).
    x:          abscissa of orthoscopy: ``tan α`` (object at infinity) or the object height y (mm).
    y0p:        ideal image size ``y0' = K0·x`` (mm).
    D0:         linear distortion ``y' − y0'`` (mm), Eq. (9).
    constant:   K0: F0 (mm) for an object at infinity, M0 (dimensionless) for finite conjugates.
    name, plane, source: free text for titles and tables (lens, image plane, origin).
    decimals:   decimals to print linear quantities with (3 reproduces the paper's Tables I–II).
    """

    fields: np.ndarray
    field_kind: str
    x: np.ndarray
    y0p: np.ndarray
    D0: np.ndarray
    constant: float
    name: str = ""
    plane: str = ""
    source: str = ""
    decimals: int = 4
    extra: dict = field(default_factory=dict, compare=False)

    @property
    def finite(self) -> bool:
        """True for finite conjugates (constant M0), False for an object at infinity (F0)."""
        return self.field_kind != ANGLE

    @property
    def symbol(self) -> str:
        """``"F"`` (object at infinity) or ``"M"`` (finite conjugates)."""
        return "M" if self.finite else "F"

    @property
    def yp(self) -> np.ndarray:
        """Actual image size ``y' = y0' + D0`` (mm)."""
        return self.y0p + self.D0

    @property
    def Dr(self) -> np.ndarray:
        """Characteristic relative distortion ``D0 / y0'`` as a fraction; 0 on the axis."""
        with np.errstate(divide="ignore", invalid="ignore"):
            r = np.where(self.y0p != 0.0, self.D0 / np.where(self.y0p != 0.0, self.y0p, 1.0), 0.0)
        return r

    @property
    def field_label(self) -> str:
        return {ANGLE: "α (deg)", HEIGHT: "y (mm)", NOMINAL_ANGLE: "nominal α (deg)"}[
            self.field_kind
        ]

    def __len__(self) -> int:
        return int(self.fields.size)


def make_curve(
    fields,
    D0,
    *,
    field_kind: str = ANGLE,
    constant: float,
    x=None,
    y0p=None,
    name: str = "",
    plane: str = "",
    source: str = "",
    decimals: int = 4,
) -> DistortionCurve:
    """Build a :class:`DistortionCurve` from arrays, computing ``x`` and ``y0'`` when not given
    (``x = tan α`` for angles, ``x = y`` for heights; a nominal-angle curve needs ``x``)."""
    if field_kind not in FIELD_KINDS:
        raise ValueError(f"unknown field kind {field_kind!r}; expected one of {FIELD_KINDS}")
    f = np.asarray(fields, dtype=float).ravel()
    d = np.asarray(D0, dtype=float).ravel()
    if x is None:
        if field_kind == ANGLE:
            x = np.tan(np.radians(f))
        elif field_kind == HEIGHT:
            x = f.copy()
        else:
            raise ValueError("a nominal-angle curve needs x (object heights y = p0 tan α)")
    xa = np.asarray(x, dtype=float).ravel()
    ya = constant * xa if y0p is None else np.asarray(y0p, dtype=float).ravel()
    if not (f.size == d.size == xa.size == ya.size):
        raise ValueError("fields, x, y0p and D0 must have the same length")
    return DistortionCurve(f, field_kind, xa, ya, d, float(constant), name, plane, source, decimals)


# --------------------------------------------------------------------------------------------
# CSV reader

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

    Raises :class:`raytrace.errors.DataError` naming the file and line for: an unreadable file,
    a missing header or column, an unparseable number, NaN/inf, a row with the wrong number of
    cells, non-monotonic fields, fewer than two off-axis rows, inconsistent y0' or Dr.
    ``text`` may carry the file's content (then ``path`` is only used in messages).
    """
    where = str(path)
    if text is None:
        try:
            text = Path(path).read_text(encoding="utf-8")
        except OSError as exc:
            raise DataError(f"{where}: cannot read distortion table ({exc.strerror})") from None
        except UnicodeDecodeError:
            raise DataError(f"{where}: not a text file (UTF-8 expected)") from None
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
            raise DataError(
                f"{where}:{hline}: unknown column {h!r}; expected a field column (alpha_deg or "
                "y_mm), then y0p_mm, D0_mm and optionally Dr_pct"
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
    if constant is None:
        K = float(np.dot(x[on], y0p[on]) / np.dot(x[on], x[on]))
        tol = 2.0 * tol_y
        origin = f"{sym} = {K:.6g} inferred from y0'/x"
    else:
        K = float(constant)
        if not math.isfinite(K) or K == 0.0:
            raise DataError(f"{where}: {sym} must be a finite nonzero number, got {constant!r}")
        tol = tol_y
        origin = f"{sym} = {K:.6g}"
    bad = np.nonzero(np.abs(y0p - K * x) > tol)[0]
    if bad.size:
        i = int(bad[0])
        raise DataError(
            f"{where}:{lines[i]}: y0' = {y0p[i]:g} mm is inconsistent with {origin} "
            f"({sym}·{'tan α' if kind == ANGLE else 'y'} = {K * x[i]:.6g} mm)"
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


# --------------------------------------------------------------------------------------------
# writers


def _fmt(v: float, dec: int, signed: bool) -> str:
    if not math.isfinite(v):
        return "nan"
    s = f"{v:+.{dec}f}" if signed else f"{v:.{dec}f}"
    if signed and float(s) == 0.0:
        s = f"{0.0:.{dec}f}"
    return s


def format_columns(
    title: list[str],
    field_label: str,
    fields: np.ndarray,
    quantities: list[tuple[str, np.ndarray, int, bool]],
    *,
    layout: str = "auto",
    width: int = 110,
) -> str:
    """Format a table with one column per field and one line per quantity (``layout="paper"``,
    Pestrecov's Tables I, II, V) or one line per field (``layout="rows"``). ``"auto"`` picks the
    paper layout when it fits in ``width`` characters, else rows (readable for long traced curves).

    ``quantities`` items are ``(label, values, decimals, signed)``.
    """
    if layout not in ("auto", "paper", "rows"):
        raise ValueError(f"unknown table layout {layout!r}; expected auto, paper or rows")
    fcells = [f"{v:g}" for v in fields]
    qcells = [[_fmt(float(v), dec, sg) for v in vals] for _, vals, dec, sg in quantities]
    labels = [field_label] + [q[0] for q in quantities]
    lw = max(len(s) for s in labels)
    cw = max([len(c) for c in fcells] + [len(c) for row in qcells for c in row]) + 2
    if layout == "auto":
        layout = "paper" if lw + cw * len(fcells) <= width else "rows"
    out = list(title)
    if layout == "paper":
        out.append(labels[0].ljust(lw) + "".join(c.rjust(cw) for c in fcells))
        out.append("-" * (lw + cw * len(fcells)))
        for lab, row in zip(labels[1:], qcells, strict=True):
            out.append(lab.ljust(lw) + "".join(c.rjust(cw) for c in row))
    else:
        widths = [max(len(labels[0]), *(len(c) for c in fcells))] + [
            max(len(labels[j + 1]), *(len(c) for c in qcells[j])) for j in range(len(qcells))
        ]
        out.append("  ".join(lab.rjust(w) for lab, w in zip(labels, widths, strict=True)))
        out.append("  ".join("-" * w for w in widths))
        for i, fc in enumerate(fcells):
            cells = [fc] + [qcells[j][i] for j in range(len(qcells))]
            out.append("  ".join(c.rjust(w) for c, w in zip(cells, widths, strict=True)))
    return "\n".join(out)


def format_curve(
    curve: DistortionCurve, *, layout: str = "auto", decimals: int | None = None
) -> str:
    """The characteristic distortion table in the layout of Pestrecov's Table I (fields across,
    quantities down) or one row per field; see :func:`format_columns` for ``layout``."""
    dec = curve.decimals if decimals is None else decimals
    k = curve.symbol + "0"
    unit = " mm" if not curve.finite else ""
    title = [
        " ".join(p for p in (curve.name, curve.plane) if p) + " — characteristic distortion data",
        f"{k} = {curve.constant:.{max(dec, 3)}f}{unit}",
    ]
    q = [
        ("y0' (mm)", curve.y0p, dec, False),
        ("D0 (mm)", curve.D0, dec, True),
        ("Dr (%)", 100.0 * curve.Dr, dec, True),
    ]
    return format_columns(title, curve.field_label, curve.fields, q, layout=layout)


def curve_to_dict(curve: DistortionCurve) -> dict:
    """JSON-ready dict of a curve (lists of floats; Dr as a fraction and in per cent)."""
    return {
        "name": curve.name,
        "plane": curve.plane,
        "source": curve.source,
        "field_kind": curve.field_kind,
        "conjugates": "finite" if curve.finite else "infinite",
        curve.symbol + "0": curve.constant,
        "fields": curve.fields.tolist(),
        "x": curve.x.tolist(),
        "y0p_mm": curve.y0p.tolist(),
        "yp_mm": curve.yp.tolist(),
        "D0_mm": curve.D0.tolist(),
        "Dr": curve.Dr.tolist(),
        "Dr_pct": (100.0 * curve.Dr).tolist(),
    }


def curve_to_csv(curve: DistortionCurve, *, decimals: int | None = None) -> str:
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
