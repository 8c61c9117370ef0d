"""The calibration certificate of a design (:mod:`distortion.certificate`) as JSON and text, and the
cells the one-page PDF prints (:mod:`orthoscope.plots.certificate`).

One source for every number: :func:`certificate_to_dict` (the JSON); the text and the page print
the cells of :func:`certificate_cells`, made from that dict with the precisions of
:data:`DECIMALS`. Each cell carries its JSON path (``"decentering/profile_um/3"``), which the page
sets as the text object's ``gid`` — so a test can check that every number on the page is its
JSON value rounded as printed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from distortion.certificate import CalibrationCertificate

from .jsonout import jsonable

TITLE = "Calibration certificate - design prediction"
#: printed decimals per kind of number
DECIMALS = {"mm": 3, "pp": 4, "um": 1, "deg": 2, "field": 2, "coef": 4, "nm": 2}


@dataclass(frozen=True)
class Cell:
    """A printed number: its text and the JSON path of the value (None for plain labels)."""

    text: str
    path: str | None = None


def _get(d: dict, path: str):
    v = d
    for k in path.split("/"):
        v = v[int(k)] if isinstance(v, list) else v[k]
    return v


def number_text(v, kind: str, *, signed: bool = False) -> str:
    """``v`` printed with the decimals of ``kind``; NaN / None as an em dash."""
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return "\u2014"
    if kind == "coef":
        return f"{float(v):+.{DECIMALS[kind]}e}" if signed else f"{float(v):.{DECIMALS[kind]}e}"
    dec = DECIMALS[kind]
    s = f"{float(v):+.{dec}f}" if signed else f"{float(v):.{dec}f}"
    if float(s) == 0.0:
        s = f"{0.0:.{dec}f}"  # no "-0.0"
    return s


def cell(d: dict, path: str, kind: str, *, signed: bool = False) -> Cell:
    return Cell(number_text(_get(d, path), kind, signed=signed), path)


def certificate_to_dict(cert: CalibrationCertificate, *, software: str | None = None) -> dict:
    """The JSON of the certificate (full precision; NaN → null through
    :func:`orthoscope.report.jsonout.jsonable`)."""
    if software is None:
        from .. import __version__

        software = f"orthoscope {__version__}"
    labels = cert.semi_diagonal_labels
    dec = cert.decentering
    d = {
        "title": TITLE,
        "lens": cert.name,
        "source": cert.source,
        "date": cert.date,
        "software": software,
        "conditions": {
            "object_distance_mm": cert.object_distance,
            "field_kind": cert.field_kind,
            "wavelength_nm": cert.wavelength,
            "s_prime_mm": cert.s_prime,
            "from_last_vertex_mm": cert.from_last_vertex,
            "defocus_mm": cert.defocus,
            "plane": cert.plane_label,
            "format": cert.format,
            "reference_point": cert.reference_point,
            "origin": cert.origin,
            "frame": "x right, y up, looking from the image toward the lens; mm",
        },
        "paraxial_focal_length_mm": cert.paraxial_constant_mm,
        "calibrated_focal_length_mm": cert.calibrated_focal_length_mm,
        "method": cert.method,
        "method_text": cert.method_text,
        "principal_points_mm": {
            "ppa": list(cert.ppa_mm),
            "ppbs": list(cert.ppbs_mm),
            "axial": list(cert.axial_mm),
        },
        "fields_deg": cert.fields_deg,
        "radius_mm": cert.radius_mm,
        "semi_diagonals": [
            {
                "label": labels[i],
                "azimuth_deg": cert.azimuths_deg[i],
                "max_field_deg": cert.max_fields_deg[i],
                "radial_um": cert.radial_um[i],
                "tangential_um": cert.tangential_um[i],
            }
            for i in range(len(labels))
        ],
        "mean_radial_um": cert.mean_radial_um,
        "max_abs_mean_radial_um": cert.max_abs_radial_um,
        "decentering": {
            "P1_per_mm": dec["P1"],
            "P2_per_mm": dec["P2"],
            "J_per_mm": dec["J"],
            "axis_deg": dec["axis_deg"],
            "phi0_deg": dec["phi0_deg"],
            "S1_per_mm": dec["S1"],
            "S2_per_mm": dec["S2"],
            "decomposition_rms_um": dec["residual_rms_um"],
            "profile_um": cert.decentering_profile_um,
        },
        "radial_coefficients": {
            "form": "dr = k0 r + k1 r^3 + k2 r^5 + k3 r^7 (mm), r = CFL tan(theta)",
            "k0": cert.radial_coefficients["k0"],
            "k1_per_mm2": cert.radial_coefficients["k1"],
            "k2_per_mm4": cert.radial_coefficients["k2"],
            "k3_per_mm6": cert.radial_coefficients["k3"],
            "rms_um": cert.radial_coefficients["rms_um"],
        },
        "dense": {
            "fields_deg": cert.dense_fields_deg,
            "radial_um": cert.dense_radial_um,
            "mean_radial_um": cert.dense_mean_radial_um,
            "decentering_profile_um": cert.dense_decentering_profile_um,
        },
        "notes": list(cert.notes),
    }
    return jsonable(d)


# ------------------------------------------------------------------ the printed cells


def _object_text(d: dict) -> str:
    od = d["conditions"]["object_distance_mm"]
    if od == "inf":
        return "at infinity"
    return f"{float(od):g} mm from the first vertex (nominal field angles)"


def condition_lines(d: dict) -> list[tuple[str, str]]:
    """(label, text) of the header's conditions."""
    c = d["conditions"]
    ref = {
        "ppbs": "PPBS (point of best symmetry)",
        "ppa": "PPA (autocollimation)",
        "axial": "image of the axial object point",
    }[c["reference_point"]]
    return [
        ("Object", _object_text(d)),
        ("Wavelength", f"{number_text(c['wavelength_nm'], 'nm')} nm"),
        (
            "Image plane",
            f"{c['plane']}; {number_text(c['from_last_vertex_mm'], 'pp')} mm from the last vertex",
        ),
        ("Format", c["format"]),
        ("Radial distortion from", ref),
        ("Coordinates", f"origin at the {c['origin']}; {c['frame']}"),
        ("Computed", f"{d['date']} by {d['software']} from the prescription (real chief rays)"),
    ]


