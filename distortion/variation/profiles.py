"""Measured-data mode: read radial distortion profiles from a CSV file.

File format (UTF-8 text)::

    # source: who measured it, where it was published        <- free comments start with '#'
    # focal_length_mm: 45                                     <- optional metadata, 'key: value'
    r_mm, dr_um, focus, object                                <- header (any column order)
    4, 2.4, 8, 1.5
    ...

Columns (names case-insensitive):

* ``r_mm`` — radial distance in the image, millimetres.
* ``dr_um`` or ``dr_mm`` — radial distortion δr, micrometres or millimetres (the unit must be in
  the name), positive outward. Stored in µm.
* ``focus`` — the distance the lens is focused on; ``object`` — the object-plane distance.
  Each value is either metres from the lens (``1.5``, ``inf``) or an image scale ``12x``
  (also ``12X``, ``12×``: Gaussian magnification −1/12). One unit per column: a column mixing
  image scales and metres is an error. ``focus_m``/``object_m`` force metres,
  ``focus_x``/``object_x`` force image scales (values may then omit the ``x``).

Rows with the same (focus, object) form one profile (radii sorted; duplicates are an error).
Metadata keys: ``focal_length_mm`` (needed for distances in metres), ``source``, ``lens``.
Errors raise :class:`raytrace.errors.DataError` as ``path:line: message``.
"""

from __future__ import annotations

import csv
import math
import warnings
from pathlib import Path

import numpy as np

from ..coefficients import MAX_RADIUS_RATIO, check_profile_units
from ..errors import DataError, UnitWarning, read_text
from .analysis import Profile, ProfileSet, VariationAnalysis, analyze_variation
from .models import PLAIN_METRES_WARN, WEAK_THRESHOLD_UM, Conjugate

_SCALE_SUFFIXES = ("x", "X", "×")


def _err(path, line, msg) -> DataError:
    where = f"{path}:{line}" if line is not None else f"{path}"
    return DataError(f"{where}: {msg}")


def _parse_number(text: str, col: str, path, line) -> float:
    try:
        v = float(text)
    except ValueError:
        raise _err(path, line, f"column {col!r}: {text!r} is not a number") from None
    if math.isnan(v):
        raise _err(path, line, f"column {col!r}: NaN is not allowed")
    return v


def _parse_conjugate(text: str, col: str, forced: str | None, path, line) -> Conjugate:
    t = text.strip()
    is_scale = t.endswith(_SCALE_SUFFIXES)
    if forced == "m" and is_scale:
        raise _err(path, line, f"column {col!r} is in metres but {t!r} is an image scale")
    if is_scale or forced == "x":
        num = t[:-1].strip() if is_scale else t
        v = _parse_number(num, col, path, line)
        if not (v > 0 and math.isfinite(v)):
            raise _err(path, line, f"column {col!r}: image scale {t!r} must be positive, finite")
        return Conjugate(v, "x", t)
    v = _parse_number(t, col, path, line)
    if not v > 0:
        raise _err(path, line, f"column {col!r}: distance {t!r} m must be positive")
    return Conjugate(v, "m", t)


