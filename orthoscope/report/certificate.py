"""The calibration certificate of a design (:mod:`distortion.certificate`) as JSON and text, and the
cells the one-page PDF prints (:mod:`orthoscope.plots.certificate`).

One source for every number: :func:`certificate_to_dict` (the JSON); the text and the page print
the cells of :func:`certificate_cells`, made from that dict with the precisions of
:data:`DECIMALS`. Each cell carries its JSON path (``"decentering/profile_um/3"``), which the page
sets as the text object's ``gid`` — so a test can check that every number on the page is its
JSON value rounded as printed.

Long tables
    The tabulated fields run across (the USGS form) up to :data:`ACROSS_MAX_FIELDS` (12: the
    most the default 7.5° step gives, for a format below 90°). Beyond, the text prints one row
    per field (fields down, the semi-diagonals, their mean and the decentering profile across),
    and the page, which has room for one row of 12 fields, tabulates one field in every k and
    the edge (:func:`page_field_indices`), saying so; the JSON and the text carry every field.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from distortion.certificate import CalibrationCertificate

from .jsonout import jsonable

TITLE = "Calibration certificate - design prediction"
#: printed decimals per kind of number
DECIMALS = {"mm": 3, "pp": 4, "um": 1, "deg": 2, "field": 2, "coef": 4, "nm": 2}
#: the most tabulated fields printed across (text) and on the page's one table row
ACROSS_MAX_FIELDS = 12


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


def number_text(v, kind: str, *, signed: bool = False, decimals: int | None = None) -> str:
    """``v`` printed with the decimals of ``kind`` (or ``decimals``); NaN / None as an em
    dash."""
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return "\u2014"
    dec = DECIMALS[kind] if decimals is None else int(decimals)
    if kind == "coef":
        if float(v) == 0.0:
            signed = False  # no "+0.0000e+00" or "-0.0000e+00"
        return f"{float(v):+.{dec}e}" if signed else f"{float(v):.{dec}e}"
    s = f"{float(v):+.{dec}f}" if signed else f"{float(v):.{dec}f}"
    if float(s) == 0.0:
        s = f"{0.0:.{dec}f}"  # no "-0.0"
    return s


def cell(d: dict, path: str, kind: str, *, signed: bool = False, decimals=None) -> Cell:
    return Cell(number_text(_get(d, path), kind, signed=signed, decimals=decimals), path)


#: the most decimals a field angle is printed with when its step's own decimals set them
FIELD_DECIMALS_MAX = 6


def field_decimals(d: dict) -> int:
    """Decimals of the tabulated field angles: ``DECIMALS["field"]`` (2), more for a finer step
    (the first field is the step): the step's own decimals up to ``FIELD_DECIMALS_MAX``, else
    enough that neighbouring fields never print alike (a unit of the last decimal no larger than
    the step)."""
    f = d["fields_deg"]
    dec = DECIMALS["field"]
    if len(f) < 2 or f[0] is None or not float(f[0]) > 0:
        return dec
    step = float(f[0])
    for k in range(dec, FIELD_DECIMALS_MAX + 1):
        if abs(round(step, k) - step) <= 1e-9 * step:
            return k
    return max(dec, min(15, math.ceil(-math.log10(step) - 1e-9)))


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
    fd = field_decimals(d)
    head = [cell(d, f"fields_deg/{j}", "field", decimals=fd) for j in range(n)]
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


def _every(n: int, k: int) -> list[int]:
    """The k-th, 2k-th, ... of ``n`` fields and the last (the edge)."""
    idx = list(range(k - 1, n, k))
    if not idx or idx[-1] != n - 1:
        idx.append(n - 1)
    return idx


def _round_step(x: float) -> bool:
    """True when ``x`` is 1, 2, 2.5 or 5 times a power of ten (to 1e-9)."""
    if not x > 0:
        return False
    e = math.floor(math.log10(x))
    m = x / 10.0**e
    return any(abs(m - v) <= 1e-9 * v for v in (1.0, 2.0, 2.5, 5.0, 10.0))


def page_field_indices(d: dict) -> tuple[list[int], int]:
    """(indices of the tabulated fields the page prints, k): every field when there are at most
    :data:`ACROSS_MAX_FIELDS`, else one in every k (the k-th, 2k-th, ... field: a regular step of
    k times the table's, the first field being the step) and the last (the edge). k is the
    smallest that fits, or a larger one up to twice that whose step is round (1, 2, 2.5 or 5
    times a power of ten degrees): a 0.001 deg table over 20 deg prints every 2 deg."""
    n = len(d["fields_deg"])
    if n <= ACROSS_MAX_FIELDS:
        return list(range(n)), 1
    k0 = 2
    while len(_every(n, k0)) > ACROSS_MAX_FIELDS:
        k0 += 1
    step = float(d["fields_deg"][0])
    k = next((k for k in range(k0, 2 * k0 + 1) if _round_step(k * step)), k0)
    return _every(n, k), k


def page_table_note(d: dict) -> str | None:
    """The line under the page's table when it prints only some of the fields (None else)."""
    idx, k = page_field_indices(d)
    if k == 1:
        return None
    n = len(d["fields_deg"])
    step = number_text(d["fields_deg"][k - 1], "field", decimals=field_decimals(d))
    return (
        f"The page tabulates one field in every {k} (every {step} deg) and the edge; all {n} "
        "tabulated fields are in the text and JSON output."
    )


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
    across = len(head) <= ACROSS_MAX_FIELDS
    if across:
        # a list, not max(8, *cells): an empty table (no field) is 8 wide, not a TypeError
        cw = max([8, *(len(c.text) for _, cs in rows for c in cs), *(len(c.text) for c in head)])
        cw += 1
        out += ["", "Radial distortion (um) along the semi-diagonals"]
        if not head:  # the API refuses such a format; a certificate made otherwise still prints
            out.append("  no tabulated field: the format lies within 5 % of the field step")
        else:
            out.append(f"  {'field angle (deg)':<{lw}}" + "".join(c.text.rjust(cw) for c in head))
            for lab, cs in rows:
                out.append(f"  {lab:<{lw}}" + "".join(c.text.rjust(cw) for c in cs))
    else:
        out += ["", *_rows_table(d, head, rows, prof)]
    out += ["", "Decentering distortion"]
    for lab, c, unit in params:
        out.append(f"  {lab:<{kw}}{c.text:>18} {unit}")
    if across:
        if prof:  # (none without a tabulated field)
            out.append(f"  {'profile J r^2 (um)':<{lw}}" + "".join(c.text.rjust(cw) for c in prof))
    else:
        out.append(f"  {'profile J r^2 (um)':<{kw}}the last column of the table above")
    out += ["", "Radial distortion coefficients (mean curve): " + d["radial_coefficients"]["form"]]
    out.append("  " + ", ".join(f"{lab} = {c.text}" for lab, c in coefficient_cells(d)))
    out += [""] + [f"  {s}" for s in definition_lines(d)]
    out += [f"  note: {n}" for n in d["notes"]]
    return "\n".join(out)


def _rows_table(d: dict, head: list[Cell], rows, prof: list[Cell]) -> list[str]:
    """The radial table with one row per field (more than ``ACROSS_MAX_FIELDS`` fields): field,
    radius, the semi-diagonals, their mean and the decentering profile across."""
    sds = d["semi_diagonals"]
    labels = ["field (deg)", "r (mm)", *(sd["label"] for sd in sds), "mean", "J r^2"]
    cols = [head, *(cs for _, cs in rows), prof]
    widths = [
        max(len(lab), *(len(c.text) for c in col)) for lab, col in zip(labels, cols, strict=True)
    ]
    where = ", ".join(f"{sd['label']} at {number_text(sd['azimuth_deg'], 'deg')} deg" for sd in sds)
    out = [
        f"Radial distortion (um) along the semi-diagonals: one row per field ({len(head)} fields)",
        f"  semi-diagonals: {where}",
        "  r = CFL tan(theta); J r^2: the decentering profile (um)",
        "  " + "  ".join(lab.rjust(w) for lab, w in zip(labels, widths, strict=True)),
    ]
    for j in range(len(head)):
        out.append(
            "  " + "  ".join(col[j].text.rjust(w) for col, w in zip(cols, widths, strict=True))
        )
    return out


def page_numbers(d: dict) -> dict[str, str]:
    """Every printed number of the page by JSON path (for tests and tools); the table's fields
    are those of :func:`page_field_indices`."""
    out: dict[str, str] = {}
    for _, a, b, _ in summary_cells(d):
        for c in (a, b):
            if c is not None:
                out[c.path] = c.text
    idx, _ = page_field_indices(d)
    head, rows = radial_table_cells(d)
    for c in [head[j] for j in idx] + [cs[j] for _, cs in rows for j in idx]:
        out[c.path] = c.text
    params, prof = decentering_cells(d)
    for _, c, _ in params:
        out[c.path] = c.text
    for j in idx:
        out[prof[j].path] = prof[j].text
    for _, c in coefficient_cells(d):
        out[c.path] = c.text
    return out
