"""JSON of a lens prescription (``orthoscope prescription --json``); the text table is
:func:`raytrace.listing.format_prescription` (also ``str(lens)``)."""

from __future__ import annotations

import math
from dataclasses import asdict

from raytrace.lens import Lens


def material_dict(m) -> dict:
    d = {"kind": m.kind, "description": m.describe()}
    if m.kind in ("index", "model", "catalog"):
        d.update(nd=m.nd, vd=m.vd if m.kind != "index" else None)
    if m.kind == "model":
        d["model"] = m.model
    if m.kind == "catalog":
        d.update(name=m.name, catalog=m.catalog, formula=m.formula)
    return d


def prescription_to_dict(lens: Lens) -> dict:
    """The lens as JSON-ready data: every surface with units in the keys."""
    surfaces = []
    for i, s in enumerate(lens.surfaces, start=1):
        surfaces.append(
            {
                "surface": i,
                "radius_mm": s.radius,
                "curvature_per_mm": s.curvature,
                "thickness_mm": s.thickness,
                "medium_after": material_dict(s.material),
                "semi_diameter_mm": s.semi_diameter if math.isfinite(s.semi_diameter) else None,
                "conic": s.conic,
                "aspheric": list(s.aspheric),
                "stop": s.stop,
                "label": s.label,
                "mirror": s.mirror,
                "coordinate_break": s.coordinate_break,
                "placement": _placement(s.placement),
                "after": s.after if isinstance(s.after, str) else _placement(s.after),
                "clear_aperture": None if s.aperture is None else asdict(s.aperture),
            }
        )
    return {
        "name": lens.name,
        "source": lens.source,
        "units": "mm",
        "wavelength_nm": lens.wavelength,
        "wavelengths_nm": [float(w) for w in lens.wavelengths],
        "object_distance_mm": lens.object_distance,
        "object_medium": material_dict(lens.object_material),
        "aperture": asdict(lens.aperture),
        "field": asdict(lens.field),
        "image_solve": lens.image_solve,
        "image_placement": _placement(lens.image_placement),
        "surfaces": surfaces,
        "first_order": first_order_dict(lens),
    }


def first_order_dict(lens: Lens) -> dict:
    """The first-order summary under the text table (:func:`raytrace.listing.summary_lines`),
    at the reference wavelength and the lens file's object: ``efl_mm``, ``bfl_mm``, ``epd_mm``,
    ``f_number`` (EFL/EPD), ``m_e`` (pupil magnification), ``entrance_pupil_z_mm`` and
    ``exit_pupil_z_mm`` (from the first vertex); ``error`` says why they are null when the lens
    has no first-order data."""
    from raytrace.errors import LensError
    from raytrace.paraxial.firstorder import paraxial

    keys = (
        "efl_mm",
        "bfl_mm",
        "epd_mm",
        "f_number",
        "m_e",
        "entrance_pupil_z_mm",
        "exit_pupil_z_mm",
    )
    try:
        p = paraxial(lens)
    except LensError as e:
        return {**dict.fromkeys(keys), "error": str(e)}
    values = (p.efl, p.bfl, p.epd, p.f_number, p.m_e, p.z_E0, p.z_E0p)
    return {**{k: float(v) for k, v in zip(keys, values, strict=True)}, "error": None}


def _placement(p) -> dict | None:
    """A surface's placement (decenter mm, tilt deg, order) or None when it has none."""
    from raytrace.frames import Placement

    if not isinstance(p, Placement) or p.is_identity:
        return None
    return {"decenter_mm": list(p.decenter), "tilt_deg": list(p.tilt), "order": p.order}
