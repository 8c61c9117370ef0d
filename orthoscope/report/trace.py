"""Text, JSON and CSV of real chief rays (``orthoscope trace``)."""

from __future__ import annotations

import numpy as np

from raytrace.lens import Lens
from raytrace.paraxial import ParaxialResult
from raytrace.trace import ChiefRays

from .text import csv_text, fmt


def chief_ray_rows(cr: ChiefRays, z_image: float) -> list[dict]:
    """One dict per field: field, object height, image height, landing angle, real entrance
    pupil (z) and status (None where the ray failed)."""
    y_img = cr.heights_at(z_image)
    finite = np.isfinite(cr.object_distance)
    fname = "angle_deg" if cr.field_kind == "angle" else "object_height_mm"
    rows = []
    for i in range(len(cr)):
        ok = bool(cr.ok[i])
        rows.append(
            {
                fname: float(cr.fields[i]),
                "y_object_mm": float(cr.y_start[i]) if finite else None,
                "y_image_mm": float(y_img[i]) if ok else None,
                "landing_angle_deg": float(cr.landing_angle_deg[i]) if ok else None,
                "entrance_pupil_z_mm": float(cr.entrance_pupil_z[i]) if ok else None,
                "status": cr.status_names[i],
            }
        )
    return rows


def image_plane_dict(par: ParaxialResult, z_image: float, given_as: str) -> dict:
    """The image plane in every vocabulary (docs/design.md, "Vocabulary")."""
    return {
        "z_mm": z_image,
        "s_prime_mm": z_image - par.z_Hp,
        "from_last_vertex_mm": z_image - par.z_last,
        "defocus_mm": z_image - par.z_gauss,
        "given_as": given_as,
    }


def trace_to_dict(lens: Lens, par: ParaxialResult, cr: ChiefRays, plane: dict) -> dict:
    return {
        "lens": lens.name,
        "wavelength_nm": par.wavelength,
        "object_distance_mm": cr.object_distance,
        "field_kind": cr.field_kind,
        "image_plane": plane,
        "rays": chief_ray_rows(cr, plane["z_mm"]),
    }


def trace_csv(cr: ChiefRays, z_image: float) -> str:
    rows = chief_ray_rows(cr, z_image)
    cols = list(rows[0].keys()) if rows else []
    return csv_text(cols, [[r[c] for c in cols] for r in rows])


def format_trace(lens: Lens, par: ParaxialResult, cr: ChiefRays, plane: dict) -> str:
    rows = chief_ray_rows(cr, plane["z_mm"])
    finite = not par.infinite
    obj = "infinity" if par.infinite else f"{cr.object_distance:.6g} mm before the first vertex"
    out = [
        f"{lens.name} — real chief rays at {par.wavelength:g} nm, object at {obj}",
        f"image plane: {plane['from_last_vertex_mm']:.6f} mm after the last vertex "
        f"(s' = {plane['s_prime_mm']:.6f} mm from H', defocus {plane['defocus_mm']:+.6f} mm; "
        f"from {plane['given_as']})",
    ]
    angle = cr.field_kind == "angle"
    head = "field (deg)" if angle else "y obj (mm)"
    out.append(
        f"{head:>12} {'y obj (mm)' if angle and finite else '':>12}"
        f" {'y image (mm)':>14} {'landing (deg)':>14} {'EP z (mm)':>12}  status"
    )
    for i, r in enumerate(rows):
        extra = fmt(r["y_object_mm"], 12, 4) if (angle and finite) else " " * 12
        out.append(
            f"{cr.fields[i]:12.4f} {extra} {fmt(r['y_image_mm'], 14, 6)} "
            f"{fmt(r['landing_angle_deg'], 14, 6)} {fmt(r['entrance_pupil_z_mm'], 12, 4)}  "
            f"{r['status']}"
        )
    return "\n".join(out)