def read_profiles_csv(
    path: str | Path, *, focal_length_mm: float | None = None, min_profiles: int = 2
) -> ProfileSet:
    """Read a CSV of radial distortion profiles (format in the module docstring).

    Rows with the same (focus, object) pair form one profile δr(r) of Fraser & Shortis (1992): the
    lens focused at ``focus`` (s), the object plane at ``object`` (s'); δr_ss' when they differ,
    the Gaussian profile δr_s when they are the same.

    Parameters
    ----------
    path : str or Path
        The CSV file (UTF-8 text; a byte-order mark is allowed).
    focal_length_mm : float, optional
        Focal length f in mm; overrides the file's ``# focal_length_mm:`` metadata. Needed to turn
        distances in metres into image scales (Eq. 2); must be positive and finite.
    min_profiles : int
        The fewest profiles the file must hold: 2 (default, what a variation analysis needs), 1
        for a coefficient fit of a single profile.

    Returns
    -------
    ProfileSet
        The profiles (radii r in mm sorted ascending, δr in µm, positive outward; ``dr_mm``
        columns are converted to µm), the focal length in mm (None when neither the file nor
        ``focal_length_mm`` gives it), the file name and the file's comments.

    Raises
    ------
    DataError
        Naming the file (and line) for: an unreadable or non-UTF-8 file; a missing header or
        missing columns (also units not stated in the column names, or columns separated by
        something other than commas); a row with the wrong number of values; a non-numeric or NaN
        value; a negative or non-finite radius, a non-finite δr; a distance or image scale that is
        not positive; a column mixing image scales and metres; duplicate radii; a profile of one
        point; |δr| ≥ r (radii in metres or δr in mm under a µm label); fewer than
        ``min_profiles`` profiles; a focal length that is not positive, that is smaller than the
        largest radius / 19 (metres?), or that is not shorter than a distance given in metres.

    Warns
    -----
    UnitWarning
        When distances in metres are so large that they look like millimetres.
    """
    path = Path(path)
    text = read_text(path, "a distortion profile")
    meta: dict[str, str] = {}
    notes: list[str] = []
    header: list[str] | None = None
    header_line = 0
    rows: list[tuple[int, list[str]]] = []
    for lineno, raw in enumerate(text.splitlines(), start=1):
        s = raw.strip()
        if not s:
            continue
        if s.startswith("#"):
            body = s.lstrip("#").strip()
            k, sep, v = body.partition(":")
            if sep and k.strip().lower() in ("focal_length_mm", "source", "lens"):
                meta[k.strip().lower()] = v.strip()
            elif body:
                notes.append(body)
            continue
        cells = [c.strip() for c in next(csv.reader([s]))]
        if header is None:
            header, header_line = [c.lower() for c in cells], lineno
            continue
        rows.append((lineno, cells))
    if header is None:
        raise _err(path, None, "no header line (expected e.g. 'r_mm, dr_um, focus, object')")

    def find(*names: str) -> tuple[int, str] | None:
        for n in names:
            if n in header:
                return header.index(n), n
        return None

    r_col = find("r_mm")
    dr_col = find("dr_um", "dr_mm")
    f_col = find("focus", "focus_m", "focus_x")
    o_col = find("object", "object_m", "object_x")
    missing = []
    if r_col is None:
        hint = " (state the unit: 'r_mm')" if find("r", "radius") else ""
        missing.append("'r_mm'" + hint)
    if dr_col is None:
        hint = " (state the unit: 'dr_um' or 'dr_mm')" if find("dr", "distortion") else ""
        missing.append("'dr_um' or 'dr_mm'" + hint)
    if f_col is None:
        missing.append("'focus'")
    if o_col is None:
        missing.append("'object'")
    if missing:
        sep = next((c for c in ";\t|" if any(c in h for h in header)), None)
        if sep:
            raise _err(
                path,
                header_line,
                f"columns separated by {sep!r}: separate them with commas (header {header!r})",
            )
        raise _err(
            path,
            header_line,
            "missing column(s) " + ", ".join(missing) + f" in header {header!r}; each row needs "
            "r_mm, dr_um, and the profile's focused distance 'focus' and object distance "
            "'object' (metres, or image scale like '12x')",
        )
    dr_scale = 1000.0 if dr_col[1] == "dr_mm" else 1.0
    forced = {
        "focus": "m" if f_col[1].endswith("_m") else "x" if f_col[1].endswith("_x") else None,
        "object": "m" if o_col[1].endswith("_m") else "x" if o_col[1].endswith("_x") else None,
    }
    f_mm = focal_length_mm
    if f_mm is None and "focal_length_mm" in meta:
        f_mm = _parse_number(meta["focal_length_mm"], "focal_length_mm", path, None)
    if f_mm is not None and not (f_mm > 0 and math.isfinite(f_mm)):
        raise _err(path, None, f"focal length must be positive, got {f_mm!r}")

    groups: dict[tuple, dict] = {}
    first_unit: dict[str, tuple[str, int, str]] = {}
    ncols = len(header)
    for lineno, cells in rows:
        if len(cells) != ncols:
            raise _err(path, lineno, f"{len(cells)} values, the header has {ncols}")
        r = _parse_number(cells[r_col[0]], r_col[1], path, lineno)
        dr = _parse_number(cells[dr_col[0]], dr_col[1], path, lineno) * dr_scale
        if not (math.isfinite(r) and r >= 0):
            raise _err(path, lineno, f"radial distance {cells[r_col[0]]!r} must be >= 0, finite")
        if not math.isfinite(dr):
            raise _err(path, lineno, f"distortion {cells[dr_col[0]]!r} must be finite")
        conj = {}
        for name, (idx, col) in (("focus", f_col), ("object", o_col)):
            c = _parse_conjugate(cells[idx], col, forced[name], path, lineno)
            if name not in first_unit:
                first_unit[name] = (c.unit, lineno, cells[idx])
            elif first_unit[name][0] != c.unit:
                u0, l0, t0 = first_unit[name]
                kind = {"x": "image scales", "m": "metres"}
                raise _err(
                    path,
                    lineno,
                    f"column {col!r} mixes units: {kind[c.unit]} ({cells[idx]!r}) here, "
                    f"{kind[u0]} ({t0!r}) on line {l0}; use one unit per column",
                )
            conj[name] = c
        k = (conj["focus"].unit, conj["focus"].value, conj["object"].unit, conj["object"].value)
        g = groups.setdefault(
            k, {"focus": conj["focus"], "object": conj["object"], "line": lineno, "pts": []}
        )
        g["pts"].append((r, dr, lineno, conj["focus"].text, conj["object"].text))

    profiles = []
    for g in groups.values():
        pts = sorted(g["pts"])
        rr = np.array([p[0] for p in pts])
        dd = np.array([p[1] for p in pts])
        label = f"focus {g['focus'].text}, object {g['object'].text}"
        dup = np.nonzero(np.diff(rr) == 0)[0]
        if dup.size:
            a, b = pts[dup[0]], pts[dup[0] + 1]
            if a[3:] != b[3:]:  # one plane written two ways (1.5 and 1.50)
                raise _err(
                    path,
                    b[2],
                    f"focus {b[3]}, object {b[4]} is the same profile as focus {a[3]}, object "
                    f"{a[4]} on line {a[2]} (radius {rr[dup[0]]:g} mm in both): write each "
                    "distance once, one way",
                )
            raise _err(path, b[2], f"profile ({label}): radius {rr[dup[0]]:g} mm twice")
        check_profile_units(rr, dd, [f"{path}:{q[2]}: " for q in pts])
        if rr.size < 2:
            raise _err(path, g["line"], f"profile ({label}) has only one point")
        profiles.append(Profile(g["focus"], g["object"], rr, dd, g["line"]))
    if len(profiles) < min_profiles:
        only = (
            f" (focus {profiles[0].focus.text}, object {profiles[0].obj.text})" if profiles else ""
        )
        raise _err(
            path,
            header_line,
            f"{len(profiles)} profile(s){only}: a variation analysis needs at least two "
            "profiles (different object planes and/or focus settings)"
            if min_profiles >= 2
            else "no profile: the file holds no data rows under its header",
        )
    _warn_plain_metres(profiles, path)
    if f_mm is not None:
        r_top = max(float(p.r_mm[-1]) for p in profiles)
        if r_top / f_mm > MAX_RADIUS_RATIO:
            raise _err(
                path,
                None,
                f"focal length {f_mm:g} mm is {r_top / f_mm:.3g} times smaller than the largest "
                f"radius {r_top:g} mm: is it in metres? (the focal length is in mm)",
            )
        for p in profiles:
            for c in (p.focus, p.obj):
                if c.unit == "m" and not c.value * 1000.0 > f_mm:
                    raise _err(
                        path, p.line, f"distance {c.text} m is inside the focal length {f_mm:g} mm"
                    )
    src = meta.get("source", "")
    return ProfileSet(
        tuple(profiles), f_mm, str(path), tuple(([f"source: {src}"] if src else []) + notes)
    )