def summary_cells(d: dict) -> list[tuple[str, Cell, Cell | None, str]]:
    """(label, value cell, second cell or None, unit) rows of the focal-length and principal-point
    table."""
    fin = d["conditions"]["object_distance_mm"] != "inf"
    what = "principal distance" if fin else "focal length"
    gauss = abs(float(d["conditions"]["defocus_mm"])) <= 1e-9 * abs(
        float(d["conditions"]["s_prime_mm"])
    )
    if fin:
        par = "Paraxial principal distance M0 p0 (Pestrecov Eq. 8)"
    elif gauss:
        par = "Equivalent focal length (paraxial)"
    else:
        par = "Paraxial F0 of this plane (Pestrecov Eq. 8)"
    pp = "principal_points_mm"
    return [
        (par, cell(d, "paraxial_focal_length_mm", "mm"), None, "mm"),
        (
            f"Calibrated {what} ({d['method']})",
            cell(d, "calibrated_focal_length_mm", "mm"),
            None,
            "mm",
        ),
        (
            "PPA  x, y",
            cell(d, f"{pp}/ppa/0", "pp", signed=True),
            cell(d, f"{pp}/ppa/1", "pp", signed=True),
            "mm",
        ),
        (
            "PPBS  x, y",
            cell(d, f"{pp}/ppbs/0", "pp", signed=True),
            cell(d, f"{pp}/ppbs/1", "pp", signed=True),
            "mm",
        ),
        (
            "Axial object's image  x, y",
            cell(d, f"{pp}/axial/0", "pp", signed=True),
            cell(d, f"{pp}/axial/1", "pp", signed=True),
            "mm",
        ),
    ]


def radial_table_cells(d: dict) -> tuple[list[Cell], list[tuple[str, list[Cell]]]]:
    """(header cells: the field angles, rows (label, cells)): radius and the radial distortion per
    semi-diagonal and their mean (µm)."""
    n = len(d["fields_deg"])
    head = [cell(d, f"fields_deg/{j}", "field") for j in range(n)]
    rows = [("r = CFL tan(theta) (mm)", [cell(d, f"radius_mm/{j}", "mm") for j in range(n)])]
    for i, sd in enumerate(d["semi_diagonals"]):
        lab = f"{sd['label']}  ({number_text(sd['azimuth_deg'], 'deg')} deg)"
        rows.append(
            (
                lab,
                [cell(d, f"semi_diagonals/{i}/radial_um/{j}", "um", signed=True) for j in range(n)],
            )
        )
    rows.append(("mean", [cell(d, f"mean_radial_um/{j}", "um", signed=True) for j in range(n)]))
    return head, rows


def decentering_cells(d: dict) -> tuple[list[tuple[str, Cell, str]], list[Cell]]:
    """(parameter rows (label, cell, unit), the profile cells at the table's fields)."""
    n = len(d["fields_deg"])
    p = "decentering"
    params = [
        ("P1", cell(d, f"{p}/P1_per_mm", "coef", signed=True), "1/mm"),
        ("P2", cell(d, f"{p}/P2_per_mm", "coef", signed=True), "1/mm"),
        ("J = sqrt(P1^2 + P2^2)", cell(d, f"{p}/J_per_mm", "coef"), "1/mm"),
        ("axis psi (max. radial)", cell(d, f"{p}/axis_deg", "deg", signed=True), "deg"),
        (
            "Brown phi0 = psi - 90 deg (max. tangential)",
            cell(d, f"{p}/phi0_deg", "deg", signed=True),
            "deg",
        ),
    ]
    prof = [cell(d, f"{p}/profile_um/{j}", "um", signed=True) for j in range(n)]
    return params, prof


