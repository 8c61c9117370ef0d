"""Text, JSON and CSV of the camera models of a prescription (:mod:`distortion.camera.traced`),
of a calibration compared with the prediction (:mod:`distortion.camera.compare`) and of the
tables of models per object distance (:mod:`distortion.camera.distance`).

Every output states the projection centre (the paraxial entrance pupil at the reference
wavelength), the object plane and the focus setting. JSON keys carry units (README, "JSON");
a model's parameters keep the target's own names, with their units in a ``units`` table.
"""

from __future__ import annotations

import math

from distortion.camera import (
    CameraComparison,
    CameraModel,
    CameraPoints,
    ModelTable,
    Sensor,
    TracedCamera,
)
from distortion.camera.models import OPENCV_ORDERS
from distortion.errors import DataError
from raytrace.trace.results import status_name

from .jsonout import copy_fields
from .text import csv_text
from .units import PARAMETER_UNITS

_PIXEL_PARAMS = ("f", "fx", "fy", "cx", "cy")
#: a fit whose (column-scaled) Jacobian is worse conditioned than this gets a note
CONDITION_NOTE = 1e5
_RADIAN_PARAMS = ("tau_x", "tau_y", "omega")


def parameter_units(camera: CameraModel) -> dict[str, str]:
    """The unit of each parameter of ``camera`` (the target's own: px for focal lengths and
    principal points — COLMAP and Metashape in their own pixel frames — rad for angles, mm for
    the Australis model, empty for dimensionless coefficients)."""
    out = {}
    for n in camera.spec.params:
        if camera.model == "australis":
            out[n] = PARAMETER_UNITS.get(n, "")
        elif n in _PIXEL_PARAMS:
            out[n] = "px"
        elif n in _RADIAN_PARAMS:
            out[n] = "rad"
        else:
            out[n] = ""
    return out


def _g(v: float, digits: int = 6) -> str:
    v = float(v)
    if math.isnan(v):
        return "-"
    if math.isinf(v):
        return "inf" if v > 0 else "-inf"
    return f"{v:.{digits}g}"


def _shown_params(camera: CameraModel) -> list[str]:
    if camera.model == "opencv":
        return ["fx", "fy", "cx", "cy", *OPENCV_ORDERS[camera.n_opencv_coefficients]]
    return list(camera.spec.params)


def _model_label(camera: CameraModel) -> str:
    if camera.model == "opencv":
        return f"opencv ({camera.n_opencv_coefficients} coefficients)"
    return camera.model


def sensor_to_dict(s: Sensor) -> dict:
    return copy_fields(
        s,
        "width_mm",
        "height_mm",
        "width_px",
        "height_px",
        "pixel_pitch_um",
        "principal_point_offset_mm",
    )


def _sensor_line(s: Sensor) -> str:
    px, py = s.pixel_pitch_um
    pitch = f"{px:.4g} um" if abs(px - py) <= 1e-9 * px else f"{px:.4g} x {py:.4g} um"
    dx, dy = s.principal_point_offset_mm
    off = "" if dx == dy == 0 else f", lens axis at ({dx:g}, {dy:g}) mm from the centre (y up)"
    return (
        f"Sensor {s.width_mm:g} x {s.height_mm:g} mm, {s.width_px} x {s.height_px} px, pitch "
        f"{pitch}{off}"
    )


def _geometry_lines(points: CameraPoints) -> list[str]:
    g = points.geometry
    obj = (
        "object at infinity"
        if g.infinite
        else f"object {g.object_distance:g} mm from the first vertex (s = {g.object_s:.6g} mm)"
    )
    lines = [
        _sensor_line(points.sensor),
        f"{obj}; {g.focus}: sensor plane {g.from_last_vertex:.6g} mm from the last vertex "
        f"(s' = {g.s_prime:.6g} mm, defocus {g.defocus:+.4g} mm); {g.wavelength:g} nm",
        g.projection_centre,
        f"paraxial camera constant in the sensor plane c = {g.camera_constant:.6f} mm "
        f"({g.camera_constant / points.sensor.pixel_size_mm[0]:.6g} px)",
    ]
    if points.pupils is not None:
        line = (
            f"real entrance pupil: shift from E0 up to {points.max_entrance_pupil_shift_mm:.4g} "
            f"mm, viewpoint offset up to {points.max_viewpoint_offset_mm:.4g} mm over the sensor"
        )
        if not g.infinite:
            line += (
                f" (seen from the object plane about {points.viewpoint_parallax_px:.3g} px, "
                "first order)"
            )
        lines.append(line)
    return lines


