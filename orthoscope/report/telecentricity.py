"""Text, JSON and CSV of the chief-ray angles, pupils and distortion slope per field
(``orthoscope pupils``; :mod:`distortion.telecentricity`)."""

from __future__ import annotations

import math

import numpy as np

from distortion.curve import ANGLE, HEIGHT, NOMINAL_ANGLE
from distortion.telecentricity import PupilAnalysis
from raytrace.trace.results import status_name

from .jsonout import float_list
from .text import csv_text, format_columns, untraced

_FIELD_LABEL = {ANGLE: "alpha (deg)", HEIGHT: "y (mm)", NOMINAL_ANGLE: "nominal alpha (deg)"}


def _z(v: float) -> str:
    return f"{v:.4f} mm" if math.isfinite(v) else ("inf" if v > 0 else "-inf")


def format_pupils(pa: PupilAnalysis, *, decimals: int = 4, layout: str = "rows") -> str:
    """Two tables: image side (CRA real and paraxial, real exit pupil, ∂D0/∂s') and object side
    (real entrance pupil and its shift, height in the E0 plane, viewpoint offset)."""
    par = pa.paraxial
    obj = (
        "object at infinity"
        if math.isinf(pa.object_distance)
        else (f"object {pa.object_distance:g} mm from the first vertex (s = {par.s:.4f} mm)")
    )
    flabel = _FIELD_LABEL[pa.field_kind]
    sym = "M0" if pa.finite else "F0"
    unit = " 1/mm" if pa.finite else ""
    head = [
        f"{pa.name} — chief-ray angles, pupils and distortion slope; {obj}; {pa.wavelength:g} nm",
        f"paraxial E0 at z = {_z(par.z_E0)}, E0' at z = {_z(par.z_E0p)}, m_e = {par.m_e:.6g}; "
        f"d{sym}/ds' = {pa.constant_slope:.6g}{unit}",
        f"max |CRA| = {pa.max_abs_cra_deg:.6g} deg (0 = telecentric in image space)"
        + ("; over the traced fields only" if np.any(pa.status != 0) else ""),
        "",
        "Image side: CRA = angle of the real chief ray after the last surface; exit pupil = "
        "where it crosses the axis;",
        "dD0/ds' = tan CRA - x d" + sym + "/ds' (exact: D0 is affine in s' for a fixed object)",
    ]
    img = [
        ("CRA (deg)", pa.cra_deg, decimals, True),
        ("paraxial (deg)", pa.cra_paraxial_deg, decimals, True),
        ("exit pupil z (mm)", pa.exit_pupil_z, decimals, True),
        ("shift from E0' (mm)", pa.exit_pupil_shift, decimals, True),
        ("dD0/ds' (um/mm)", 1000.0 * pa.slope, decimals, True),
    ]
    obj_head = [
        "",
        "Object side (viewpoint): entrance pupil = where the object-space chief ray crosses the "
        "axis; offset = distance of that ray from E0",
    ]
    objq = [
        ("theta (deg)", pa.theta_object_deg, decimals, True),
        ("entrance pupil z (mm)", pa.entrance_pupil_z, decimals, True),
        ("shift from E0 (mm)", pa.entrance_pupil_shift, decimals, True),
        ("height at E0 (mm)", pa.height_at_E0, decimals, True),
        ("viewpoint offset (mm)", pa.viewpoint_offset, decimals, True),
    ]
    tail = untraced(pa.fields, pa.status)
    at_inf = [f"{v:g}" for v, z in zip(pa.fields, pa.exit_pupil_z, strict=True) if np.isinf(z)]
    if at_inf:
        tail.append(
            "exit pupil at infinity (chief ray parallel to the axis) at: " + ", ".join(at_inf)
        )
    return "\n".join(
        [
            format_columns(head, flabel, pa.fields, img, layout=layout),
            format_columns(obj_head, flabel, pa.fields, objq, layout=layout),
            *tail,
        ]
    )


def pupils_to_dict(pa: PupilAnalysis) -> dict:
    """JSON-ready dict (keys carry units; infinite pupil positions as "inf"/"-inf")."""
    par = pa.paraxial
    return {
        "lens": pa.name,
        "field_kind": pa.field_kind,
        "fields": float_list(pa.fields),
        "object_distance_mm": pa.object_distance,
        "wavelength_nm": pa.wavelength,
        "paraxial": {
            "entrance_pupil_z_mm": par.z_E0,
            "exit_pupil_z_mm": par.z_E0p,
            "m_e": par.m_e,
            "constant_slope": pa.constant_slope,
            "constant_slope_unit": "1/mm" if pa.finite else "1",
        },
        "max_abs_cra_deg": pa.max_abs_cra_deg,
        "x": float_list(pa.x),
        "cra_deg": float_list(pa.cra_deg),
        "cra_paraxial_deg": float_list(pa.cra_paraxial_deg),
        "exit_pupil_z_mm": float_list(pa.exit_pupil_z),
        "exit_pupil_shift_mm": float_list(pa.exit_pupil_shift),
        "distortion_slope": float_list(pa.slope),
        "theta_object_deg": float_list(pa.theta_object_deg),
        "entrance_pupil_z_mm": float_list(pa.entrance_pupil_z),
        "entrance_pupil_shift_mm": float_list(pa.entrance_pupil_shift),
        "height_at_E0_mm": float_list(pa.height_at_E0),
        "viewpoint_offset_mm": float_list(pa.viewpoint_offset),
        "status": [status_name(c) for c in pa.status],
    }


def pupils_csv(pa: PupilAnalysis) -> str:
    """One row per field."""
    d = pupils_to_dict(pa)
    cols = [
        "cra_deg",
        "cra_paraxial_deg",
        "exit_pupil_z_mm",
        "exit_pupil_shift_mm",
        "distortion_slope",
        "theta_object_deg",
        "entrance_pupil_z_mm",
        "entrance_pupil_shift_mm",
        "height_at_E0_mm",
        "viewpoint_offset_mm",
    ]
    fname = {ANGLE: "angle_deg", HEIGHT: "object_height_mm", NOMINAL_ANGLE: "nominal_angle_deg"}[
        pa.field_kind
    ]
    rows = [
        [float(pa.fields[i])] + [d[c][i] for c in cols] + [d["status"][i]]
        for i in range(pa.fields.size)
    ]
    return csv_text([fname, *cols, "status"], rows)
