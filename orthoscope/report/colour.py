"""Text and JSON of the colour results (``orthoscope colour``, ``orthoscope distortion
--wavelengths``): focal shift, lateral colour and distortion per wavelength. Every table says
which wavelengths were compared and which constant the distortion is measured against."""

from __future__ import annotations

import math

import numpy as np

from distortion.characteristic import ChromaticDistortion
from distortion.colour import FocalShift, LateralColour
from raytrace.trace.results import field_unit, status_name

from .text import format_columns


def _obj(od: float) -> str:
    return "object at infinity" if math.isinf(od) else f"object {od:.6g} mm before the first vertex"


def _field_label(kind: str) -> str:
    return "object height (mm)" if kind == "height" else "field (deg)"


def status_names(status: np.ndarray) -> list:
    """A status array (any shape) as nested lists of the status words of the other commands'
    JSON (``"ok"``, ``"aim_failed"``, ...: :func:`raytrace.trace.results.status_name`)."""
    a = np.asarray(status)
    if a.ndim == 0:
        return status_name(int(a))
    return [status_names(row) for row in a]


def untraced_note(status: np.ndarray, fields: np.ndarray, wavelengths, kind: str) -> list[str]:
    """The line under a colour table for the rays that did not trace (``[]`` when all did):
    how many, that the table shows them as '-', and per field the wavelengths and status.
    ``status`` (m, n): wavelengths x fields."""
    st = np.asarray(status)
    bad = int(np.count_nonzero(st != 0))
    if not bad:
        return []
    unit = " " + field_unit(kind)
    parts = []
    for j, f in enumerate(fields):
        col = st[:, j]
        if not np.any(col != 0):
            continue
        names = ", ".join(dict.fromkeys(status_name(c) for c in col if c != 0))
        wl = ", ".join(f"{w:g}" for w, c in zip(wavelengths, col, strict=True) if c != 0)
        parts.append(f"{f + 0.0:g}{unit} at {wl} nm ({names})")
    return [
        f"{bad} wavelength x field ray(s) not traced (shown as -): " + "; ".join(parts),
    ]


# ------------------------------------------------------------------ focal shift
def format_focal_shift(fs: FocalShift) -> str:
    """The focal-shift curve as a table (one row per wavelength)."""
    what = (
        "paraxial image of the object"
        if fs.kind == "paraxial"
        else "plane of least RMS spot radius, axial point"
    )
    title = [
        f"{fs.name} — longitudinal colour (focal shift): {what}; {_obj(fs.object_distance)}",
        f"reference {fs.reference_wavelength:g} nm: plane {fs.reference_plane:.6f} mm from the "
        f"last vertex; shift = plane − reference plane (+ away from the lens); range "
        f"{fs.range * 1000:.3f} um",
    ]
    q = [
        ("plane from last vertex (mm)", fs.from_last_vertex, 6, False),
        ("shift (um)", 1000.0 * fs.shift, 3, True),
        ("EFL (mm)", fs.efl, 6, False),
    ]
    if fs.kind == "best-focus":
        q.append(("RMS radius (um)", 1000.0 * fs.rms_radius, 3, False))
    return format_columns(title, "wavelength (nm)", fs.wavelengths, q)


def focal_shift_to_dict(fs: FocalShift) -> dict:
    return {
        "name": fs.name,
        "kind": fs.kind,
        "object_distance_mm": fs.object_distance,
        "reference_wavelength_nm": fs.reference_wavelength,
        "reference_plane_from_last_vertex_mm": fs.reference_plane,
        "wavelength_nm": fs.wavelengths,
        "from_last_vertex_mm": fs.from_last_vertex,
        "shift_mm": fs.shift,
        "efl_mm": fs.efl,
        "rms_radius_mm": fs.rms_radius,
        "range_mm": fs.range,
    }