def coefficient_cells(d: dict) -> list[tuple[str, Cell]]:
    rc = "radial_coefficients"
    return [
        ("k0", cell(d, f"{rc}/k0", "coef", signed=True)),
        ("k1 (1/mm^2)", cell(d, f"{rc}/k1_per_mm2", "coef", signed=True)),
        ("k2 (1/mm^4)", cell(d, f"{rc}/k2_per_mm4", "coef", signed=True)),
        ("k3 (1/mm^6)", cell(d, f"{rc}/k3_per_mm6", "coef", signed=True)),
        ("RMS of the fit (um)", cell(d, f"{rc}/rms_um", "um")),
    ]


def definition_lines(d: dict) -> list[str]:
    """The definitions printed at the foot of the page (and of the text)."""
    return [
        "Radial distortion dr = r' - CFL tan(theta): r' the distance of the real chief-ray image "
        "from the reference point along the semi-diagonal; + outward (pincushion).",
        "Calibrated focal length (principal distance for a finite object), criterion "
        f"{d['method_text']}.",
        "PPA: image of the object at infinity normal to the image plane. PPBS: principal point of "
        "a purely radial least-squares fit over the format's polar grid (symmetric about the "
        "axis). Semi-diagonals from the lens axis to the format's corners.",
        "Decentering (Brown 1966; distortion form, principal point held at the reference point): "
        "profile P(r) = J r^2 (tangential, across the axis; radial along it 3 J r^2).",
        "A prediction from the lens prescription by real ray tracing - not a measurement of a "
        "camera.",
    ]


# ------------------------------------------------------------------ text


def format_certificate(cert_or_dict) -> str:
    """The certificate as text (the page's tables)."""
    d = cert_or_dict if isinstance(cert_or_dict, dict) else certificate_to_dict(cert_or_dict)
    out = [f"{d['title']}: {d['lens']}"]
    if d["source"]:
        out.append(f"  source: {d['source']}")
    for lab, txt in condition_lines(d):
        out.append(f"  {lab + ':':<24}{txt}")
    summary = summary_cells(d)
    params, prof = decentering_cells(d)
    kw = max(len(r[0]) for r in summary + params) + 2
    out += ["", "Focal length and principal points"]
    for lab, a, b, unit in summary:
        val = a.text if b is None else f"{a.text}, {b.text}"
        out.append(f"  {lab:<{kw}}{val:>18} {unit}")
    head, rows = radial_table_cells(d)
    lw = max(len(r[0]) for r in rows)
    cw = max(8, *(len(c.text) for _, cs in rows for c in cs), *(len(c.text) for c in head)) + 1
    out += ["", "Radial distortion (um) along the semi-diagonals"]
    out.append(f"  {'field angle (deg)':<{lw}}" + "".join(c.text.rjust(cw) for c in head))
    for lab, cs in rows:
        out.append(f"  {lab:<{lw}}" + "".join(c.text.rjust(cw) for c in cs))
    out += ["", "Decentering distortion"]
    for lab, c, unit in params:
        out.append(f"  {lab:<{kw}}{c.text:>18} {unit}")
    out.append(f"  {'profile J r^2 (um)':<{lw}}" + "".join(c.text.rjust(cw) for c in prof))
    out += ["", "Radial distortion coefficients (mean curve): " + d["radial_coefficients"]["form"]]
    out.append("  " + ", ".join(f"{lab} = {c.text}" for lab, c in coefficient_cells(d)))
    out += [""] + [f"  {s}" for s in definition_lines(d)]
    out += [f"  note: {n}" for n in d["notes"]]
    return "\n".join(out)


def page_numbers(d: dict) -> dict[str, str]:
    """Every printed number of the page by JSON path (for tests and tools)."""
    out: dict[str, str] = {}
    for _, a, b, _ in summary_cells(d):
        for c in (a, b):
            if c is not None:
                out[c.path] = c.text
    head, rows = radial_table_cells(d)
    for c in head + [c for _, cs in rows for c in cs]:
        out[c.path] = c.text
    params, prof = decentering_cells(d)
    for _, c, _ in params:
        out[c.path] = c.text
    for c in prof:
        out[c.path] = c.text
    for _, c in coefficient_cells(d):
        out[c.path] = c.text
    return out
