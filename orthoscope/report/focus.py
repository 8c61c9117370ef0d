"""Text and JSON of a focus study (:func:`distortion.variation.focus.focus_study`)."""

from __future__ import annotations

import math
from typing import Any


def _n(x: float) -> str:
    return "inf" if math.isinf(x) else f"{x:.4f}"


def format_focus_study(st: Any) -> str:
    """The focus study as text: one row per configuration (``dr fmax``: δr at the largest
    traced field), Brown's γ, Eq. (3)-(4), Eq. (6)."""
    out = [f"Focus study of {st.lens_name} ({len(st.settings)} configurations)"]
    out += [f"  {n}" for n in st.notes]
    out.append("")
    out.append(
        f"{'config':>8} {'distance mm':>12} {'N':>10} {'EFL mm':>10} {'c_s mm':>10} "
        f"{'c p0/me mm':>11} {'PP mm':>7} {'dr fmax um':>11}"
    )
    for s in st.settings:
        out.append(
            f"{s.name:>8} {_n(s.distance_mm):>12} {_n(s.image_scale):>10} {s.efl_mm:10.4f} "
            f"{s.principal_distance_mm:10.4f} {s.camera_constant_mm:11.4f} "
            f"{s.principal_point_mm:7.4f} {s.dr_um[-1]:11.2f}"
        )
    out.append("")
    out.append("Brown Eq. (2), gamma from image scales vs traced principal distances:")
    for g in st.gamma[1:]:
        out.append(
            f"  {g.name:>8}: brown {g.gamma_brown:.6f}  traced {g.gamma_traced:.6f}  "
            f"rel {g.relative_error:+.3e}  = {g.error_um_at_edge:+.2f} um "
            f"at r = {g.r_edge_mm:.2f} mm"
        )
    if st.interpolation:
        a, b = (st.settings[i].name for i in st.calibrated)
        out.append(f"Brown Eq. (3)-(4) from the calibrations at {a} and {b}:")
        for t in st.interpolation:
            out.append(
                f"  {t.name:>8}: alpha {t.alpha:.4f}  rms {t.rms_um:.2f} um  "
                f"max {t.max_abs_um:.2f} um at r = {t.r_at_max_mm:.2f} mm"
            )
    if st.analysis is not None:
        for fs in st.analysis.focus_summaries:
            out.append(f"Fraser-Shortis Eq. (6), lens focused at {fs.focus.label}:")
            for p in fs.planes:
                e = p.estimate
                out.append(
                    f"  object {p.obj.label:>10}: g {e.g:+.4f} +- {e.se:.4f}  "
                    f"rms with mean g {p.rms_mean_g_um:.2f} um"
                )
            out.append(f"  mean g {fs.summary.mean:+.4f}")
    return "\n".join(out)


def focus_study_to_dict(st: Any) -> dict[str, Any]:
    """The focus study as JSON-ready data (lengths in mm, distortion in µm)."""

    def f(x: float) -> float | str:
        return "inf" if math.isinf(x) else float(x)

    return {
        "lens": st.lens_name,
        "notes": list(st.notes),
        "configurations": [
            {
                "name": s.name,
                "distance_mm": f(s.distance_mm),
                "object_distance_mm": f(s.object_distance_mm),
                "image_scale": f(s.image_scale),
                "efl_mm": s.efl_mm,
                "principal_distance_mm": s.principal_distance_mm,
                "camera_constant_mm": s.camera_constant_mm,
                "principal_point_mm": s.principal_point_mm,
                "r_mm": [float(v) for v in s.r_mm],
                "dr_um": [float(v) for v in s.dr_um],
            }
            for s in st.settings
        ],
        "gamma": [g.__dict__ for g in st.gamma],
        "interpolation": [
            {
                "name": t.name,
                "alpha": t.alpha,
                "rms_um": t.rms_um,
                "max_abs_um": t.max_abs_um,
                "r_at_max_mm": t.r_at_max_mm,
            }
            for t in st.interpolation
        ],
    }
