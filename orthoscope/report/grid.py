"""Text and JSON of the 2-D distortion results (:mod:`distortion.grid`): the grid summary per image
plane (constants, named reference points, largest distortion), the decomposition into radial,
decentering and thin-prism parts, and the Brown–Conrady (Fraser 1997) fit."""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from distortion.grid import BrownConradyFit, DistortionGrid, GridDecomposition
from raytrace.trace.results import status_name

from .jsonout import copy_fields
from .units import PARAMETER_UNITS


def _g(v: float, digits: int = 6) -> str:
    v = float(v)
    if not math.isfinite(v):
        return "-"
    return f"{v:.{digits}g}"


def _param_lines(values: dict, std: dict, order: Sequence[str]) -> list[str]:
    out = [f"    {'parameter':<10}{'value':>16}{'std error':>14}  unit"]
    for k in order:
        if k not in values:
            continue
        se = std.get(k, math.nan)
        held = "" if k in std else "  (held)"
        out.append(
            f"    {k:<10}{_g(values[k], 9):>16}{_g(se, 3):>14}  {PARAMETER_UNITS.get(k, '')}{held}"
        )
    return out


def _corr_lines(free: Sequence[str], corr: np.ndarray, limit: float = 0.5) -> list[str]:
    """The pairs with |correlation| ≥ ``limit`` (all of them in JSON)."""
    pairs = []
    for i in range(len(free)):
        for j in range(i + 1, len(free)):
            r = float(corr[i, j])
            if math.isfinite(r) and abs(r) >= limit:
                pairs.append(f"{free[i]}-{free[j]} {r:+.3f}")
    if not pairs:
        return [f"    correlations: none with |r| >= {limit:g}"]
    return [f"    correlations |r| >= {limit:g}: " + ", ".join(pairs)]


def _plane_fit_lines(
    fits: Sequence, p: int, name: Callable[[Any], str], describe: Callable[[Any], list[str]]
) -> list[str]:
    """The lines of the fits of plane ``p`` (decompositions or Brown-Conrady fits): ``describe``
    of a determined fit; for another, one line with its ``name`` and why it is not determined."""
    out = []
    for f in fits:
        if f.plane != p:
            continue
        if f.determined:
            out += describe(f)
        else:
            out.append(f"  {name(f)}: not determined - {f.not_determined}")
    return out


def _decomposition_name(d: GridDecomposition) -> str:
    return (
        f"Decomposition (principal point {d.principal_point}, camera constant {d.camera_constant})"
    )


def _decomposition_lines(d: GridDecomposition) -> list[str]:
    lines = [
        f"  Decomposition (distortion form; principal point {d.principal_point}, camera "
        f"constant {d.camera_constant}): residual RMS {_g(d.rms_mm * 1000, 4)} um, max "
        f"{_g(d.max_mm * 1000, 4)} um"
    ]
    order = ("c", "x0", "y0", *sorted(k for k in d.values if k[0] == "K"), "P1", "P2",
             "S1", "S2")  # fmt: skip
    lines += _param_lines(d.values, d.std_errors, order)
    J, psi = d.decentering
    S, chi = d.thin_prism
    lines.append(
        f"    decentering profile J r^2: J = {_g(J, 4)} mm^-1, axis {_g(psi, 5)} deg; "
        f"thin prism S r^2: S = {_g(S, 4)} mm^-1, axis {_g(chi, 5)} deg"
    )
    return lines + _corr_lines(d.free, d.correlation)


def _brown_lines(b: BrownConradyFit) -> list[str]:
    lines = [
        f"  Brown-Conrady, Fraser 1997 {len(b.free)}-parameter model (Australis: a "
        f"correction, measured radius): RMS {_g(b.rms_mm * 1000, 4)} um, max "
        f"{_g(b.max_mm * 1000, 4)} um"
    ]
    lines += _param_lines(b.values, b.std_errors, b.values.keys())
    lines += _corr_lines(b.free, b.correlation)
    if b.opencv is not None:
        oc = b.opencv_coefficients
        lines.append(
            "    OpenCV (refit): "
            + ", ".join(f"{k} = {_g(v, 6)}" for k, v in oc.items())
            + f"; fx = fy = c/pitch; refit RMS {_g(b.opencv.rms_px * b.pixel_mm * 1000, 3)}"
            " um"
        )
    return lines + [f"    warning: {w}" for w in b.warnings]


