"""The prescription of a lens as a table (text and HTML): what ``str(lens)``, the notebook view
``lens._repr_html_()`` and ``orthoscope prescription LENS`` show.

One row per surface: number, radius (mm, ``inf`` for a plane), thickness to the next vertex (mm),
the medium after the surface, semi-diameter (mm, ``-`` when not limited), conic, aspheric terms
(a Q-type surface: its form, ρ_max and a_m, on the base radius and conic of the row), stop mark
and notes (label, mirror, coordinate break, decenter / tilt, extra clear aperture); a decentered
image surface under the table; then the first-order summary (EFL, BFL, EPD, f-number, pupils,
m_e) at the lens's wavelength. Plain floats, units in the headers.
"""

from __future__ import annotations

import html
import math

from .lens import Lens

COLUMNS = ("#", "radius (mm)", "thickness (mm)", "medium after", "semi-diam (mm)", "conic", "asph")


def _g(v: float, digits: int = 6) -> str:
    if math.isinf(v):
        return "inf" if v > 0 else "-inf"
    return f"{v:.{digits}g}"


def surface_rows(lens: Lens) -> list[list[str]]:
    """The surface table as strings (see :data:`COLUMNS`); the stop row is marked ``STO``."""
    rows = []
    for i, s in enumerate(lens.surfaces, start=1):
        tag = "STO" if s.stop else str(i)
        thick = _g(s.thickness, 8)
        if i == lens.n_surfaces and lens.image_solve == "gaussian":
            thick += " (Gaussian)"
        asph = ", ".join(f"{a:.4g}" for a in s.aspheric) if any(s.aspheric) else ""
        if s.qtype is not None:
            asph = s.qtype.describe()
        rows.append(
            [
                tag,
                _g(s.radius, 8),
                thick,
                s.material.describe(),
                "-" if math.isinf(s.semi_diameter) else _g(s.semi_diameter),
                _g(s.conic) if s.conic else "",
                asph,
            ]
            + ([note] if (note := "; ".join(surface_notes(s))) else [])
        )
    return rows


def surface_notes(s) -> list[str]:
    """What the columns do not show of a surface: its label, a mirror, a coordinate break, its
    placement and the frame after it (:mod:`raytrace.frames`), an extra clear aperture."""
    from .frames import Placement

    out = [s.label] if s.label else []
    if s.mirror:
        out.append("MIRROR")
    if s.coordinate_break:
        out.append("coordinate break")
    if isinstance(s.placement, Placement) and not s.placement.is_identity:
        out.append(s.placement.describe())
    if isinstance(s.after, Placement):
        out.append(f"after: {s.after.describe()}")
    elif s.after != "stay":
        out.append(f"after: {s.after}")
    a = s.aperture
    if a is not None:
        size = f"{a.half_x:g}" if a.shape == "circle" else f"{a.half_x:g} x {a.half_y:g}"
        at = f" at ({a.x0:g}, {a.y0:g})" if (a.x0 or a.y0) else ""
        out.append(f"aperture {a.shape} {size}{at}")
    return out


def summary_lines(lens: Lens) -> list[str]:
    """The first-order summary under the table (or why it is undefined)."""
    from .errors import LensError
    from .paraxial.firstorder import paraxial

    obj = (
        "object at infinity"
        if math.isinf(lens.object_distance)
        else f"object {lens.object_distance:g} mm before the first vertex"
    )
    head = f"{obj}; {lens.wavelength:g} nm"
    try:
        p = paraxial(lens)
    except LensError as e:
        return [head, f"first-order data undefined: {e}"]
    fno = p.f_number
    return [
        head,
        f"EFL {p.efl:.6f} mm   BFL {p.bfl:.6f} mm   EPD {p.epd:.6g} mm   f/{fno:.4g}   "
        f"m_e {p.m_e:.6f}",
        f"entrance pupil z {p.z_E0:.6g} mm, exit pupil z {p.z_E0p:.6g} mm (from the first vertex); "
        f"HE0 {p.HE0:.6g} mm, H'E0' {p.HpE0p:.6g} mm",
    ]


def format_prescription(lens: Lens, *, summary: bool = True) -> str:
    """The lens as a text table with its first-order summary."""
    rows = surface_rows(lens)
    ncol = len(COLUMNS)
    widths = [
        max(len(COLUMNS[j]), *(len(r[j]) for r in rows)) if rows else len(COLUMNS[j])
        for j in range(ncol)
    ]
    out = [
        f"{lens.name}",
        f"aperture {lens.aperture.describe()}; field {lens.field.describe()}",
        "  ".join(c.rjust(w) for c, w in zip(COLUMNS, widths, strict=True))
        + ("  notes" if any(len(r) > ncol for r in rows) else ""),
        "  ".join("-" * w for w in widths),
    ]
    for r in rows:
        line = "  ".join(c.rjust(w) for c, w in zip(r[:ncol], widths, strict=True))
        out.append((line + (f"  {r[ncol]}" if len(r) > ncol else "")).rstrip())
    ip = lens.image_placement
    if ip is not None and not isinstance(ip, str) and not ip.is_identity:
        out.append(f"image surface: {ip.describe()}")
    if summary:
        out += summary_lines(lens)
    return "\n".join(out)


def html_prescription(lens: Lens) -> str:
    """The same table as HTML (Jupyter's rich display)."""
    esc = html.escape
    head = "".join(f"<th>{esc(c)}</th>" for c in COLUMNS) + "<th>notes</th>"
    body = "".join(
        "<tr>"
        + "".join(f"<td>{esc(c)}</td>" for c in r[: len(COLUMNS)])
        + f"<td>{esc(r[len(COLUMNS)] if len(r) > len(COLUMNS) else '')}</td></tr>"
        for r in surface_rows(lens)
    )
    summ = "<br>".join(esc(s) for s in summary_lines(lens))
    return (
        f"<div><b>{esc(lens.name)}</b><table><thead><tr>{head}</tr></thead>"
        f"<tbody>{body}</tbody></table><p>{summ}</p></div>"
    )