# ------------------------------------------------------------------ lateral colour
def format_lateral_colour(lc: LateralColour) -> str:
    """Lateral colour per field, one table per image plane."""
    w1, w2 = lc.wavelengths
    out = []
    for i in range(lc.n_planes):
        title = [
            f"{lc.name} — lateral colour dy' = y'({w1:g} nm) − y'({w2:g} nm), real chief rays; "
            f"{_obj(lc.distortion.object_distance)}",
            f"plane {lc.distortion.plane_label(i)}; relative = dy'/y'"
            f"({lc.reference_wavelength:g} nm)",
        ]
        q = [
            (f"y'({w1:g}) (mm)", lc.heights[0, i], 6, False),
            (f"y'({w2:g}) (mm)", lc.heights[1, i], 6, False),
            ("dy' (um)", 1000.0 * lc.linear[i], 3, True),
            ("relative (%)", 100.0 * lc.relative[i], 4, True),
        ]
        if i:
            out.append("")
        out.append(format_columns(title, _field_label(lc.field_kind), lc.fields, q))
    ws = (w1, w2, lc.reference_wavelength)
    out += untraced_note(lc.status, lc.fields, ws, lc.field_kind)
    return "\n".join(out)


def lateral_colour_to_dict(lc: LateralColour) -> dict:
    return {
        "name": lc.name,
        "wavelengths_nm": list(lc.wavelengths),
        "definition": "y'(wavelengths_nm[0]) - y'(wavelengths_nm[1]), real chief rays",
        "reference_wavelength_nm": lc.reference_wavelength,
        "field_kind": lc.field_kind,
        "fields": lc.fields,
        "object_distance_mm": lc.distortion.object_distance,
        "planes": [
            {
                "s_prime_mm": float(lc.s_prime[i]),
                "defocus_mm": float(lc.defocus[i]),
                "z_mm": float(lc.z_planes[i]),
                "yp_1_mm": lc.heights[0, i],
                "yp_2_mm": lc.heights[1, i],
                "yp_reference_mm": lc.heights[2, i],
                "lateral_colour_mm": lc.linear[i],
                "relative": lc.relative[i],
            }
            for i in range(lc.n_planes)
        ],
        "status": status_names(lc.status),
    }


# ------------------------------------------------------------------ distortion per wavelength
def format_chromatic_distortion(cd: ChromaticDistortion) -> str:
    """Characteristic distortion D0 and Dr at each wavelength, one table per image plane; the
    header says which F0/M0 every wavelength is measured against."""
    r0 = cd[0]
    sym = r0.symbol + "0"
    unit = "" if r0.finite else " mm"
    out = []
    for i in range(r0.n_planes):
        consts = ", ".join(
            f"{sym}({w:g}) = {c[i]:.6f}{unit}"
            for w, c in zip(cd.wavelengths, cd.constant, strict=True)
        )
        title = [
            f"{cd.name} — distortion per wavelength ({cd.reference}); {_obj(cd.object_distance)}",
            f"plane {cd.plane_label(i)}",
            f"scale: {cd.scale_description}: {consts}",
        ]
        q = [(f"D0 {w:g} (mm)", cd.D0[k, i], 6, True) for k, w in enumerate(cd.wavelengths)]
        q += [(f"Dr {w:g} (%)", 100.0 * cd.Dr[k, i], 4, True) for k, w in enumerate(cd.wavelengths)]
        if i:
            out.append("")
        out.append(format_columns(title, _field_label(r0.field_kind), cd.fields, q))
    out += untraced_note(cd.status, cd.fields, cd.wavelengths, r0.field_kind)
    return "\n".join(out)


def chromatic_distortion_to_dict(cd: ChromaticDistortion) -> dict:
    r0 = cd[0]
    return {
        "name": cd.name,
        "reference": cd.reference,
        "scale": cd.scale,
        "scale_description": cd.scale_description,
        "reference_wavelength_nm": cd.reference_wavelength,
        "wavelength_nm": cd.wavelengths,
        "field_kind": r0.field_kind,
        "fields": cd.fields,
        "x": cd.x,
        "object_distance_mm": cd.object_distance,
        "planes": [
            {
                "s_prime_mm": float(r0.z_planes[i] - cd.reference_paraxial.z_Hp),
                "z_mm": float(r0.z_planes[i]),
                "from_last_vertex_mm": float(r0.from_last_vertex[i]),
                "constant": cd.constant[:, i],
                "y0p_mm": cd.y0p[:, i],
                "yp_mm": cd.yp[:, i],
                "D0_mm": cd.D0[:, i],
                "Dr": cd.Dr[:, i],
            }
            for i in range(r0.n_planes)
        ],
        "status": status_names(cd.status),
    }