def _warn_plain_metres(profiles, path) -> None:
    """One UnitWarning per column whose distances in metres look like millimetres."""
    for col in ("focus", "object"):
        big = [
            (p.line, c)
            for p in profiles
            for c in ([p.focus] if col == "focus" else [p.obj])
            if c.unit == "m" and math.isfinite(c.value) and c.value >= PLAIN_METRES_WARN
        ]
        if big:
            line, c = min(big, key=lambda lc: lc[0])
            warnings.warn(
                UnitWarning(
                    f"{path}:{line}: {col} {c.text!r} is read as {c.value:g} m from the lens "
                    "(the column is in metres); it looks like millimetres: give the distances "
                    "in metres"
                ),
                stacklevel=3,
            )


def analyze_csv(
    path: str | Path,
    *,
    focal_length_mm: float | None = None,
    r_min: float | None = None,
    r_max: float | None = None,
    threshold_um: float = WEAK_THRESHOLD_UM,
    method: str = "lsq",
) -> VariationAnalysis:
    """Read ``path`` (:func:`read_profiles_csv`) and run :func:`analyze_variation` on it
    (Fraser & Shortis 1992, Eqs. 1–4 and 6).

    Parameters
    ----------
    path : str or Path
        A profile CSV (format in :mod:`distortion.variation.profiles`) with at least two profiles.
    focal_length_mm : float, optional
        Focal length f in mm, overriding the file's ``# focal_length_mm:`` metadata; γ_ss'
        (Eq. 2) needs it when the distances are in metres.
    r_min, r_max, threshold_um, method
        As :func:`analyze_variation`: the radial range over which g_ss' is estimated (mm;
        default all common radii), the weak-determination threshold (µm; default
        :data:`~distortion.variation.models.WEAK_THRESHOLD_UM`, 0.5 µm) and the g_ss' estimate
        (``"lsq"``, the default, or ``"mean"``).

    Returns
    -------
    VariationAnalysis
        As :func:`analyze_variation` returns it.

    Raises
    ------
    DataError
        For a file :func:`read_profiles_csv` refuses, or options :func:`analyze_variation`
        refuses.
    """
    ps = read_profiles_csv(path, focal_length_mm=focal_length_mm)
    return analyze_variation(ps, r_min=r_min, r_max=r_max, threshold_um=threshold_um, method=method)
