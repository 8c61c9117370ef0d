"""Photogrammetric radial-distortion coefficients and their OpenCV equivalents.

Conventions
-----------
δr is distortion, ``δr = r_actual − r_ideal`` (positive outward = pincushion): the sign of the
Fraser & Shortis profiles and of Brown's distortion polynomial ``δr = K1 r³ + K2 r⁵ + ...``.
The Australis / Fraser (1997) model writes instead the CORRECTION ``Δx = x̄ (K1 r² + ...)``
added to a measured coordinate to get the ideal one, so its K are the negatives of these (to
first order; :mod:`distortion.camera` converts exactly). r and δr are in mm inside this module
(profiles in µm are converted at the interface: ``dr_um``).

* Gaussian form (Brown–Conrady odd polynomial, no linear term), referred to the Gaussian
  principal distance c_g:  ``δr = K1 r³ + K2 r⁵ + K3 r⁷``  (K1 in mm⁻², K2 mm⁻⁴, K3 mm⁻⁶).
* Balanced form, referred to a calibrated principal distance c_b:
  ``δr = K0 r + K1 r³ + K2 r⁵ + K3 r⁷`` (K0 dimensionless).

The radial argument r is either the *measured* (actual, distorted) radius — the photogrammetric
convention, where the correction is evaluated at measured image coordinates — or the *ideal*
(undistorted) radius. The linear term and the principal distances are related exactly by
(q = c_b / c_g; Pestrecov 1958 Eq. 12 with F_c/F0 = q):

* measured radius: r_b,ideal = q (r − δr_g) ⇒ δr_b(r) = q δr_g(r) + (1 − q) r, so
  ``K0 = 1 − q``, ``c_b = c_g (1 − K0)``, ``K_i,b = q K_i,g``;
* ideal radius (r_b = c_b tan θ, r_g = r_b / q): δr_b(r_b) = (1/q − 1) r_b + δr_g(r_b / q), so
  ``K0 = 1/q − 1``, ``c_g = c_b (1 + K0)``, ``K_i,b = K_i,g q^-(2i+1)``.

A positive K0 thus means a calibrated principal distance shorter than the Gaussian one.
To first order in K0 both read c_b ≈ c_g (1 − K0).

OpenCV (``cv2.calibrateCamera`` / ``projectPoints``): ideal normalised coordinates
x = X/Z, y = Y/Z, ρ² = x² + y², distorted ``x_d = x (1 + k1 ρ² + k2 ρ⁴ + k3 ρ⁶)`` (radial part),
pixels ``u = fx x_d + cx``. With r_ideal = c ρ and δr = r_d − r_ideal this is the Gaussian form
in the IDEAL radius with c = fx·pitch the Gaussian principal distance:
``k1 = K1 c²``, ``k2 = K2 c⁴``, ``k3 = K3 c⁶`` (same signs: k1 > 0 is pincushion).
A measured-radius profile is therefore refitted against r − δr before converting
(:func:`opencv_model`); :func:`brown_to_opencv` itself is pure algebra and inverts exactly.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from raytrace.units import is_whole

from .camera.models import radial_polynomial, scale_radial_coefficients
from .errors import DataError

_RADIUS = ("measured", "ideal")


@dataclass(frozen=True, eq=False)
class RadialFit:
    """Least-squares fit of a radial profile.

    ``form`` "gaussian" (K0 = 0 fixed) or "balanced"; ``radius`` "measured" or "ideal" (what
    r means); ``k0`` linear term; ``k`` = (K1, K2, K3, ...) in mm^(1−(2i+1)); ``se_k0``, ``se_k``
    their standard errors (NaN without redundancy); residuals ``data − fit`` in µm at ``r_mm``.
    """

    form: str
    radius: str
    k0: float
    k: tuple[float, ...]
    se_k0: float
    se_k: tuple[float, ...]
    r_mm: np.ndarray
    dr_um: np.ndarray
    residual_um: np.ndarray
    rms_um: float
    max_abs_um: float

    @property
    def scale_ratio(self) -> float:
        """q = c_b / c_g implied by the linear term (1 for the Gaussian form)."""
        return balanced_scale_ratio(self.k0, self.radius)


def evaluate_radial(k0: float, k: Sequence[float], r_mm: np.ndarray) -> np.ndarray:
    """δr (mm) = K0 r + Σ K_i r^(2i+1) at r (mm) (the even series of
    :func:`distortion.camera.models.radial_polynomial` times r)."""
    r = np.asarray(r_mm, dtype=float)
    return r * (k0 + radial_polynomial(tuple(k), r * r))


#: the largest r/c of a perspective profile the fits accept: tan 87° (a field angle nearer 90°
#: means a principal distance or pixel pitch in the wrong unit)
MAX_RADIUS_RATIO = 19.0


def check_profile_units(
    r_mm: np.ndarray, dr_um: np.ndarray, where: Sequence[str] | None = None
) -> None:
    """Refuse a profile whose distortion is as large as its radius (|δr| ≥ r: 100 % or more),
    the mark of radii in metres or of δr in mm labelled µm; the message says so, after
    ``where[i]`` (e.g. ``"file.csv:12: "``) of the first such point when given."""
    r = np.abs(np.asarray(r_mm, dtype=float))
    d = np.abs(np.asarray(dr_um, dtype=float)) / 1000.0
    big = np.nonzero((r > 0) & (d >= r))[0]
    if big.size:
        i = int(big[0])
        raise DataError(
            ("" if where is None else where[i])
            + f"distortion {d[i] * 1000.0:g} µm at r = {r[i]:g} mm is as large as the radius "
            "itself: radii must be in mm and distortion in µm (radii in metres, or distortion "
            "in mm under a µm label?)"
        )


def fit_radial(
    r_mm: np.ndarray,
    dr_um: np.ndarray,
    *,
    form: str = "gaussian",
    n_terms: int = 3,
    radius: str = "measured",
) -> RadialFit:
    """Fit δr (µm) at radii r (mm) with K1 r³ + … (+ K0 r if ``form="balanced"``), n_terms odd
    terms (1–3 … any ≥ 1). Least squares on the powers of r/r_max (well conditioned), then
    rescaled. Needs more points than unknowns for standard errors; at least as many to fit.

    Parameters
    ----------
    r_mm : array_like
        Radii in mm, 1-D and finite (measured or ideal radii: see ``radius``).
    dr_um : array_like
        Radial distortion δr = r_actual − r_ideal in µm (positive outward = pincushion), same
        length as ``r_mm``.
    form : {"gaussian", "balanced"}
        ``"gaussian"`` (default): ``δr = K1 r³ + K2 r⁵ + …``, no linear term (referred to the
        Gaussian principal distance); ``"balanced"``: with a linear term ``K0 r`` (a calibrated
        principal distance; Pestrecov 1958 Eq. 12, module docstring).
    n_terms : int
        The number of odd terms K1 r³ … (≥ 1; default 3).
    radius : {"measured", "ideal"}
        What r means; only recorded in the result (the fit is the same).

    Returns
    -------
    RadialFit
        ``k0`` (0 for the Gaussian form), ``k`` = (K1, K2, …) in mm⁻², mm⁻⁴, …, their standard
        errors (NaN without redundancy), residuals ``data − fit`` in µm, their RMS and largest
        absolute value (µm).

    Raises
    ------
    DataError
        An unknown ``form`` or ``radius``, ``n_terms`` < 1, arrays that are not 1-D of one
        length, non-finite values, |δr| ≥ r (radii in metres or δr in mm?), fewer points than
        coefficients, all radii zero.
    """
    if form not in ("gaussian", "balanced"):
        raise DataError(f"unknown form {form!r} (expected 'gaussian' or 'balanced')")
    if radius not in _RADIUS:
        raise DataError(f"unknown radius convention {radius!r} (expected {_RADIUS})")
    if not (is_whole(n_terms) and n_terms >= 1):
        why = "" if is_whole(n_terms) else f" (a whole number of odd terms), got {n_terms!r}"
        raise DataError(f"n_terms must be at least 1{why}")
    r = np.asarray(r_mm, dtype=float)
    d_um = np.asarray(dr_um, dtype=float)
    if r.shape != d_um.shape or r.ndim != 1:
        raise DataError("r_mm and dr_um must be 1-D arrays of the same length")
    if not (np.all(np.isfinite(r)) and np.all(np.isfinite(d_um))):
        raise DataError("the profile contains non-finite values")
    check_profile_units(r, d_um)
    powers = ([1] if form == "balanced" else []) + [2 * i + 1 for i in range(1, n_terms + 1)]
    p = len(powers)
    if r.size < p:
        raise DataError(f"{p} coefficients need at least {p} profile points, got {r.size}")
    rs = float(np.max(np.abs(r)))
    if rs == 0:
        raise DataError("all radii are zero")
    u = r / rs
    a = np.stack([u**e for e in powers], axis=1)
    d = d_um / 1000.0
    sol, *_ = np.linalg.lstsq(a, d, rcond=None)
    resid_mm = d - a @ sol
    scale = np.array([rs**e for e in powers])
    coef = sol / scale
    dof = r.size - p
    if dof > 0:
        s2 = float(resid_mm @ resid_mm) / dof
        cov = s2 * np.linalg.pinv(a.T @ a)
        se = np.sqrt(np.diag(cov)) / scale
    else:
        se = np.full(p, math.nan)
    if form == "balanced":
        k0, se0, k, sek = float(coef[0]), float(se[0]), coef[1:], se[1:]
    else:
        k0, se0, k, sek = 0.0, 0.0, coef, se
    res_um = resid_mm * 1000.0
    return RadialFit(
        form=form,
        radius=radius,
        k0=k0,
        k=tuple(float(x) for x in k),
        se_k0=se0,
        se_k=tuple(float(x) for x in sek),
        r_mm=r,
        dr_um=d_um,
        residual_um=res_um,
        rms_um=float(np.sqrt(np.mean(res_um**2))),
        max_abs_um=float(np.max(np.abs(res_um))),
    )


def balanced_scale_ratio(k0: float, radius: str = "measured") -> float:
    """q = c_b/c_g from the linear term: 1 − K0 (measured radius) or 1/(1 + K0) (ideal)."""
    if radius not in _RADIUS:
        raise DataError(f"unknown radius convention {radius!r}")
    q = 1.0 - k0 if radius == "measured" else 1.0 / (1.0 + k0)
    if not q > 0:
        raise DataError(f"linear term K0 = {k0:g} implies a non-positive principal distance")
    return q


def balanced_to_gaussian(
    k0: float, k: Sequence[float], radius: str = "measured"
) -> tuple[tuple[float, ...], float]:
    """Balanced (K0, K_b) → Gaussian K_g and q = c_b/c_g (exact relations, module docstring)."""
    q = balanced_scale_ratio(k0, radius)
    if radius == "measured":
        kg = tuple(ki / q for ki in k)
    else:
        kg = tuple(ki * q ** (2 * i + 1) for i, ki in enumerate(k, start=1))
    return kg, q


def gaussian_to_balanced(
    k: Sequence[float], q: float, radius: str = "measured"
) -> tuple[float, tuple[float, ...]]:
    """Gaussian K_g and q = c_b/c_g → balanced (K0, K_b) (exact; inverse of the above)."""
    if not q > 0:
        raise DataError(f"principal distance ratio must be positive, got {q!r}")
    if radius == "measured":
        return 1.0 - q, tuple(q * ki for ki in k)
    if radius == "ideal":
        return 1.0 / q - 1.0, tuple(ki * q ** -(2 * i + 1) for i, ki in enumerate(k, start=1))
    raise DataError(f"unknown radius convention {radius!r}")


def brown_to_opencv(k: Sequence[float], c_mm: float) -> tuple[float, ...]:
    """Gaussian K_i (mm^-2i, ideal radius) → OpenCV k_i = K_i c^(2i) (c = principal distance mm)."""
    if not c_mm > 0:
        raise DataError(f"principal distance must be positive, got {c_mm!r}")
    return scale_radial_coefficients(k, c_mm)


def opencv_to_brown(kcv: Sequence[float], c_mm: float) -> tuple[float, ...]:
    """OpenCV k_i → Gaussian K_i = k_i / c^(2i) (inverse of :func:`brown_to_opencv`)."""
    if not c_mm > 0:
        raise DataError(f"principal distance must be positive, got {c_mm!r}")
    return scale_radial_coefficients(kcv, 1.0 / c_mm)


@dataclass(frozen=True, eq=False)
class OpenCVModel:
    """OpenCV radial coefficients for a profile. ``principal_distance_mm`` is the Gaussian c_g
    (the one OpenCV's fx must use: fx = c_g / pitch); ``fx_px`` when the pixel pitch is known.
    ``fit`` is the ideal-radius fit the coefficients come from (residuals in µm);
    ``rms_px``/``max_abs_px`` the residuals in pixels when the pitch is known."""

    k1: float
    k2: float
    k3: float
    principal_distance_mm: float
    input_principal_distance_mm: float
    pixel_pitch_um: float | None
    fx_px: float | None
    fit: RadialFit
    gaussian_k: tuple[float, ...]
    rms_px: float | None
    max_abs_px: float | None
    notes: tuple[str, ...]


def opencv_model(
    r_mm: np.ndarray,
    dr_um: np.ndarray,
    *,
    principal_distance_mm: float | None = None,
    focal_length_px: float | None = None,
    pixel_pitch_um: float | None = None,
    radius: str = "measured",
    balanced: bool = False,
) -> OpenCVModel:
    """OpenCV k1, k2, k3 for a radial profile δr (µm) at r (mm).

    The profile refers to the principal distance c (``principal_distance_mm``, or
    ``focal_length_px`` × ``pixel_pitch_um``/1000). A "measured"-radius profile is moved to the
    ideal radius r − δr; the Gaussian (or, with ``balanced=True``, balanced) 3-term polynomial
    is fitted there; a balanced fit is converted to Gaussian with c_g = c (1 + K0); then
    k_i = K_i c_g^(2i). ``fx_px`` = c_g / pitch if the pitch is given.

    Parameters
    ----------
    r_mm : array_like
        Radii in mm (measured or ideal: see ``radius``).
    dr_um : array_like
        Radial distortion δr = r_actual − r_ideal in µm (positive outward = pincushion).
    principal_distance_mm : float, optional
        c in mm (positive, finite). Give it or ``focal_length_px``, not both.
    focal_length_px : float, optional
        c in pixels; needs ``pixel_pitch_um``.
    pixel_pitch_um : float, optional
        Pixel pitch in µm (a number; a value that looks like mm is refused). With it the result
        also has ``fx`` and residuals in pixels.
    radius : {"measured", "ideal"}
        What r means (default the measured radius, the photogrammetric convention).
    balanced : bool
        Fit the balanced form (with a linear term K0 r) instead of the Gaussian one.

    Returns
    -------
    OpenCVModel
        k1, k2, k3 (dimensionless, same signs as K: k1 > 0 is pincushion), the Gaussian principal
        distance c_g and the given c (mm), the pitch (µm), fx = c_g / pitch (px, or None), the
        :class:`RadialFit`, the Gaussian K1–K3, the RMS and largest residual in px (None
        without a pitch) and notes.

    Raises
    ------
    DataError
        Neither or both of ``principal_distance_mm`` and ``focal_length_px``, a focal length in
        pixels without a pitch, c not positive, a pitch :func:`parse_pitch_um` refuses, an
        unknown ``radius``, |δr| ≥ r, c below the largest radius / 19 (a unit slip), or a profile
        :func:`fit_radial` refuses.
    """
    if pixel_pitch_um is not None:
        from .camera.sensor import parse_pitch_um

        pixel_pitch_um = parse_pitch_um(pixel_pitch_um)[0]  # µm, or "6um" / "0.006mm"
    if principal_distance_mm is None:
        if focal_length_px is None:
            raise DataError("give the principal distance in mm, or the focal length in pixels")
        if pixel_pitch_um is None:
            raise DataError(
                "a focal length in pixels needs the pixel pitch (µm) to relate it to the "
                "profile's radii in mm"
            )
        principal_distance_mm = focal_length_px * pixel_pitch_um / 1000.0
    elif focal_length_px is not None:
        raise DataError("give either the principal distance (mm) or the focal length (px)")
    c = float(principal_distance_mm)
    if not (c > 0 and math.isfinite(c)):
        raise DataError(f"principal distance must be positive, got {c!r}")
    if radius not in _RADIUS:
        raise DataError(f"unknown radius convention {radius!r}")
    r = np.asarray(r_mm, dtype=float)
    d = np.asarray(dr_um, dtype=float)
    notes = []
    check_profile_units(r, d)
    ratio = float(np.max(np.abs(r), initial=0.0)) / c
    if ratio > MAX_RADIUS_RATIO:
        raise DataError(
            f"principal distance {c:g} mm is {ratio:.3g} times smaller than the largest radius "
            f"{ratio * c:g} mm (a field angle of {math.degrees(math.atan(ratio)):.4g}°): is it "
            "in the wrong unit (metres for mm, or a pixel pitch in mm for µm)?"
        )
    r_ideal = r - d / 1000.0 if radius == "measured" else r
    if radius == "measured":
        notes.append("measured radii converted to ideal radii r - dr before fitting")
    fit = fit_radial(r_ideal, d, form="balanced" if balanced else "gaussian", radius="ideal")
    if balanced:
        kg, q = balanced_to_gaussian(fit.k0, fit.k, "ideal")
        c_g = c / q
        notes.append(
            f"balanced fit: K0 = {fit.k0:.6g}; Gaussian principal distance c_g = c(1 + K0) = "
            f"{c_g:.6f} mm"
        )
    else:
        kg, c_g = fit.k, c
    k1, k2, k3 = brown_to_opencv(kg, c_g)
    fx = c_g / (pixel_pitch_um / 1000.0) if pixel_pitch_um else None
    rms_px = fit.rms_um / pixel_pitch_um if pixel_pitch_um else None
    max_px = fit.max_abs_um / pixel_pitch_um if pixel_pitch_um else None
    return OpenCVModel(
        k1, k2, k3, c_g, c, pixel_pitch_um, fx, fit, tuple(kg), rms_px, max_px, tuple(notes)
    )