def _status_line(points: CameraPoints) -> list[str]:
    if not points.n_failed:
        return []
    counts: dict[str, int] = {}
    for s in points.status:
        if s != 0:
            k = status_name(s)
            counts[k] = counts.get(k, 0) + 1
    return [
        f"{points.n_failed} of {points.status.size} chief rays not traced (left out of the fit): "
        + ", ".join(f"{k} {v}" for k, v in counts.items())
    ]


def format_traced_camera(tc: TracedCamera) -> str:
    """The text report of a camera model fitted to a traced lens."""
    cam, pts, fit = tc.camera, tc.points, tc.fit
    lines = [
        f"{pts.geometry.lens_name} - camera model {_model_label(cam)} from "
        f"{fit.n_points} real chief rays ({pts.shape[1]} x {pts.shape[0]} over the sensor)",
        *_geometry_lines(pts),
        *_status_line(pts),
        f"model chosen by: {tc.criterion}",
    ]
    if tc.selection is not None:
        lines.append(f"  {'candidate':<28}{'free':>5}{'RMS (px)':>12}{'max (px)':>12}")
        for f in tc.selection.fits:
            mark = "  <- chosen" if f is tc.selection.chosen else ""
            lines.append(
                f"  {_model_label(f.camera):<28}{len(f.free):>5}{_g(f.rms_px, 3):>12}"
                f"{_g(f.max_px, 3):>12}{mark}"
            )
    units = parameter_units(cam)
    se = dict(zip(fit.free, fit.std_errors, strict=True))
    lines.append("")
    lines.append(f"  {'parameter':<10}{'value':>22}{'std error':>12}  unit")
    d = cam.as_dict()
    for n in _shown_params(cam):
        held = "" if n in se else "  (held)"
        lines.append(
            f"  {n:<10}{_g(d[n], 12):>22}{_g(se.get(n, math.nan), 3):>12}  {units[n]}{held}"
        )
    lines.append("")
    lines.append(
        f"fit residual against the traced image points: RMS {_g(tc.rms_px, 3)} px, max "
        f"{_g(tc.max_px, 3)} px (placement of the grid: within {_g(pts.placement_px, 2)} px)"
    )
    if fit.condition > CONDITION_NOTE:
        lines.append(
            f"condition number of the fit {_g(fit.condition, 3)}: the coefficients are strongly "
            "correlated (e.g. a rational numerator and denominator that nearly cancel) - the "
            "projection is determined, the individual coefficients are not"
        )
    try:
        lines.append("COLMAP cameras.txt: " + tc.colmap_line())
    except DataError:  # not every model has an exact COLMAP form
        lines.append("COLMAP cameras.txt: no exact COLMAP form (convert the model first)")
    return "\n".join(lines)


def pupils_to_dict(points: CameraPoints) -> dict | None:
    pa = points.pupils
    if pa is None:
        return None
    key = "angle_deg" if points.geometry.infinite else "object_height_mm"
    return {
        "wavelength_nm": pa.wavelength,
        key: pa.fields,
        "entrance_pupil_z_mm": pa.entrance_pupil_z,
        "entrance_pupil_shift_mm": pa.entrance_pupil_shift,
        "viewpoint_offset_mm": pa.viewpoint_offset,
        "max_entrance_pupil_shift_mm": points.max_entrance_pupil_shift_mm,
        "max_viewpoint_offset_mm": points.max_viewpoint_offset_mm,
        "viewpoint_parallax_px": points.viewpoint_parallax_px,
    }


def geometry_to_dict(points: CameraPoints) -> dict:
    g = points.geometry
    return {
        "object_distance_mm": g.object_distance,
        "s_mm": g.object_s,
        "focus": g.focus,
        "focus_object_distance_mm": g.focus_object_distance,
        "from_last_vertex_mm": g.from_last_vertex,
        "s_prime_mm": g.s_prime,
        "defocus_mm": g.defocus,
        "wavelength_nm": g.wavelength,
        "reference_wavelength_nm": g.reference_wavelength,
        "projection_centre": g.projection_centre,
        "projection_centre_z_mm": g.z_projection_centre,
        "camera_constant_mm": g.camera_constant,
        "efl_mm": g.efl,
    }


def camera_to_dict(cam: CameraModel) -> dict:
    out = {
        "model": cam.model,
        "image_width_px": cam.width,
        "image_height_px": cam.height,
        "parameters": cam.as_dict(),
        "units": parameter_units(cam),
    }
    if cam.pixel_size_mm is not None:
        out["pixel_size_mm"] = list(cam.pixel_size_mm)
    if cam.model == "opencv":
        d = cam.as_dict()
        out["opencv"] = {
            "camera_matrix": [[d["fx"], 0.0, d["cx"]], [0.0, d["fy"], d["cy"]], [0.0, 0.0, 1.0]],
            "dist_coeffs": [d[k] for k in OPENCV_ORDERS[cam.n_opencv_coefficients]],
        }
    return out