def format_grid(
    grid: DistortionGrid,
    decompositions: Sequence[GridDecomposition] = (),
    brown: Sequence[BrownConradyFit] = (),
) -> str:
    """The text report: per plane the constants, the named reference points, the largest
    distortion, the decomposition and the Brown–Conrady fit (when given)."""
    obj = (
        "object at infinity"
        if math.isinf(grid.object_distance)
        else f"object {grid.object_distance:g} mm"
    )
    bad = int(np.count_nonzero(grid.status != 0))
    lines = [
        f"{grid.name} - 2-D distortion, {grid.status.size} fields "
        f"({' x '.join(str(n) for n in grid.shape[::-1])}), {grid.field_kind} fields, {obj}, "
        f"{grid.wavelength:g} nm",
        f"Ideal image P0' = R + K0 X (Pestrecov Eq. 8 in 2-D), R = {grid.reference_point} point; "
        "image frame x right, y up (looking along -z)",
    ]
    if bad:
        st = {}
        for s in grid.status.ravel():
            if s != 0:
                name = status_name(s)
                st[name] = st.get(name, 0) + 1
        lines.append(f"{bad} field(s) not traced: " + ", ".join(f"{n} {v}" for n, v in st.items()))
    sym = "M0" if grid.finite else "F0"
    for p in range(grid.n_planes):
        lines.append("")
        lines.append(f"Plane {p + 1}: {grid.plane_label(p)}")
        unit = "" if grid.finite else " mm"
        lines.append(
            f"  {sym} = {grid.constant[p]:.6f}{unit}, camera constant c = "
            f"{grid.camera_constant[p]:.6f} mm"
        )
        lines.append(f"  {'reference point':<22}{'x (mm)':>14}{'y (mm)':>14}")
        for label, xy in (
            ("axial object's image", grid.axial_xy[p]),
            ("PPA", grid.ppa_xy[p]),
            ("PPBS", grid.ppbs_xy[p]),
        ):
            lines.append(f"  {label:<22}{_g(xy[0], 6):>14}{_g(xy[1], 6):>14}")
        rad = grid.radial[p]
        tan = grid.tangential[p]
        with np.errstate(invalid="ignore"):
            rmax = float(np.nanmax(np.abs(rad))) if np.isfinite(rad).any() else math.nan
            tmax = float(np.nanmax(np.abs(tan))) if np.isfinite(tan).any() else math.nan
        lines.append(
            f"  max |D| = {_g(grid.max_distortion(p) * 1000, 5)} um; max |radial| = "
            f"{_g(rmax * 1000, 5)} um, max |tangential| = {_g(tmax * 1000, 5)} um"
        )
        lines += _plane_fit_lines(decompositions, p, _decomposition_name, _decomposition_lines)
        lines += _plane_fit_lines(
            brown, p, lambda b: "Brown-Conrady, Fraser 1997 model", _brown_lines
        )
    return "\n".join(lines)


def _fit_to_dict(f: GridDecomposition | BrownConradyFit, **between) -> dict:
    """The keys a decomposition and a Brown-Conrady fit share: plane, determined, the reason it
    is not (null when it is), ``between``, then the values, std errors, free parameters and
    their correlation."""
    return {
        **copy_fields(f, "plane", "determined"),
        "not_determined": f.not_determined or None,
        **between,
        **copy_fields(f, "values", "std_errors", "free", "correlation"),
    }


def decomposition_to_dict(d: GridDecomposition) -> dict:
    """JSON-ready dict; ``determined`` false (with ``not_determined``, the reason) when the grid
    does not determine the decomposition: its values are then null."""
    return {
        **_fit_to_dict(d, **copy_fields(d, "principal_point", "camera_constant")),
        "decentering_J_per_mm": d.decentering[0],
        "decentering_axis_deg": d.decentering[1],
        "thin_prism_S_per_mm": d.thin_prism[0],
        "thin_prism_axis_deg": d.thin_prism[1],
        "residual_rms_mm": d.rms_mm,
        "residual_max_mm": d.max_mm,
        "condition": d.condition,
    }


def brown_to_dict(b: BrownConradyFit) -> dict:
    """JSON-ready dict; ``determined`` false (with ``not_determined``, the reason) when the
    points do not determine the model: its values are then null and there is no OpenCV refit."""
    out = {
        **_fit_to_dict(b, model="australis (Fraser 1997, correction at the measured radius)"),
        **copy_fields(b, "rms_mm", "max_mm", "warnings"),
    }
    if b.opencv is not None:
        out["opencv"] = {
            **b.opencv_coefficients,
            "fx_px": b.opencv.camera["fx"],
            "fy_px": b.opencv.camera["fy"],
            "cx_px": b.opencv.camera["cx"],
            "cy_px": b.opencv.camera["cy"],
            "pixel_mm": b.pixel_mm,
            "image_px": [b.opencv.camera.width, b.opencv.camera.height],
            "refit_rms_px": b.opencv.rms_px,
            "refit_max_px": b.opencv.max_px,
        }
    return out


def grid_to_dict(
    grid: DistortionGrid,
    decompositions: Sequence[GridDecomposition] = (),
    brown: Sequence[BrownConradyFit] = (),
) -> dict:
    """JSON-ready dict (arrays as nested lists; points end with [x, y] in mm)."""
    return {
        "name": grid.name,
        "field_kind": grid.field_kind,
        "object_distance_mm": grid.object_distance,
        "wavelength_nm": grid.wavelength,
        "shape": list(grid.shape),
        "field_x": grid.field_x,
        "field_y": grid.field_y,
        "t_x": grid.tx,
        "t_y": grid.ty,
        "status": [status_name(s) for s in grid.status.ravel()],
        "reference_point": grid.reference_point,
        "planes": [
            {
                "s_prime_mm": grid.s_prime[p],
                "from_last_vertex_mm": grid.from_last_vertex[p],
                "defocus_mm": grid.defocus[p],
                ("M0" if grid.finite else "F0_mm"): grid.constant[p],
                "camera_constant_mm": grid.camera_constant[p],
                "axial_mm": grid.axial_xy[p],
                "ppa_mm": grid.ppa_xy[p],
                "ppbs_mm": grid.ppbs_xy[p],
                "actual_mm": grid.actual[p],
                "ideal_mm": grid.ideal[p],
                "D_mm": grid.D[p],
                "radial_mm": grid.radial[p],
                "tangential_mm": grid.tangential[p],
                "decomposition": [decomposition_to_dict(d) for d in decompositions if d.plane == p],
                "brown_conrady": [brown_to_dict(b) for b in brown if b.plane == p],
            }
            for p in range(grid.n_planes)
        ],
    }
