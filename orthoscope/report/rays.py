"""Text, JSON and CSV of ray fans and spot diagrams (``orthoscope fan``, ``orthoscope spot``)."""

from __future__ import annotations

from raytrace.trace import RayFan, SpotDiagram
from raytrace.trace.results import status_name

from .text import csv_text


def _field(f) -> str:
    return f"{f.field:g} deg" if f.field_kind == "angle" else f"object height {f.field:g} mm"


def _field_keys(f) -> dict:
    """The field as the trace JSON keys it (``angle_deg`` or ``object_height_mm``: the unit in
    the key, README "JSON output"), after the unitless ``field`` / ``field_kind`` pair."""
    unit_key = "angle_deg" if f.field_kind == "angle" else "object_height_mm"
    return {"field": f.field, "field_kind": f.field_kind, unit_key: f.field}


def fan_to_dict(f: RayFan) -> dict:
    return {
        "axis": "tangential" if f.axis == "y" else "sagittal",
        **_field_keys(f),
        "object_distance_mm": f.object_distance,
        "image_plane_z_mm": f.z_plane,
        "chief_height_mm": f.chief_height,
        "wavelength_nm": f.wavelength,
        "pupil": f.pupil.tolist(),
        "eps_x_mm": f.ex.tolist(),
        "eps_y_mm": f.ey.tolist(),
        "status": [status_name(c) for c in f.status],
    }


def format_fans(fans: list[RayFan]) -> str:
    out = []
    for f in fans:
        kind = "tangential (eps_y vs py)" if f.axis == "y" else "sagittal (eps_x vs px)"
        out.append(
            f"Ray fan, {kind}, field {_field(f)}, {f.wavelength:g} nm; image plane z = "
            f"{f.z_plane:.6f} mm, chief ray at y = {f.chief_height:.6f} mm"
        )
        out.append(f"{'pupil':>8} {'eps (um)':>12}")
        for p, e, s in zip(f.pupil, f.aberration, f.status, strict=True):
            out.append(
                f"{p:8.3f} {1000 * e:12.4f}" if s == 0 else f"{p:8.3f} {'-':>12}  {status_name(s)}"
            )
        out.append("")
    return "\n".join(out).rstrip()


def fans_csv(fans: list[RayFan]) -> str:
    rows = [
        [("y" if f.axis == "y" else "x"), f.field, p, ex, ey, status_name(s)]
        for f in fans
        for p, ex, ey, s in zip(f.pupil, f.ex, f.ey, f.status, strict=True)
    ]
    return csv_text(["axis", "field", "pupil", "eps_x_mm", "eps_y_mm", "status"], rows)


def spot_to_dict(s: SpotDiagram) -> dict:
    return {
        **_field_keys(s),
        "object_distance_mm": s.object_distance,
        "image_plane_z_mm": s.z_plane,
        "chief_height_mm": s.chief_height,
        "wavelength_nm": s.wavelength,
        "rays": int(s.x.size),
        "rays_ok": s.n_ok,
        "centroid_x_mm": s.centroid_x,
        "centroid_y_mm": s.centroid_y,
        "rms_radius_mm": s.rms_radius,
        "geometric_radius_mm": s.geometric_radius,
        "x_mm": s.x.tolist(),
        "y_mm": s.y.tolist(),
    }


def format_spots(spots: list[SpotDiagram]) -> str:
    out = [
        "Spot diagrams (relative to the real chief ray; RMS and geometric radius about the "
        "centroid)",
        f"{'field':>22} {'rays':>9} {'centroid y (um)':>16} {'RMS (um)':>10} {'geo (um)':>10}",
    ]
    for s in spots:
        out.append(
            f"{_field(s):>22} {s.n_ok:>4}/{s.x.size:<4} {1000 * s.centroid_y:16.4f} "
            f"{1000 * s.rms_radius:10.4f} {1000 * s.geometric_radius:10.4f}"
        )
    return "\n".join(out)


def spots_csv(spots: list[SpotDiagram]) -> str:
    rows = [
        [s.field, s.n_ok, s.centroid_x, s.centroid_y, s.rms_radius, s.geometric_radius]
        for s in spots
    ]
    head = ["field", "rays_ok", "centroid_x_mm", "centroid_y_mm", "rms_radius_mm", "geo_radius_mm"]
    return csv_text(head, rows)
