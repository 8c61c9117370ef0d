"""Text, JSON and CSV of the distortion-variation analysis (Fraser & Shortis 1992): the
data-mode report, the g table in the layout of the paper's Tables 2–3, and the prescription-mode
report."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from distortion.errors import DataError
from distortion.variation.analysis import FocusSummary, GEstimate, VariationAnalysis, summarize_g
from distortion.variation.models import Conjugate
from distortion.variation.traced import DEFINITION, FOCUSING, TracedVariation

from .jsonout import float_list, jsonable
from .text import printed


def _num(x: float, fmt: str = ".3f") -> str:
    return "—" if x is None or not np.isfinite(x) else format(x, fmt)


def format_g_table(rows: Sequence[tuple[str, FocusSummary]], *, overall: bool = True) -> str:
    """Table in the layout of Fraser & Shortis Tables 2–3: one row per lens (label, summary of
    one focus setting): g per object plane, their mean, the one-sigma precision of each g and
    the RMS error (µm) of Eq. (6) with the lens's mean g; then the overall mean and precision
    (sample SD of the lens means). All rows must have the same object planes."""
    if not rows:
        return "(no g_ss' determinations)"
    planes = [p.obj.label for p in rows[0][1].planes]
    w = 7
    head1 = (
        f"{'Lens':<10}"
        + "".join(f"{'g ' + pl:>{w}}" for pl in planes)
        + f"{'Mean':>{w}}"
        + "".join(f"{'s ' + pl:>{w}}" for pl in planes)
        + "".join(f"{'e ' + pl:>{w}}" for pl in planes)
    )
    lines = [
        f"g_ss' (Fraser & Shortis Eq. 6), lens focused at {rows[0][1].focus.label}; "
        "s = one-sigma precision of each g; e = RMS error (µm) of Eq. (6) with the mean g",
        head1,
    ]
    for label, fs in rows:
        if [p.obj.label for p in fs.planes] != planes:
            raise DataError(f"{label}: object planes differ from the first row's {planes}")
        lines.append(
            f"{label:<10}"
            + "".join(f"{_num(p.estimate.g, '.2f'):>{w}}" for p in fs.planes)
            + f"{_num(fs.summary.mean, '.2f'):>{w}}"
            + "".join(f"{_num(p.estimate.se, '.2f'):>{w}}" for p in fs.planes)
            + "".join(f"{_num(p.rms_mean_g_um, '.1f'):>{w}}" for p in fs.planes)
        )
    if overall and len(rows) > 1:
        s = summarize_g([fs.summary.mean for _, fs in rows])
        lines.append(
            f"Overall mean g = {_num(s.mean, '.2f')} with a precision (sample SD over "
            f"{s.n} lenses) of {_num(s.precision, '.2f')}"
        )
    return "\n".join(lines)


def format_variation(a: VariationAnalysis) -> str:
    """Human-readable report of a :class:`VariationAnalysis`."""
    out = [f"Distortion variation — {a.source or 'profiles'}"]
    if a.focal_length_mm is not None:
        out.append(f"focal length {a.focal_length_mm:g} mm")
    out.append(f"profiles ({len(a.profiles)}): " + ", ".join(p.label for p in a.profiles))
    out.append(f"comparison at common radii: {a.interpolation}")
    lo, hi = a.radial_range_mm
    out.append(
        "radial range: "
        + ("all" if lo is None and hi is None else f"{lo or 0:g}–{hi or math.inf:g} mm")
        + ";"
        f" weak threshold |δr_s' − δr_s| < {a.threshold_um:g} µm; g by "
        + ("least squares through the origin" if a.method == "lsq" else "mean of ratios")
    )
    if a.gammas:
        out.append("")
        out.append("Brown γ_ss' (Eq. 2, thin lens, s = f(1 + N)):")
        # printed: 'gamma' under an ASCII-only locale, still right-aligned over its column
        out.append(f"  {'plane':<16}{'N focus':>10}{'N object':>10}{printed('γ'):>9}")
        for g in a.gammas:
            lab = f"{g.obj.label}({g.focus.label})"
            out.append(f"  {lab:<16}{g.scale_focus:>10.2f}{g.scale_object:>10.2f}{g.gamma:>9.4f}")
    if a.brown:
        out.append("")
        out.append("Brown Eq. (1) prediction δr_s'/γ vs measured δr_ss' (µm):")
        for b in a.brown:
            out.append(
                f"  {b.obj.label}({b.focus.label}): RMS {b.rms_um:.2f}, max |diff| "
                f"{b.max_abs_um:.2f} over {b.r_mm.size} radii"
            )
    for fs in a.focus_summaries:
        out.append("")
        out.append(f"Fraser–Shortis Eq. (6), focus {fs.focus.label}:")
        sg, eu = printed("σ_g"), printed("e (µm)")
        out.append(f"  {'plane':<16}{'g':>8}{sg:>8}{'used':>6}{'weak':>6}{eu:>9}  note")
        for p in fs.planes:
            e = p.estimate
            lab = f"{p.obj.label}({p.focus.label})"
            note = "" if e.determined else "undetermined"
            out.append(
                f"  {lab:<16}{_num(e.g):>8}{_num(e.se):>8}{e.n_used:>6}{e.n_excluded:>6}"
                f"{_num(p.rms_mean_g_um, '.2f'):>9}  {note}"
            )
        s = fs.summary
        out.append(
            f"  mean g = {_num(s.mean)} over {s.n} planes; precision (SD) {_num(s.precision)}, "
            f"standard error {_num(s.sem)}; e = RMS error of Eq. (6) with the mean g"
        )
    for fv in a.field_variation:
        out.append("")
        out.append(
            f"Variation within the field at focus {fv.focus.label} (µm; spread = max − min):"
        )
        out.append(
            f"  {'r (mm)':>8}" + "".join(f"{o.label:>10}" for o in fv.objects) + f"{'spread':>10}"
        )
        for j, r in enumerate(fv.r_mm):
            out.append(
                f"  {r:>8.2f}"
                + "".join(f"{v:>10.2f}" for v in fv.dr_um[:, j])
                + f"{fv.spread_um[j]:>10.2f}"
            )
    for c in a.interpolation_checks:
        out.append("")
        out.append(
            f"Brown Eq. (3)–(4): {c.s.label} from {c.s1.label} and {c.s2.label}, "
            f"α = {c.alpha:.4f}: RMS {c.rms_um:.2f} µm, max |diff| {c.max_abs_um:.2f} µm"
        )
    if a.messages:
        out.append("")
        out.append("Notes:")
        out.extend(f"  - {m}" for m in a.messages)
    return "\n".join(out)


def conjugate_to_dict(c: Conjugate) -> dict:
    return {"value": c.value, "unit": c.unit, "label": c.label}


def g_estimate_to_dict(e: GEstimate) -> dict:
    return {
        "g": e.g,
        "se": e.se,
        "status": e.status,
        "message": e.message,
        "method": e.method,
        "n_used": e.n_used,
        "n_excluded": e.n_excluded,
        "threshold_um": e.threshold_um,
        "excluded_r_mm": float_list(e.excluded_r_mm),
        "rms_fit_um": e.rms_fit_um,
        "r_mm": float_list(e.r_mm),
        "g_pointwise": float_list(e.g_pointwise),
        "weak": [bool(w) for w in e.weak],
    }


def variation_to_dict(a: VariationAnalysis) -> dict:
    """JSON-ready dict of a :class:`VariationAnalysis` (NaN → null, infinities "inf" / "-inf"
    as in every JSON output; units in the key names)."""
    out = {
        "source": a.source,
        "focal_length_mm": a.focal_length_mm,
        "interpolation": a.interpolation,
        "radial_range_mm": list(a.radial_range_mm),
        "threshold_um": a.threshold_um,
        "method": a.method,
        "profiles": [
            {
                "label": p.label,
                "focus": conjugate_to_dict(p.focus),
                "object": conjugate_to_dict(p.obj),
                "r_mm": float_list(p.r_mm),
                "dr_um": float_list(p.dr_um),
            }
            for p in a.profiles
        ],
        "gamma": [
            {
                "focus": conjugate_to_dict(g.focus),
                "object": conjugate_to_dict(g.obj),
                "scale_focus": g.scale_focus,
                "scale_object": g.scale_object,
                "gamma": g.gamma,
            }
            for g in a.gammas
        ],
        "brown_prediction": [
            {
                "focus": conjugate_to_dict(b.focus),
                "object": conjugate_to_dict(b.obj),
                "gamma": b.gamma,
                "r_mm": float_list(b.r_mm),
                "measured_um": float_list(b.measured_um),
                "predicted_um": float_list(b.predicted_um),
                "rms_um": b.rms_um,
                "max_abs_um": b.max_abs_um,
            }
            for b in a.brown
        ],
        "g": [
            {
                "focus": conjugate_to_dict(fs.focus),
                "mean_g": fs.summary.mean,
                "precision": fs.summary.precision,
                "sem": fs.summary.sem,
                "n_planes": fs.summary.n,
                "planes": [
                    {
                        "object": conjugate_to_dict(p.obj),
                        "rms_mean_g_um": p.rms_mean_g_um,
                        **g_estimate_to_dict(p.estimate),
                    }
                    for p in fs.planes
                ],
            }
            for fs in a.focus_summaries
        ],
        "field_variation": [
            {
                "focus": conjugate_to_dict(fv.focus),
                "objects": [conjugate_to_dict(o) for o in fv.objects],
                "r_mm": float_list(fv.r_mm),
                "dr_um": [float_list(row) for row in fv.dr_um],
                "spread_um": float_list(fv.spread_um),
            }
            for fv in a.field_variation
        ],
        "interpolation_checks": [
            {
                "s": conjugate_to_dict(c.s),
                "s1": conjugate_to_dict(c.s1),
                "s2": conjugate_to_dict(c.s2),
                "alpha": c.alpha,
                "r_mm": float_list(c.r_mm),
                "measured_um": float_list(c.measured_um),
                "predicted_um": float_list(c.predicted_um),
                "rms_um": c.rms_um,
                "max_abs_um": c.max_abs_um,
            }
            for c in a.interpolation_checks
        ],
        "messages": list(a.messages),
    }
    return jsonable(out)


def format_traced_variation(tv: TracedVariation) -> str:
    """Text report: traced settings (planes, magnifications), then the data-mode report with
    Brown's γ prediction beside the traced truth."""
    out = [f"Prescription mode — {tv.lens_name}, f = {tv.efl_mm:.4f} mm"]
    out += [f"  {n}" for n in tv.notes[1:]]
    out.append("")
    out.append("Traced settings (s from H, image plane from the last vertex and from H'; mm):")
    out.append(
        f"  {'profile':<14}{'s':>12}{'m0':>10}{'img dist':>11}{'s_prime':>11}{'defocus':>10}"
        f"{'K0 (Eq.8)':>12}"
    )
    for s in tv.settings:
        out.append(
            f"  {s.label:<14}{s.s:>12.3f}{s.magnification:>10.5f}{s.from_last_vertex:>11.4f}"
            f"{s.s_prime:>11.4f}{s.defocus:>+10.4f}{s.constant:>12.6f}"
        )
    out.append("")
    out.append(format_variation(tv.analysis))
    return "\n".join(out)


def traced_variation_to_dict(tv: TracedVariation) -> dict:
    """JSON-ready dict: ``variation`` (:func:`variation_to_dict`) plus the traced settings."""
    return {
        "mode": "prescription",
        "lens": tv.lens_name,
        "efl_mm": tv.efl_mm,
        "reference": tv.reference,
        "definition": DEFINITION if tv.reference == "characteristic" else tv.reference,
        "focusing": FOCUSING,
        "r_grid_mm": [float(v) for v in tv.r_grid_mm],
        "settings": [
            {
                "label": s.label,
                "focus": s.focus.label,
                "object": s.obj.label,
                "gaussian": s.gaussian,
                "s_mm": s.s,
                "object_distance_mm": s.object_distance,
                "magnification_gaussian": s.magnification,
                "from_last_vertex_mm": s.from_last_vertex,
                "s_prime_mm": s.s_prime,
                "defocus_mm": s.defocus,
                "constant": s.constant,
            }
            for s in tv.settings
        ],
        "variation": variation_to_dict(tv.analysis),
    }
