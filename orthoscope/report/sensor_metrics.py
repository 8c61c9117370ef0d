"""Text and JSON of the picture metrics of a rectangular sensor (:mod:`distortion.sensor_metrics`):
TV distortion (SMIA and traditional), keystone, line straightness and the anamorphic ratio."""

from __future__ import annotations

import math
from collections.abc import Sequence

from distortion.sensor_metrics import SensorMetrics

from .jsonout import copy_fields

_LINE_LABEL = {
    "top": "top edge",
    "bottom": "bottom edge",
    "left": "left edge",
    "right": "right edge",
    "centre_row": "centre row",
    "centre_column": "centre column",
}


def _signed(v: float, digits: int) -> str:
    """``v`` with a sign and ``digits`` decimals, never "-0.000"."""
    return f"{round(v, digits) + 0.0:+.{digits}f}"


def _pct(v: float, digits: int = 4) -> str:
    return f"{_signed(100.0 * v, digits)} %" if math.isfinite(v) else "-"


def _um(v: float) -> str:
    return f"{_signed(1000.0 * v, 3)} um" if math.isfinite(v) else "-"


def format_sensor_metrics(metrics: SensorMetrics | Sequence[SensorMetrics]) -> str:
    """The text report: one block per plane."""
    items = [metrics] if isinstance(metrics, SensorMetrics) else list(metrics)
    out: list[str] = []
    for m in items:
        if out:
            out.append("")
        where = f" - {m.plane_label}" if m.plane_label else ""
        out += [
            f"Picture metrics of the {m.width_mm:g} x {m.height_mm:g} mm picture (the rectangle "
            f"whose ideal image the grid spans; {m.shape[1]} x {m.shape[0]} points){where}",
            "  TV distortion (negative = barrel):",
            f"    SMIA 1.0 (A - B)/B            {_pct(m.tv_distortion_smia):>12}"
            f"   (A = mean of left/right heights {m.height_left_mm:.6f}, "
            f"{m.height_right_mm:.6f} mm; B = centre height {m.height_centre_mm:.6f} mm)",
            f"    traditional dH/H = (A - B)/2B {_pct(m.tv_distortion_traditional):>12}"
            "   (= SMIA / 2)",
            f"    horizontal, SMIA form         {_pct(m.tv_distortion_smia_horizontal):>12}"
            f"   (widths: top {m.width_top_mm:.6f}, bottom {m.width_bottom_mm:.6f}, centre "
            f"{m.width_centre_mm:.6f} mm)",
            f"    horizontal, traditional       {_pct(m.tv_distortion_traditional_horizontal):>12}",
            "  Keystone (trapezoid):",
            f"    vertical (top - bottom width) / mean    {_pct(m.keystone_vertical, 6):>14}",
            f"    horizontal (right - left height) / mean {_pct(m.keystone_horizontal, 6):>14}",
            "  Line straightness (sag from the chord; edges: + toward the picture centre, i.e. "
            "pincushion; centre lines: + toward +y / +x):",
        ]
        for s in m.straightness:
            out.append(
                f"    {_LINE_LABEL[s.name]:<14} sag {_um(s.sag_mm):>14}  over "
                f"{s.chord_mm:.4f} mm = {_pct(s.fraction, 5):>12}"
            )
        out += [
            f"  Anamorphic ratio (central scales dx'/dx : dy'/dy) {m.anamorphic_ratio:.9f} "
            f"(scale x {m.scale_x:.9f}, y {m.scale_y:.9f})",
            f"  Scale ratio of the whole centre lines (Wc/W)/(Hc/H) {m.mean_scale_ratio:.9f}",
        ]
        out += [f"  note: {n}" for n in m.notes]
    return "\n".join(out)


def sensor_metrics_to_dict(m: SensorMetrics) -> dict:
    """JSON-ready dict (fractions as fractions; lengths in mm)."""
    out = copy_fields(
        m,
        "plane",
        "plane_label",
        "width_mm",
        "height_mm",
        "shape",
        "height_left_mm",
        "height_right_mm",
        "height_centre_mm",
        "width_top_mm",
        "width_bottom_mm",
        "width_centre_mm",
        "tv_distortion_smia",
        "tv_distortion_traditional",
        "tv_distortion_smia_horizontal",
        "tv_distortion_traditional_horizontal",
        "keystone_vertical",
        "keystone_horizontal",
    )
    out["straightness"] = {
        s.name: copy_fields(s, "sag_mm", "chord_mm", "fraction") for s in m.straightness
    }
    out.update(copy_fields(m, "scale_x", "scale_y", "anamorphic_ratio", "mean_scale_ratio"))
    out["definitions"] = {
        "tv_distortion_smia": "(A - B)/B, A = mean imaged height at the left and right "
        "edges, B = imaged height at the centre (SMIA 1.0 Part 5)",
        "tv_distortion_traditional": "dH/H = (A - B)/(2B) = SMIA/2",
        "keystone_vertical": "(W_top - W_bottom)/mean",
        "straightness": "sag from the chord; edges + toward the picture centre",
        "anamorphic_ratio": "dx'/dx : dy'/dy at the picture centre",
    }
    out["notes"] = list(m.notes)
    return out
