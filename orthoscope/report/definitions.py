"""Text, JSON and CSV of distortion against a named definition (F-tanθ, F-θ, calibrated, fisheye
projections; :mod:`distortion.definitions`). Every output names the definition, its mapping and
the focal length it uses."""

from __future__ import annotations

from distortion.definitions import ProjectionDistortion
from raytrace.trace.results import status_name

from .jsonout import float_list
from .text import csv_text, format_columns


def _block_title(res: ProjectionDistortion, k: int, i: int) -> str:
    wl = f"{res.wavelengths[k]:g} nm"
    return (
        f"{wl}, {res.plane_label(i)}: f = {res.focal_length[k, i]:.6f} mm "
        f"(paraxial F0 {res.paraxial_focal_length[k, i]:.6f} mm, least-squares "
        f"{res.least_squares_focal_length[k, i]:.6f} mm; EFL {res.efl[k]:.6f} mm)"
    )


def _scale_line(res: ProjectionDistortion) -> list[str]:
    if not res.scale:
        return []
    if res.scale == "reference":
        return [
            "every wavelength against the reference wavelength's f "
            f"({res.reference_wavelength:g} nm), in its planes"
        ]
    return ["each wavelength against its own f, in the reference wavelength's planes"]


def format_projection(res: ProjectionDistortion, *, decimals: int = 4, layout: str = "rows") -> str:
    """Text tables: a header naming the definition (mapping and focal length), then one table
    per wavelength and image plane (theta, y_ref, y', D, Dr)."""
    head = [
        f"{res.name} — distortion against {res.title} (definition {res.definition}); "
        "object at infinity",
        res.describe(),
        "theta = field angle of the object-space chief ray; D = y' - y_ref, Dr = D / y_ref",
        *_scale_line(res),
    ]
    blocks = ["\n".join(head)]
    for k in range(res.n_wavelengths):
        for i in range(res.n_planes):
            q = [
                ("y_ref (mm)", res.y_ref[k, i], decimals, True),
                ("y' (mm)", res.yp[k, i], decimals, True),
                ("D (mm)", res.D[k, i], decimals, True),
                ("Dr (%)", 100.0 * res.Dr[k, i], decimals, True),
            ]
            blocks.append(
                format_columns(
                    [_block_title(res, k, i)], "theta (deg)", res.fields, q, layout=layout
                )
            )
    bad = [
        f"{res.wavelengths[k]:g} nm, {v:g} deg: {status_name(c)}"
        for k in range(res.n_wavelengths)
        for v, c in zip(res.fields, res.status[k], strict=True)
        if c != 0
    ]
    if bad:
        blocks.append("fields not traced: " + "; ".join(bad))
    return "\n\n".join(blocks)


def projection_to_dict(res: ProjectionDistortion) -> dict:
    """JSON-ready dict (keys carry units; relative values as fractions and in per cent)."""
    return {
        "lens": res.name,
        "definition": res.definition,
        "title": res.title,
        "projection": res.projection,
        "formula": f"y_ref = {res.formula}",
        "focal_basis": res.focal_basis,
        "focal_description": res.focal_description,
        "object_distance_mm": float("inf"),
        "angle_deg": float_list(res.fields),
        "scale": res.scale or None,
        "reference_wavelength_nm": res.reference_wavelength,
        "wavelengths": [
            {
                "wavelength_nm": float(res.wavelengths[k]),
                "efl_mm": float(res.efl[k]),
                "status": [status_name(c) for c in res.status[k]],
                "planes": [
                    {
                        "z_mm": float(res.z_planes[i]),
                        "s_prime_mm": float(res.s_prime[i]),
                        "from_last_vertex_mm": float(res.from_last_vertex[i]),
                        "defocus_mm": float(res.defocus[i]),
                        "focal_length_mm": float(res.focal_length[k, i]),
                        "paraxial_focal_length_mm": float(res.paraxial_focal_length[k, i]),
                        "least_squares_focal_length_mm": float(
                            res.least_squares_focal_length[k, i]
                        ),
                        "y_ref_mm": float_list(res.y_ref[k, i]),
                        "yp_mm": float_list(res.yp[k, i]),
                        "D_mm": float_list(res.D[k, i]),
                        "Dr": float_list(res.Dr[k, i]),
                        "Dr_pct": float_list(100.0 * res.Dr[k, i]),
                    }
                    for i in range(res.n_planes)
                ],
            }
            for k in range(res.n_wavelengths)
        ],
    }


def projection_csv(res: ProjectionDistortion) -> str:
    """One row per wavelength, plane and field; the definition and focal basis in every row."""
    header = [
        "definition",
        "focal_basis",
        "wavelength_nm",
        "s_prime_mm",
        "angle_deg",
        "focal_length_mm",
        "y_ref_mm",
        "yp_mm",
        "D_mm",
        "Dr_pct",
        "status",
    ]
    rows = []
    for k in range(res.n_wavelengths):
        for i in range(res.n_planes):
            for j in range(res.fields.size):
                rows.append(
                    [
                        res.definition,
                        res.focal_basis,
                        float(res.wavelengths[k]),
                        float(res.s_prime[i]),
                        float(res.fields[j]),
                        float(res.focal_length[k, i]),
                        float(res.y_ref[k, i, j]),
                        float(res.yp[k, i, j]),
                        float(res.D[k, i, j]),
                        float(100.0 * res.Dr[k, i, j]),
                        status_name(res.status[k, j]),
                    ]
                )
    return csv_text(header, rows)
