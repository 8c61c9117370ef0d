"""Text and JSON of radial-distortion coefficient fits (Brown–Conrady, OpenCV)."""

from __future__ import annotations

import math

from distortion.coefficients import OpenCVModel, RadialFit


def radial_fit_to_dict(fit: RadialFit) -> dict:
    """JSON-ready dict: form, radius, K0, K1..Kn (mm units), standard errors, residuals (µm)."""
    out = {
        "model": "brown-conrady radial, dr = K0*r + K1*r^3 + K2*r^5 + K3*r^7 (mm)",
        "form": fit.form,
        "radius": fit.radius,
        "K0": fit.k0,
        "se_K0": fit.se_k0 if math.isfinite(fit.se_k0) else None,
        "scale_ratio_cb_over_cg": fit.scale_ratio,
        "rms_um": fit.rms_um,
        "max_abs_um": fit.max_abs_um,
        "residual_um": [float(x) for x in fit.residual_um],
        "r_mm": [float(x) for x in fit.r_mm],
    }
    for i, (ki, si) in enumerate(zip(fit.k, fit.se_k, strict=True), start=1):
        out[f"K{i}"] = ki
        out[f"se_K{i}"] = si if math.isfinite(si) else None
    return out


def opencv_to_dict(m: OpenCVModel) -> dict:
    """JSON for a calibration tool. Keys: ``camera_model`` "opencv-pinhole-radial";
    ``dist_coeffs`` = [k1, k2, p1, p2, k3] (OpenCV order, p1 = p2 = 0: no decentering here);
    ``k1``, ``k2``, ``k3``; ``principal_distance_mm`` (Gaussian c_g); ``fx_px``/``fy_px`` (null
    without the pitch); ``pixel_pitch_um``; ``fit_rms_um``, ``fit_max_um`` (and ``_px``);
    ``notes``."""
    return {
        "camera_model": "opencv-pinhole-radial",
        "dist_coeffs": [m.k1, m.k2, 0.0, 0.0, m.k3],
        "k1": m.k1,
        "k2": m.k2,
        "k3": m.k3,
        "principal_distance_mm": m.principal_distance_mm,
        "input_principal_distance_mm": m.input_principal_distance_mm,
        "fx_px": m.fx_px,
        "fy_px": m.fx_px,
        "pixel_pitch_um": m.pixel_pitch_um,
        "brown_K_gaussian_ideal_radius": list(m.gaussian_k),
        "fit_rms_um": m.fit.rms_um,
        "fit_max_um": m.fit.max_abs_um,
        "fit_rms_px": m.rms_px,
        "fit_max_px": m.max_abs_px,
        "notes": list(m.notes),
    }


def format_radial_fit(fit: RadialFit) -> str:
    """Text summary of a fit."""
    lines = [
        f"Radial distortion fit ({fit.form} form, {fit.radius} radius; r in mm, dr in mm):",
        f"  K0 = {fit.k0: .6e}" + ("" if fit.form == "gaussian" else f"  ± {fit.se_k0:.2e}"),
    ]
    for i, (ki, si) in enumerate(zip(fit.k, fit.se_k, strict=True), start=1):
        lines.append(f"  K{i} = {ki: .6e}  ± {si:.2e}  (mm^-{2 * i})")
    if fit.form == "balanced":
        lines.append(f"  c_b/c_g = {fit.scale_ratio:.8f}")
    lines.append(
        f"  residuals: RMS {fit.rms_um:.3f} µm, max {fit.max_abs_um:.3f} µm "
        f"({fit.r_mm.size} points)"
    )
    return "\n".join(lines)


def format_opencv(m: OpenCVModel) -> str:
    lines = [
        "OpenCV radial model x_d = x(1 + k1 r^2 + k2 r^4 + k3 r^6):",
        f"  k1 = {m.k1: .6e}   k2 = {m.k2: .6e}   k3 = {m.k3: .6e}",
        f"  principal distance c_g = {m.principal_distance_mm:.6f} mm"
        + (f", fx = fy = {m.fx_px:.3f} px" if m.fx_px else ""),
        f"  fit residuals: RMS {m.fit.rms_um:.3f} µm, max {m.fit.max_abs_um:.3f} µm",
    ]
    lines += [f"  note: {n}" for n in m.notes]
    return "\n".join(lines)
