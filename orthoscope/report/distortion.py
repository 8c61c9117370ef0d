"""Text, JSON and CSV of the distortion results: characteristic curves (Pestrecov's Tables I and
V), calibrations (Table II) and compensation residuals (Section VI)."""

from __future__ import annotations

from distortion.calibration import CalibrationResult
from distortion.characteristic import CharacteristicDistortion
from distortion.compensation import CompensationResult
from distortion.curve import ANGLE, HEIGHT, NOMINAL_ANGLE, DistortionCurve
from raytrace.trace.results import status_name

from .jsonout import copy_fields, float_list
from .text import csv_text, format_columns, untraced


def format_curve(
    curve: DistortionCurve, *, layout: str = "rows", decimals: int | None = None
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
        **copy_fields(curve, "name", "plane", "source", "field_kind"),
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


def format_characteristic(
    res: CharacteristicDistortion, *, decimals: int = 4, layout: str = "rows"
) -> str:
    """Text table. One plane: Pestrecov's Table I layout (y, y0', y', D0, Dr per field). Several
    planes: Table V layout — D0 (mm) per field (rows) and plane (columns, headed by s')."""
    s = res.symbol
    unit = " mm" if not res.finite else ""
    head = [
        f"{res.name} — distortion ({res.reference}); object distance {res.object_distance:g} mm"
    ]
    flabel = {ANGLE: "α (deg)", HEIGHT: "y (mm)", NOMINAL_ANGLE: "nominal α (deg)"}[res.field_kind]
    tail = untraced(res.fields, res.status)
    if res.n_planes == 1:
        head.append(
            f"{res.plane_label(0)};  {s}0 = {res.constant[0]:.6f}{unit};  "
            f"scale = {res.scale[0]:.6f}{unit}"
        )
        q = []
        if res.finite and res.field_kind != HEIGHT:  # a height field is y already
            q.append(("y (mm)", res.x, decimals, True))
        q += [
            ("y0' (mm)", res.y0p[0], decimals, True),
            ("y' (mm)", res.yp[0], decimals, True),
            ("D0 (mm)", res.D0[0], decimals, True),
            ("Dr (%)", 100.0 * res.Dr[0], decimals, True),
        ]
        return "\n".join([format_columns(head, flabel, res.fields, q, layout=layout)] + tail)
    head.append("Linear distortion D0 (mm) in image planes at s' (mm from H'):")
    for i in range(res.n_planes):
        head.append(f"  {res.plane_label(i)}: {s}0 = {res.constant[i]:.6f}{unit}")
    q = [(f"s'={res.s_prime[i]:.1f}", res.D0[i], decimals, True) for i in range(res.n_planes)]
    return "\n".join([format_columns(head, flabel, res.fields, q, layout=layout)] + tail)


def characteristic_to_dict(res: CharacteristicDistortion) -> dict:
    """JSON-ready dict of a traced distortion result (keys carry units; see jsonout)."""
    return {
        "lens": res.name,
        "reference": res.reference,
        "field_kind": res.field_kind,
        "object_distance_mm": res.object_distance,
        "fields": float_list(res.fields),
        "x": float_list(res.x),
        "y_mm": float_list(res.y),
        "status": [status_name(c) for c in res.status],
        "gaussian_constant": res.gaussian_constant,
        "planes": [
            {
                "z_mm": float(res.z_planes[i]),
                "s_prime_mm": float(res.s_prime[i]),
                "from_last_vertex_mm": float(res.from_last_vertex[i]),
                "defocus_mm": float(res.defocus[i]),
                "F0_mm" if res.symbol == "F" else "M0": float(res.constant[i]),
                "scale": float(res.scale[i]),
                "y0p_mm": float_list(res.y0p[i]),
                "yp_mm": float_list(res.yp[i]),
                "D0_mm": float_list(res.D0[i]),
                "Dr": float_list(res.Dr[i]),
                "Dr_pct": float_list(100.0 * res.Dr[i]),
            }
            for i in range(res.n_planes)
        ],
    }


def format_calibration(
    res: CalibrationResult, *, layout: str = "rows", decimals: int | None = None
) -> str:
    """Pestrecov's Table II layout: the calibrated constant, then per field y_c', D_c and D_rc (%),
    followed by the summary (scale error, ρ, ρ_k, D_rc on the axis, max |D_c|, spreads)."""
    c = res.curve
    dec = c.decimals if decimals is None else decimals
    s = res.symbol
    unit = " mm" if not c.finite else ""
    at = f" at {', '.join(f'{a:g}' for a in res.at)}" if res.at else ""
    title = [
        " ".join(p for p in (c.name, c.plane) if p) + " — calibrated distortion data",
        f"{s}_c = {res.Kc:.{max(dec, 3)}f}{unit}   ({res.method}{at}; {s}0 = "
        f"{res.K0:.{max(dec, 3)}f}{unit})",
    ]
    q = [
        ("Yc' (mm)", res.ycp, dec, False),
        ("Dc (mm)", res.Dc, dec, True),
        ("Drc (%)", 100.0 * res.Drc, dec, True),
    ]
    table = format_columns(title, c.field_label, c.fields, q, layout=layout)
    summary = [
        "",
        f"{s}_c/{s}0 - 1 = tan rho = {res.scale_error:+.6e}   rho = {res.rho_deg:.4f} deg   "
        f"rho_k = {res.rho_k_deg:.2f} deg (k = {res.k:g})",
        f"Drc on the axis (Eq. 15) = {100 * res.Drc_axis:+.{dec}f} %",
        f"max |D0| = {res.D0_max_abs:.{dec}f} mm, spread {res.D0_spread:.{dec}f} mm;  "
        f"max |Dc| = {res.Dc_max_abs:.{dec}f} mm, spread {res.Dc_spread:.{dec}f} mm",
        f"spread of Dr = {100 * res.Dr_spread:.{dec}f} %, "
        f"of Drc = {100 * res.Drc_spread:.{dec}f} %",
    ]
    return table + "\n".join(summary)


def calibration_to_dict(res: CalibrationResult) -> dict:
    """JSON-ready dict of a calibration (relative quantities as fractions and in per cent)."""
    s = res.symbol
    return {
        "method": res.method,
        "at": list(res.at),
        f"{s}0": res.K0,
        f"{s}c": res.Kc,
        **copy_fields(res, "scale_error", "rho_deg", "k", "rho_k_deg", "Drc_axis"),
        "Drc_axis_pct": 100.0 * res.Drc_axis,
        "Dc_max_abs_mm": res.Dc_max_abs,
        "Dc_spread_mm": res.Dc_spread,
        "D0_max_abs_mm": res.D0_max_abs,
        "D0_spread_mm": res.D0_spread,
        "Dr_spread": res.Dr_spread,
        "Drc_spread": res.Drc_spread,
        "ycp_mm": res.ycp.tolist(),
        "Dc_mm": res.Dc.tolist(),
        "Drc": res.Drc.tolist(),
        "Drc_pct": (100.0 * res.Drc).tolist(),
        "characteristic": curve_to_dict(res.curve),
    }


def format_compensation(res: CompensationResult, *, layout: str = "rows", decimals: int = 4) -> str:
    """Text table: per camera field D1, D2 (negative plane), residual R, the print's distortion."""
    title = [
        "Distortion compensation (Pestrecov Eq. 16): camera F1 = "
        f"{res.F1:.4f} mm, printer M2 = {res.M2:.6f}, M = {res.M:.6f} ({res.method})",
        f"max |R| = {res.max_abs:.{decimals}f} mm (negative plane), "
        f"spread {res.spread:.{decimals}f} mm",
    ]
    q = [
        ("F1 tan α (mm)", res.y1, 3, False),
        ("D1 (mm)", res.D1, decimals, True),
        ("D2 (mm)", res.D2, decimals, True),
        ("R (mm)", res.residual, decimals, True),
        ("print (mm)", res.print_residual, decimals, True),
    ]
    return format_columns(title, "α (deg)", res.alpha_deg, q, layout=layout)


def compensation_to_dict(res: CompensationResult) -> dict:
    """JSON-ready dict of a compensation result: lengths carry ``_mm`` (the camera's F1 as
    ``F1_mm``); the magnifications ``M2`` (the printer's) and ``M`` (the print's, Eq. 16) are
    plain numbers, as ``M0`` in the distortion JSON."""
    return {
        "F1_mm": res.F1,
        **copy_fields(res, "M2", "M", "method", "alpha_deg"),
        "y1_mm": res.y1.tolist(),
        "yp_mm": res.yp.tolist(),
        "D1_mm": res.D1.tolist(),
        "D2_mm": res.D2.tolist(),
        "residual_mm": res.residual.tolist(),
        "print_residual_mm": res.print_residual.tolist(),
        "max_abs_mm": res.max_abs,
        "spread_mm": res.spread,
    }


def characteristic_csv(res: CharacteristicDistortion) -> str:
    """CSV: one row per (plane, field) with s', defocus, field, y, y0', y', D0, Dr (%), status."""
    fname = {ANGLE: "alpha_deg", HEIGHT: "y_mm", NOMINAL_ANGLE: "nominal_alpha_deg"}[res.field_kind]
    rows = []
    for p in range(res.n_planes):
        for i in range(res.fields.size):
            ok = res.status[i] == 0
            rows.append(
                [
                    float(res.s_prime[p]),
                    float(res.defocus[p]),
                    float(res.fields[i]),
                    float(res.y[i]),
                    float(res.y0p[p, i]),
                    float(res.yp[p, i]) if ok else None,
                    float(res.D0[p, i]) if ok else None,
                    float(100.0 * res.Dr[p, i]) if ok else None,
                    status_name(res.status[i]),
                ]
            )
    head = ["s_prime_mm", "defocus_mm", fname, "y_mm", "y0p_mm", "yp_mm", "D0_mm", "Dr_pct"]
    return csv_text(head + ["status"], rows)


def calibration_csv(res: CalibrationResult) -> str:
    """CSV: one row per field with y_c', D_c and D_rc (%)."""
    c = res.curve
    fname = "alpha_deg" if not c.finite else "y_mm"
    rows = [
        [float(c.fields[i]), float(res.ycp[i]), float(res.Dc[i]), float(100 * res.Drc[i])]
        for i in range(c.fields.size)
    ]
    return csv_text([fname, "ycp_mm", "Dc_mm", "Drc_pct"], rows)
