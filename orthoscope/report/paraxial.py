"""Text and JSON of first-order data (``orthoscope paraxial``)."""

from __future__ import annotations

from dataclasses import asdict

from raytrace.lens import Lens
from raytrace.paraxial import ParaxialResult

from .text import fmt


def paraxial_rows(par: ParaxialResult) -> list[tuple[str, float, str]]:
    """(label, value, unit) rows of the paraxial listing."""
    rows = [
        ("EFL (1/power)", par.efl, "mm"),
        ("BFL: last vertex -> F'", par.bfl, "mm"),
        ("FFL: first vertex -> F", par.ffl, "mm"),
        ("F  (z from first vertex)", par.z_F, "mm"),
        ("F' (z from first vertex)", par.z_Fp, "mm"),
        ("H  principal point (z)", par.z_H, "mm"),
        ("H' principal point (z)", par.z_Hp, "mm"),
        ("N  nodal point (z)", par.z_N, "mm"),
        ("N' nodal point (z)", par.z_Np, "mm"),
        ("E0  entrance pupil (z)", par.z_E0, "mm"),
        ("E0' exit pupil (z)", par.z_E0p, "mm"),
        ("HE0 (Pestrecov)", par.HE0, "mm"),
        ("H'E0' (Pestrecov)", par.HpE0p, "mm"),
        ("entrance pupil diameter", par.epd, "mm"),
        ("exit pupil diameter", par.xpd, "mm"),
        ("pupil magnification", par.pupil_magnification, ""),
        ("m_e (Pestrecov Eq. 6)", par.m_e, ""),
        ("Lagrange invariant", par.lagrange, "mm"),
        ("stop radius (paraxial)", par.stop_radius, "mm"),
        ("working f-number", par.working_fnumber, ""),
    ]
    if not par.infinite:
        rows += [
            ("object: s from H (Pestrecov)", par.s, "mm"),
            ("p0 = s - HE0", par.p0, "mm"),
            ("Gaussian image: s' from H'", par.s_prime_gauss, "mm"),
            ("Gaussian image from last vertex", par.gaussian_image_distance, "mm"),
            ("m0 (Pestrecov Eq. 5)", par.m0, ""),
        ]
    else:
        rows += [("Gaussian image from last vertex", par.gaussian_image_distance, "mm")]
    rows += [("image plane of the file, from last vertex", par.z_image_file - par.z_last, "mm")]
    return rows


def format_paraxial(lens: Lens, par: ParaxialResult) -> str:
    """The paraxial listing as text (z positions from the first vertex)."""
    obj = "infinity" if par.infinite else f"{par.object_distance:.6g} mm before the first vertex"
    out = [
        f"{lens.name} — paraxial data at {par.wavelength:g} nm, object at {obj}",
        "(z positions from the first vertex, light travelling toward +z)",
    ]
    for label, v, unit in paraxial_rows(par):
        out.append(f"  {label:42} {fmt(v, 14, 6)} {unit}")
    return "\n".join(out)


def paraxial_to_dict(lens: Lens, par: ParaxialResult) -> dict:
    """JSON-ready dict: the lens name, units and every :class:`ParaxialResult` field (keys as in
    the README)."""
    return {"lens": lens.name, "units": "mm", **asdict(par)}