def traced_camera_to_dict(tc: TracedCamera) -> dict:
    """JSON-ready dict of a traced camera (keys with units)."""
    pts, fit = tc.points, tc.fit
    cam = camera_to_dict(tc.camera)
    cam.update(
        {
            "lens": pts.geometry.lens_name,
            "request": tc.request,
            "criterion": tc.criterion,
            "rms_px": tc.rms_px,
            "max_px": tc.max_px,
            "n_points": fit.n_points,
            "n_failed": pts.n_failed,
            "condition": fit.condition,
            "std_errors": dict(zip(fit.free, fit.std_errors, strict=True)),
            "candidates": [
                {
                    "model": f.camera.model,
                    "free": list(f.free),
                    "rms_px": f.rms_px,
                    "max_px": f.max_px,
                    "bic": f.bic,
                }
                for f in (tc.selection.fits if tc.selection else (fit,))
            ],  # fmt: skip
        }
    )
    try:
        cam["colmap_line"] = tc.colmap_line()
    except DataError:  # not every model has an exact COLMAP form
        cam["colmap_line"] = None
    return {
        "camera": cam,
        "sensor": sensor_to_dict(pts.sensor),
        "geometry": geometry_to_dict(pts),
        "pupils": pupils_to_dict(pts),
        "trace": {
            "grid": [pts.shape[1], pts.shape[0]],
            "placement_max_px": pts.placement_px,
            "n_failed": pts.n_failed,
        },
    }


def points_csv(tc: TracedCamera) -> str:
    """One row per traced chief ray: the ideal direction, the image point, the fitted model's
    residual (model − traced, px) and the trace status."""
    from distortion.camera import camera_residual

    pts = tc.points
    res = camera_residual(tc.camera, pts).residual_px
    head = [
        "x_ideal",
        "y_ideal",
        "u_px",
        "v_px",
        "x_mm",
        "y_mm",
        "residual_u_px",
        "residual_v_px",
        "status",
    ]
    rows = [
        [
            *pts.ideal[i],
            *pts.image_px[i],
            *pts.image_mm[i],
            *res[i],
            status_name(pts.status[i]),
        ]
        for i in range(pts.status.size)
    ]
    return csv_text(head, rows)


# ---- tables of models per object distance ------------------------------------------------------
def format_model_table(t: ModelTable) -> str:
    head, rows = t.rows()
    lines = [f"{t.name} - {t.model} models per object distance ({t.method}); {t.focus}"]
    lines += [f"  {n}" for n in t.notes]
    cells = [[_g(v, 8) if j else ("inf" if math.isinf(v) else f"{v:g}") for j, v in enumerate(r)]
             for r in rows]  # fmt: skip
    widths = [max(len(h), *(len(r[j]) for r in cells)) for j, h in enumerate(head)]
    lines.append("")
    lines.append("  ".join(h.rjust(w) for h, w in zip(head, widths, strict=True)))
    lines.append("  ".join("-" * w for w in widths))
    for r in cells:
        lines.append("  ".join(c.rjust(w) for c, w in zip(r, widths, strict=True)))
    return "\n".join(lines)


def model_table_to_dict(t: ModelTable) -> dict:
    head, rows = t.rows()
    return {
        "lens": t.name,
        "method": t.method,
        "focus": t.focus,
        "model": t.model,
        "notes": list(t.notes),
        "columns": head,
        "units": {
            "object_distance_mm": "mm",
            **parameter_units(t.cameras[0]),
            "rms_px": "px",
            "max_px": "px",
            "focused_model_rms_px": "px",
        },  # fmt: skip
        "rows": [dict(zip(head, r, strict=True)) for r in rows],
    }


def model_table_csv(t: ModelTable) -> str:
    head, rows = t.rows()
    return csv_text(head, rows)


# ---- comparison --------------------------------------------------------------------------------
def format_comparison(c: CameraComparison) -> str:
    lines = [
        f"{c.label_predicted} against {c.label_measured}: {_model_label(c.measured)} "
        f"{c.measured.width} x {c.measured.height} px",
        *(f"  {n}" for n in c.notes),
        "",
        f"distortion difference (predicted - measured, at the same offset from each principal "
        f"point): RMS {_g(c.rms_px, 3)} px, max {_g(c.max_px, 3)} px",
        f"projection difference for the same direction (includes principal point and distance): "
        f"RMS {_g(c.projection_rms_px, 3)} px, max {_g(c.projection_max_px, 3)} px",
        f"principal point predicted - measured: ({c.principal_point_difference_px[0]:+.4g}, "
        f"{c.principal_point_difference_px[1]:+.4g}) px; focal length fx, fy: "
        f"({c.focal_difference_px[0]:+.5g}, {c.focal_difference_px[1]:+.5g}) px",
        "",
        "radial distortion (azimuthal mean, positive outward, at the measured radius):",
    ]
    pm, pp = c.profile_measured, c.profile_predicted
    mm = pm.radius_mm is not None
    unit = "um" if mm else "px"
    lines.append(
        f"  {'r (mm)' if mm else 'r (px)':>10}{'measured (' + unit + ')':>18}"
        f"{'predicted (' + unit + ')':>18}{'difference':>14}  on sensor"
    )
    rr = pm.radius_mm if mm else pm.radius_px
    a = pm.dr_um if mm else pm.dr_px
    b = pp.dr_um if mm else pp.dr_px
    step = max(1, rr.size // 12)
    idx = list(range(0, rr.size, step))
    if idx[-1] != rr.size - 1:
        idx.append(rr.size - 1)
    for i in idx:
        lines.append(
            f"  {rr[i]:>10.4g}{_g(a[i], 5):>18}{_g(b[i], 5):>18}{_g(b[i] - a[i], 4):>14}"
            f"  {'yes' if pm.inside[i] else 'beyond the short side'}"
        )
    return "\n".join(lines)


def comparison_to_dict(c: CameraComparison) -> dict:
    pm, pp = c.profile_measured, c.profile_predicted
    out = {
        "labels": {"measured": c.label_measured, "predicted": c.label_predicted},
        "notes": list(c.notes),
        "measured": camera_to_dict(c.measured),
        "predicted": camera_to_dict(c.predicted),
        "distortion_difference_rms_px": c.rms_px,
        "distortion_difference_max_px": c.max_px,
        "projection_difference_rms_px": c.projection_rms_px,
        "projection_difference_max_px": c.projection_max_px,
        "principal_point_difference_px": list(c.principal_point_difference_px),
        "focal_length_difference_px": list(c.focal_difference_px),
        "radial_profile": {
            "radius_px": pm.radius_px,
            "radius_mm": pm.radius_mm,
            "measured_px": pm.dr_px,
            "predicted_px": pp.dr_px,
            "measured_um": pm.dr_um,
            "predicted_um": pp.dr_um,
            "on_sensor": pm.inside,
        },
        "map": {
            "u_px": c.image_px[..., 0],
            "v_px": c.image_px[..., 1],
            "difference_u_px": c.difference_px[..., 0],
            "difference_v_px": c.difference_px[..., 1],
        },
    }
    if c.prediction is not None:
        out["prediction"] = {
            "rms_px": c.prediction.rms_px,
            "max_px": c.prediction.max_px,
            "criterion": c.prediction.criterion,
            "geometry": geometry_to_dict(c.prediction.points),
            "pupils": pupils_to_dict(c.prediction.points),
        }
    return out


def comparison_csv(c: CameraComparison) -> str:
    """The radial profiles, one row per radius."""
    pm, pp = c.profile_measured, c.profile_predicted
    head = ["radius_px", "radius_mm", "measured_px", "predicted_px", "measured_um",
            "predicted_um", "on_sensor"]  # fmt: skip
    n = pm.radius_px.size
    rows = [
        [
            pm.radius_px[i],
            None if pm.radius_mm is None else pm.radius_mm[i],
            pm.dr_px[i],
            pp.dr_px[i],
            None if pm.dr_um is None else pm.dr_um[i],
            None if pp.dr_um is None else pp.dr_um[i],
            bool(pm.inside[i]),
        ]
        for i in range(n)
    ]
    return csv_text(head, rows)


def conversion_to_dict(conv) -> dict:
    return {
        "source": camera_to_dict(conv.source),
        "target": camera_to_dict(conv.camera),
        "method": conv.method,
        "rms_px": conv.rms_px,
        "max_px": conv.max_px,
        "n_points": conv.n_points,
        "lost_terms": list(conv.lost_terms),
    }


def format_conversion(conv) -> str:
    lines = [
        f"{conv.source.model} -> {conv.camera.model}: {conv.method}"
        + (f" (the target cannot hold: {', '.join(conv.lost_terms)})" if conv.lost_terms else ""),
        f"residual over the sensor ({conv.n_points} points): RMS {_g(conv.rms_px, 3)} px, max "
        f"{_g(conv.max_px, 3)} px",
    ]
    units = parameter_units(conv.camera)
    d = conv.camera.as_dict()
    for n in _shown_params(conv.camera):
        lines.append(f"  {n:<10}{_g(d[n], 12):>22}  {units[n]}")
    return "\n".join(lines)


__all__ = [
    "camera_to_dict",
    "comparison_csv",
    "comparison_to_dict",
    "conversion_to_dict",
    "format_comparison",
    "format_conversion",
    "format_model_table",
    "format_traced_camera",
    "model_table_csv",
    "model_table_to_dict",
    "parameter_units",
    "points_csv",
    "traced_camera_to_dict",
]
