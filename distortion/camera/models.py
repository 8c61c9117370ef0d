"""Camera models as pure, vectorised numpy functions: forward, inverse and Jacobian.

A camera model maps an **ideal direction** — normalised camera coordinates ``x = X/Z``,
``y = Y/Z`` (x right, y down, z toward the object; :mod:`distortion.camera.conventions`) — to an
**image point** in the model's own (native) image frame, and back.

Each model has one *explicit* direction, evaluated in closed form with its analytic 2 × 2
Jacobian; the other direction is solved by Newton's method with that Jacobian (backtracking on
the residual), converged to ``TOL_PX`` = 1e-12 px or to the rounding floor of the coordinates
(16 ulp of the larger pixel coordinate, 2e-11 px at 6000 px), whichever is larger. A point
that does not converge gets a status code instead of a silent number (:data:`STATUS_NAMES`):
``NOT_CONVERGED``, ``SINGULAR`` (zero Jacobian), ``FOLDED`` (the solution lies on a branch
where the map has folded back — past the radius where the distortion turns round, so it is not
the inverse a camera means: relative to the Jacobian at the centre, its Jacobian has an
eigenvalue in the left half plane) or ``INVALID`` (non-finite input, Z ≤ 0, outside the
model's domain).

The models and their formulas (each written once, in the functions below):

``opencv`` — OpenCV standard (``cv2.projectPoints``, calib3d ``cvProjectPoints2Internal``)
    r² = x² + y²;
    x' = x (1 + k1 r² + k2 r⁴ + k3 r⁶)/(1 + k4 r² + k5 r⁴ + k6 r⁶) + 2 p1 x y + p2 (r² + 2x²)
    + s1 r² + s2 r⁴;  y' = y (…)/(…) + p1 (r² + 2y²) + 2 p2 x y + s3 r² + s4 r⁴;
    then the tilted-sensor projection (x'', y'', 1) ∝ R_tilt (x', y', 1) with OpenCV's
    ``computeTiltProjectionMatrix`` (τx about x, then τy about y, in **radians**, as in the
    coefficient vector); u = fx x'' + cx, v = fy y'' + cy (OpenCV pixels; ``projectPoints``
    ignores a skew in the camera matrix). Coefficient vectors of 4, 5, 8, 12 or 14 elements
    (k1 k2 p1 p2 [k3 [k4 k5 k6 [s1 s2 s3 s4 [τx τy]]]]).
``opencv_fisheye`` — OpenCV fisheye / Kannala–Brandt (``cv2.fisheye.projectPoints``)
    θ = atan r, θd = θ (1 + k1 θ² + k2 θ⁴ + k3 θ⁶ + k4 θ⁸), (x', y') = (θd / r)(x, y),
    u = fx (x' + α y') + cx, v = fy y' + cy.
``colmap:…`` — COLMAP's camera models (``colmap/sensor/models.h``; COLMAP pixels, centres at
    +0.5): SIMPLE_PINHOLE, PINHOLE; SIMPLE_RADIAL, RADIAL (x (1 + k1 r² + k2 r⁴)); OPENCV
    (k1 k2 p1 p2), FULL_OPENCV (OpenCV's 8); OPENCV_FISHEYE (= OpenCV fisheye, no skew);
    SIMPLE_RADIAL_FISHEYE, RADIAL_FISHEYE (θd = θ (1 + k1 θ² [+ k2 θ⁴])); SIMPLE_FISHEYE, FISHEYE
    (equidistant, θd = θ); THIN_PRISM_FISHEYE (the equidistant point (θ/r)(x, y), then OpenCV's
    radial k1..k4, tangential p1 p2 and prism sx1 r², sy1 r² on it); RAD_TAN_THIN_PRISM_FISHEYE
    (Project Aria: radial k0..k5 in θ² first, then tangential p0 (on x's r² + 2x²), p1 and prism
    s0..s3 on the *radially distorted* point); FOV (factor atan(2 r tan(ω/2)) / (r ω), with
    COLMAP's series branches for ω² < 1e-4 and r² < 1e-4); SIMPLE_DIVISION, DIVISION (the
    explicit map is image → ideal: x_u = x_d / (1 + k r_d²)); EUCM (x / (α d + 1 − α),
    d = √(β r² + 1)). EQUIRECTANGULAR (a spherical image, not a lens model) is not included.
``metashape`` — Agisoft Metashape frame camera (User Manual, Appendix C "Camera models";
    transcribed in easyidp 2.0.4 ``reconstruct.py``): x' = x (1 + K1 r² + K2 r⁴ + K3 r⁶ + K4 r⁸)
    + (P1 (r² + 2x²) + 2 P2 x y)(1 + P3 r² + P4 r⁴), y' = y (…) + (P2 (r² + 2y²) + 2 P1 x y)(…);
    u = W/2 + cx + x' (f + B1) + y' B2, v = H/2 + cy + y' f (Metashape pixels: centres at
    +0.5, cx, cy offsets from the image centre). Its P1 is OpenCV's p2.
``australis`` — Brown / Fraser 10-parameter model as Australis and Fraser & Shortis use it
    (Fraser 1997, *Digital camera self-calibration*, ISPRS J. 52, Eqs. 1–3): measured image
    coordinates (x, y) in mm, y up, origin at the image centre; x̄ = x − xp, ȳ = y − yp;
    Δx = x̄ (K1 r² + K2 r⁴ + K3 r⁶) + P1 (r² + 2x̄²) + 2 P2 x̄ ȳ + b1 x̄ + b2 ȳ,
    Δy = ȳ (K1 r² + K2 r⁴ + K3 r⁶) + 2 P1 x̄ ȳ + P2 (r² + 2ȳ²); the **correction** gives the
    ideal point x̄ + Δx = c X/Z, ȳ + Δy = −c Y/Z (c the principal distance, mm). Its explicit
    direction is therefore image → ideal. (A K1 > 0 moves points outward on correction: barrel.)

Parameters are named as each target names them (``CameraModel.spec.params``) and keep the
target's units: pixels for focal lengths and principal points, dimensionless coefficients,
radians for OpenCV's τ, mm (and mm^-2i) for the Australis model.
"""

from __future__ import annotations

import difflib
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from ..errors import DataError
from .conventions import (
    image_centre,
    opencv_pixels_to_photo_mm,
    photo_mm_to_opencv_pixels,
    pixel_centre_offset,
)
from .sensor import Sensor, check_pixel_size_mm, check_principal_distance_mm

# ---- status codes ---------------------------------------------------------------------------
OK = 0
NOT_CONVERGED = 1
SINGULAR = 2
FOLDED = 3
INVALID = 4
STATUS_NAMES = {
    OK: "ok",
    NOT_CONVERGED: "not converged",
    SINGULAR: "singular Jacobian",
    FOLDED: "folded: the solution lies on a branch where the distortion has turned round",
    INVALID: "invalid: non-finite, behind the camera or outside the model's domain",
}

#: Newton tolerance in pixels (see the module docstring for the rounding floor)
TOL_PX = 1e-12
ROUNDING_ULPS = 16.0
MAX_ITER = 60

_EPS = np.finfo(float).eps


# ---- building blocks: value and analytic Jacobian (j11, j12, j21, j22) ------------------------
def _mul(a, b):
    """2 × 2 product a·b of Jacobians given as 4-tuples."""
    return (
        a[0] * b[0] + a[1] * b[2],
        a[0] * b[1] + a[1] * b[3],
        a[2] * b[0] + a[3] * b[2],
        a[2] * b[1] + a[3] * b[3],
    )


_IDENTITY = (1.0, 0.0, 0.0, 1.0)


def _zeros(shape, *values):
    return np.zeros(shape, dtype=np.result_type(float, *values))


def _series(coeffs: Sequence, t):
    """(Σ_{i≥1} k_i t^i, its derivative d/dt) by Horner's rule."""
    q = _zeros(np.shape(t), t, *coeffs)
    dq = _zeros(np.shape(t), t, *coeffs)
    for k in reversed(tuple(coeffs)):
        dq = dq * t + q
        q = q * t + k
    return t * q, q + t * dq


def radial_polynomial(coeffs: Sequence[float], r2: np.ndarray) -> np.ndarray:
    """Σ_i k_i (r²)^i for i = 1, 2, … — the even radial series every model here uses
    (OpenCV's 1 + k1 r² + k2 r⁴ + … is ``1 + radial_polynomial((k1, k2, …), r²)``)."""
    return _series(coeffs, np.asarray(r2))[0]


def scale_radial_coefficients(coeffs: Sequence[float], scale: float) -> tuple[float, ...]:
    """k_i · scale^(2i): the radial coefficients of the same distortion when the radius is
    measured in units ``scale`` times larger (mm-unit K_i → normalised k_i with scale = c in mm;
    the inverse with 1/scale)."""
    return tuple(k * scale ** (2 * i) for i, k in enumerate(coeffs, start=1))


def _equidistant(x, y):
    """(x, y) = (X/Z, Y/Z) → (θ/r)(x, y) with θ = atan r: the equidistant fisheye point."""
    r2 = x * x + y * y
    small = np.real(r2) < 1e-8
    r2s = np.where(small, 1.0, r2)
    r = np.sqrt(r2s)
    big_s = np.arctan(r) / r
    s = np.where(small, 1.0 + r2 * (-1 / 3 + r2 * (1 / 5 + r2 * (-1 / 7 + r2 / 9))), big_s)
    ds = np.where(
        small,
        -1 / 3 + r2 * (2 / 5 + r2 * (-3 / 7 + r2 * 4 / 9)),
        (1.0 / (1.0 + r2s) - big_s) / (2.0 * r2s),
    )
    return s * x, s * y, (s + 2 * x * x * ds, 2 * x * y * ds, 2 * x * y * ds, s + 2 * y * y * ds)


def equidistant_coordinates(x, y) -> tuple[np.ndarray, np.ndarray]:
    """(X/Z, Y/Z) → (θ/r)(x, y), θ = atan r: the undistorted point of the equidistant fisheye
    models (|result| = θ in radians)."""
    a, b, _ = _equidistant(np.asarray(x, float), np.asarray(y, float))
    return a, b


def _equidistant_inverse(a, b):
    """Inverse of :func:`_equidistant` (θ clipped below 90°: used for starting points only)."""
    th = np.sqrt(a * a + b * b)
    thc = np.minimum(th, 1.55)
    ok = th > 1e-12
    f = np.where(ok, np.tan(thc) / np.where(ok, th, 1.0), 1.0)
    return a * f, b * f


def _poly(x, y, num=(), den=(), p1=0.0, p2=0.0, q=(), s=(0.0, 0.0, 0.0, 0.0)):
    """The polynomial distortion (OpenCV's p1/p2 placement):
    x' = x N/D + (2 p1 x y + p2 (r² + 2x²)) T + s1 r² + s2 r⁴,
    y' = y N/D + (p1 (r² + 2y²) + 2 p2 x y) T + s3 r² + s4 r⁴,
    N = 1 + Σ num_i r^2i, D = 1 + Σ den_i r^2i, T = 1 + Σ q_i r^2i."""
    r2 = x * x + y * y
    n, dn = _series(num, r2)
    n = n + 1.0
    if any(np.any(d != 0) for d in den):
        d, dd = _series(den, r2)
        d = d + 1.0
        rad = n / d
        drad = (dn * d - n * dd) / (d * d)
    else:
        rad, drad = n, dn
    t, dt = _series(q, r2)
    t = t + 1.0
    tx = 2 * p1 * x * y + p2 * (r2 + 2 * x * x)
    ty = p1 * (r2 + 2 * y * y) + 2 * p2 * x * y
    s1, s2, s3, s4 = s
    sx = s1 * r2 + s2 * r2 * r2
    sy = s3 * r2 + s4 * r2 * r2
    dsx = s1 + 2 * s2 * r2
    dsy = s3 + 2 * s4 * r2
    xd = x * rad + tx * t + sx
    yd = y * rad + ty * t + sy
    j11 = rad + 2 * x * x * drad + (2 * p1 * y + 6 * p2 * x) * t + 2 * x * (tx * dt + dsx)
    j12 = 2 * x * y * drad + (2 * p1 * x + 2 * p2 * y) * t + 2 * y * (tx * dt + dsx)
    j21 = 2 * x * y * drad + (2 * p1 * x + 2 * p2 * y) * t + 2 * x * (ty * dt + dsy)
    j22 = rad + 2 * y * y * drad + (6 * p1 * y + 2 * p2 * x) * t + 2 * y * (ty * dt + dsy)
    return xd, yd, (j11, j12, j21, j22)


def tilt_matrix(tau_x: float, tau_y: float) -> np.ndarray:
    """OpenCV's ``computeTiltProjectionMatrix`` (calib3d ``distortion_model.hpp``): the 3 × 3
    map of the tilted sensor, τx about x then τy about y (radians)."""
    cx, sx = np.cos(tau_x), np.sin(tau_x)
    cy, sy = np.cos(tau_y), np.sin(tau_y)
    z, o = 0.0 * cx, 1.0 + 0.0 * cx
    rot_x = np.array([[o, z, z], [z, cx, sx], [z, -sx, cx]])
    rot_y = np.array([[cy, z, -sy], [z, o, z], [sy, z, cy]])
    rxy = rot_y @ rot_x
    proj_z = np.array([[rxy[2, 2], z, -rxy[0, 2]], [z, rxy[2, 2], -rxy[1, 2]], [z, z, o]])
    return proj_z @ rxy


def _tilt(x, y, tau_x, tau_y):
    m = tilt_matrix(tau_x, tau_y)
    a = m[0, 0] * x + m[0, 1] * y + m[0, 2]
    b = m[1, 0] * x + m[1, 1] * y + m[1, 2]
    c = m[2, 0] * x + m[2, 1] * y + m[2, 2]
    ic = 1.0 / c
    u, v = a * ic, b * ic
    return (
        u,
        v,
        (
            (m[0, 0] - u * m[2, 0]) * ic,
            (m[0, 1] - u * m[2, 1]) * ic,
            (m[1, 0] - v * m[2, 0]) * ic,
            (m[1, 1] - v * m[2, 1]) * ic,
        ),
    )


def _tilt_inverse(u, v, tau_x, tau_y):
    mi = np.linalg.inv(tilt_matrix(float(np.real(tau_x)), float(np.real(tau_y))))
    a = mi[0, 0] * u + mi[0, 1] * v + mi[0, 2]
    b = mi[1, 0] * u + mi[1, 1] * v + mi[1, 2]
    c = mi[2, 0] * u + mi[2, 1] * v + mi[2, 2]
    return a / c, b / c


def _has(v) -> bool:
    """True when a coefficient must be evaluated (nonzero, or complex for the complex step)."""
    return bool(np.iscomplexobj(v) or v != 0)


# ---- the canonical terms of the polynomial family ---------------------------------------------
@dataclass(frozen=True)
class _Terms:
    """The polynomial-family models in one form, in OpenCV pixels (exact conversions)."""

    fx: float
    fy: float
    cx: float
    cy: float
    skew: float = 0.0
    projection: str = "perspective"  # or "equidistant"
    num: tuple = (0.0,) * 6
    den: tuple = (0.0,) * 3
    p1: float = 0.0
    p2: float = 0.0
    q: tuple = (0.0, 0.0)
    s: tuple = (0.0, 0.0, 0.0, 0.0)
    tau: tuple = (0.0, 0.0)
    split: bool = False  # tangential/prism after the radial stage (RAD_TAN_THIN_PRISM_FISHEYE)


def _terms_forward(t: _Terms, x, y, shift: float):
    """Ideal (x, y) → native pixels (OpenCV pixels + ``shift``) with the Jacobian."""
    jac = _IDENTITY
    if t.projection == "equidistant":
        x, y, jac = _equidistant(x, y)
    if t.split:
        x, y, j1 = _poly(x, y, num=t.num)
        x, y, j2 = _poly(x, y, p1=t.p1, p2=t.p2, s=t.s)
        jac = _mul(j2, _mul(j1, jac))
    else:
        x, y, j1 = _poly(x, y, t.num, t.den, t.p1, t.p2, t.q, t.s)
        jac = _mul(j1, jac)
    if _has(t.tau[0]) or _has(t.tau[1]):
        x, y, jt = _tilt(x, y, t.tau[0], t.tau[1])
        jac = _mul(jt, jac)
    u = t.fx * x + t.skew * y + (t.cx + shift)
    v = t.fy * y + (t.cy + shift)
    return u, v, _mul((t.fx, t.skew, 0.0, t.fy), jac)


def _terms_guess(t: _Terms, u, v, shift: float):
    """Starting point of the inverse: pinhole/tilt/equidistant inverted exactly, the
    polynomial distortion ignored."""
    y = (v - (t.cy + shift)) / np.real(t.fy)
    x = (u - (t.cx + shift) - np.real(t.skew) * y) / np.real(t.fx)
    if _has(t.tau[0]) or _has(t.tau[1]):
        x, y = _tilt_inverse(x, y, t.tau[0], t.tau[1])
    if t.projection == "equidistant":
        x, y = _equidistant_inverse(x, y)
    return x, y


# ---- recipes: how each polynomial-family model's parameters fill the terms ----------------------
@dataclass(frozen=True)
class _Recipe:
    focal: str  # "f" | "fxfy" | "metashape"
    projection: str = "perspective"
    num: tuple = ()
    den: tuple = ()
    p: tuple = (None, None)  # (name carrying OpenCV p1, name carrying OpenCV p2)
    q: tuple = ()
    s: tuple = (None, None, None, None)
    tau: tuple = (None, None)
    alpha: str | None = None  # OpenCV fisheye skew: u = fx (x + α y) + cx
    split: bool = False


def _pad(vals, n):
    return tuple(vals) + (0.0,) * (n - len(vals))


def _recipe_terms(rc: _Recipe, frame: str, p: Mapping, cam: CameraModel) -> _Terms:
    def g(name):
        return p[name] if name is not None else 0.0

    h = pixel_centre_offset(frame)
    if rc.focal == "f":
        fx = fy = p["f"]
        skew = 0.0
        cx, cy = p["cx"] - h, p["cy"] - h
    elif rc.focal == "fxfy":
        fx, fy, skew = p["fx"], p["fy"], 0.0
        cx, cy = p["cx"] - h, p["cy"] - h
    else:  # metashape: u = W/2 + cx + x'(f + b1) + y' b2, v = H/2 + cy + y' f
        fx, fy, skew = p["f"] + p["b1"], p["f"], p["b2"]
        c0u, c0v = image_centre(cam.width, cam.height, "opencv")
        cx, cy = c0u + p["cx"], c0v + p["cy"]
    if rc.alpha is not None:
        skew = fx * p[rc.alpha]
    return _Terms(
        fx=fx,
        fy=fy,
        cx=cx,
        cy=cy,
        skew=skew,
        projection=rc.projection,
        num=_pad([p[n] for n in rc.num], 6),
        den=_pad([p[n] for n in rc.den], 3),
        p1=g(rc.p[0]),
        p2=g(rc.p[1]),
        q=_pad([p[n] for n in rc.q], 2),
        s=tuple(g(n) for n in rc.s),
        tau=tuple(g(n) for n in rc.tau),
        split=rc.split,
    )


class NotRepresentable(DataError):
    """A model's terms cannot be written exactly in another model (the conversion must be a
    refit). ``terms`` names what the target lacks."""

    def __init__(self, message: str, terms: Sequence[str] = ()):
        super().__init__(message)
        self.terms = tuple(terms)


def _recipe_params(
    rc: _Recipe, frame: str, t: _Terms, cam: CameraModel, name: str, lenient: bool = False
) -> dict:
    lost: list[str] = []
    out: dict[str, float] = {}
    if t.projection != rc.projection:
        lost.append(f"{t.projection} projection")
    if t.split != rc.split and (any(v != 0 for v in (t.p1, t.p2, *t.s))):
        lost.append("tangential/prism terms applied after the radial stage")
    h = pixel_centre_offset(frame)
    if rc.focal == "f":
        if abs(t.fx - t.fy) > 1e-12 * abs(t.fy):
            lost.append("fx != fy")
        out["f"] = 0.5 * (t.fx + t.fy)
        out["cx"], out["cy"] = t.cx + h, t.cy + h
    elif rc.focal == "fxfy":
        out["fx"], out["fy"] = t.fx, t.fy
        out["cx"], out["cy"] = t.cx + h, t.cy + h
    else:
        out["f"], out["b1"], out["b2"] = t.fy, t.fx - t.fy, t.skew
        c0u, c0v = image_centre(cam.width, cam.height, "opencv")
        out["cx"], out["cy"] = t.cx - c0u, t.cy - c0v
    if rc.alpha is not None:
        out[rc.alpha] = t.skew / t.fx
    elif rc.focal != "metashape" and t.skew != 0:
        lost.append("skew")

    def put(names, vals, label):
        for i, v in enumerate(vals):
            n = names[i] if i < len(names) else None
            if n is None:
                if v != 0:
                    lost.append(f"{label}{i + 1}")
            else:
                out[n] = v

    put(rc.num, t.num, "radial r^2 term ")
    put(rc.den, t.den, "rational denominator term ")
    put(rc.p, (t.p1, t.p2), "tangential OpenCV p")
    put(rc.q, t.q, "tangential multiplier (Metashape p3/p4) ")
    put(rc.s, t.s, "thin prism s")
    put(rc.tau, t.tau, "sensor tilt tau ")
    if lost and not lenient:
        raise NotRepresentable(f"{name} cannot hold: {', '.join(lost)}", lost)
    return out


# ---- the models that are not in the polynomial family -----------------------------------------
def _fov_factor(omega, r2):
    """COLMAP's FOV model factor and its derivative d/d r² (branches as in COLMAP)."""
    w2 = omega * omega
    if np.real(w2) < 1e-4:
        return w2 * r2 / 3 - w2 / 12 + 1, w2 / 3 + 0 * r2
    t = np.tan(omega / 2)
    small = np.real(r2) < 1e-4
    r2s = np.where(small, 1.0, r2)
    r = np.sqrt(r2s)
    big = np.arctan(2 * r * t) / (r * omega)
    fac = np.where(small, -2 * t * (4 * r2 * t * t - 3) / (3 * omega), big)
    dfac = np.where(
        small,
        -8 * t**3 / (3 * omega) + 0 * r2,
        (2 * t / (omega * (1 + 4 * r2s * t * t)) - big) / (2 * r2s),
    )
    return fac, dfac


def _radial_factor_map(x, y, fac, dfac):
    return (
        x * fac,
        y * fac,
        (
            fac + 2 * x * x * dfac,
            2 * x * y * dfac,
            2 * x * y * dfac,
            fac + 2 * y * y * dfac,
        ),
    )


def _focal(p):
    return (p["f"], p["f"]) if "f" in p else (p["fx"], p["fy"])


def _fov_forward(p, x, y, cam):
    fac, dfac = _fov_factor(p["omega"], x * x + y * y)
    xd, yd, j = _radial_factor_map(x, y, fac, dfac)
    fx, fy = _focal(p)
    return fx * xd + p["cx"], fy * yd + p["cy"], _mul((fx, 0.0, 0.0, fy), j)


def _eucm_forward(p, x, y, cam):
    a, b = p["alpha"], p["beta"]
    d = np.sqrt(b * (x * x + y * y) + 1.0)
    den = a * d + 1.0 - a
    k = a * b / (d * den * den)
    xd, yd = x / den, y / den
    j = (1.0 / den - x * x * k, -x * y * k, -x * y * k, 1.0 / den - y * y * k)
    fx, fy = _focal(p)
    return fx * xd + p["cx"], fy * yd + p["cy"], _mul((fx, 0.0, 0.0, fy), j)


def _pinhole_guess(p, u, v, cam):
    fx, fy = _focal(p)
    return (u - p["cx"]) / np.real(fx), (v - p["cy"]) / np.real(fy)


def _division_inverse(p, u, v, cam):
    """COLMAP division model, image → ideal: x_u = x_d / (1 + k r_d²)."""
    fx, fy = _focal(p)
    xd, yd = (u - p["cx"]) / fx, (v - p["cy"]) / fy
    k = p["k"]
    den = 1.0 + k * (xd * xd + yd * yd)
    g = 2 * k / (den * den)
    j = (1 / den - xd * xd * g, -xd * yd * g, -xd * yd * g, 1 / den - yd * yd * g)
    return xd / den, yd / den, _mul(j, (1.0 / fx, 0.0, 0.0, 1.0 / fy))


def _division_guess(p, x, y, cam):
    fx, fy = _focal(p)
    return np.real(fx) * x + p["cx"], np.real(fy) * y + p["cy"]


def _australis_inverse(p, x, y, cam):
    """Fraser 1997 correction: measured photo mm → ideal X/Z, Y/Z."""
    xb, yb = x - p["xp"], y - p["yp"]
    r2 = xb * xb + yb * yb
    rad, drad = _series((p["K1"], p["K2"], p["K3"]), r2)
    P1, P2, b1, b2, c = p["P1"], p["P2"], p["b1"], p["b2"], p["c"]
    dx = xb * rad + P1 * (r2 + 2 * xb * xb) + 2 * P2 * xb * yb + b1 * xb + b2 * yb
    dy = yb * rad + 2 * P1 * xb * yb + P2 * (r2 + 2 * yb * yb)
    j11 = 1 + rad + 2 * xb * xb * drad + 6 * P1 * xb + 2 * P2 * yb + b1
    j12 = 2 * xb * yb * drad + 2 * P1 * yb + 2 * P2 * xb + b2
    j21 = 2 * xb * yb * drad + 2 * P1 * yb + 2 * P2 * xb
    j22 = 1 + rad + 2 * yb * yb * drad + 2 * P1 * xb + 6 * P2 * yb
    return (xb + dx) / c, -(yb + dy) / c, (j11 / c, j12 / c, -j21 / c, -j22 / c)


def _australis_guess(p, a, b, cam):
    c = np.real(p["c"])
    return c * a + p["xp"], -c * b + p["yp"]


def _pinhole_from(t: _Terms, lost: list[str]) -> None:
    if t.projection != "perspective":
        lost.append(f"{t.projection} projection")
    for label, vals in (
        ("radial", t.num),
        ("rational", t.den),
        ("tangential", (t.p1, t.p2)),
        ("Metashape p3/p4", t.q),
        ("thin prism", t.s),
        ("tilt", t.tau),
    ):
        if any(v != 0 for v in vals):
            lost.append(f"{label} terms")


def _custom_pinhole_terms(identity: Callable[[Mapping], bool], frame: str):
    """terms() of a non-polynomial model: only when its distortion is the identity."""

    def terms(p, cam):
        if not identity(p):
            return None
        fx, fy = _focal(p)
        h = pixel_centre_offset(frame)
        return _Terms(fx=fx, fy=fy, cx=p["cx"] - h, cy=p["cy"] - h)

    return terms


def _custom_pinhole_params(identity_params: Mapping[str, float], single_f: bool, frame: str):
    def params(t: _Terms, cam, name, lenient=False):
        lost: list[str] = []
        _pinhole_from(t, lost)
        if t.skew != 0:
            lost.append("skew")
        h = pixel_centre_offset(frame)
        out = dict(identity_params)
        if single_f:
            if abs(t.fx - t.fy) > 1e-12 * abs(t.fy):
                lost.append("fx != fy")
            out["f"] = 0.5 * (t.fx + t.fy)
        else:
            out["fx"], out["fy"] = t.fx, t.fy
        out["cx"], out["cy"] = t.cx + h, t.cy + h
        if lost and not lenient:
            raise NotRepresentable(f"{name} cannot hold: {', '.join(lost)}", lost)
        return out

    return params


def _australis_terms(p, cam):
    if any(p[n] != 0 for n in ("K1", "K2", "K3", "P1", "P2")):
        return None
    px, py = cam.pixel_size_mm
    c, b1, b2 = p["c"], p["b1"], p["b2"]
    # u = cu + (xp + x̄)/px with x̄ = c (X/Z + b2 Y/Z)/(1 + b1), ȳ = −c Y/Z
    c0u, c0v = image_centre(cam.width, cam.height, "opencv")
    fx = c / ((1 + b1) * px)
    return _Terms(fx=fx, fy=c / py, cx=c0u + p["xp"] / px, cy=c0v - p["yp"] / py, skew=fx * b2)


def _australis_params(t: _Terms, cam, name, lenient=False):
    lost: list[str] = []
    _pinhole_from(t, lost)
    if lost and not lenient:
        raise NotRepresentable(f"{name} cannot hold: {', '.join(lost)}", lost)
    px, py = cam.pixel_size_mm
    c = t.fy * py
    b1 = c / (t.fx * px) - 1.0
    c0u, c0v = image_centre(cam.width, cam.height, "opencv")
    return {
        "c": c,
        "xp": (t.cx - c0u) * px,
        "yp": -(t.cy - c0v) * py,
        "K1": 0.0,
        "K2": 0.0,
        "K3": 0.0,
        "P1": 0.0,
        "P2": 0.0,
        "b1": b1,
        "b2": t.skew / t.fx,
    }


# ---- the registry -------------------------------------------------------------------------------
@dataclass(frozen=True)
class ModelSpec:
    """What a camera model is: its parameters (in the target's order and names), its native
    image frame (:mod:`distortion.camera.conventions`), its explicit direction ("forward":
    ideal → image in closed form, the inverse by Newton; "inverse": the other way round)."""

    name: str
    target: str
    params: tuple[str, ...]
    frame: str
    explicit: str
    summary: str
    default_free: tuple[str, ...]
    colmap_name: str | None = None
    identity: Mapping[str, float] = field(default_factory=dict, repr=False)
    recipe: _Recipe | None = field(default=None, repr=False)
    explicit_fn: Callable | None = field(default=None, repr=False)
    guess_fn: Callable | None = field(default=None, repr=False)
    terms_fn: Callable | None = field(default=None, repr=False)
    params_fn: Callable | None = field(default=None, repr=False)

    @property
    def projection(self) -> str:
        """ "perspective" or "equidistant" (the fisheye models)."""
        return self.recipe.projection if self.recipe is not None else "perspective"

    def evaluate(self, p: Mapping, a, b, cam: CameraModel):
        """The explicit map of the model on arrays a, b (ideal for "forward", native image for
        "inverse"): (c, d, Jacobian 4-tuple)."""
        if self.recipe is not None:
            return _terms_forward(
                _recipe_terms(self.recipe, self.frame, p, cam),
                a,
                b,
                pixel_centre_offset(self.frame),
            )
        return self.explicit_fn(p, a, b, cam)

    def guess(self, p: Mapping, a, b, cam: CameraModel):
        """Starting point for Newton on the non-explicit direction."""
        if self.recipe is not None:
            return _terms_guess(
                _recipe_terms(self.recipe, self.frame, p, cam),
                a,
                b,
                pixel_centre_offset(self.frame),
            )
        return self.guess_fn(p, a, b, cam)

    def terms(self, p: Mapping, cam: CameraModel) -> _Terms | None:
        """The model in the canonical polynomial form, or None where it has no such form."""
        if self.recipe is not None:
            return _recipe_terms(self.recipe, self.frame, p, cam)
        return self.terms_fn(p, cam) if self.terms_fn else None

    def from_terms(self, t: _Terms, cam: CameraModel, lenient: bool = False) -> dict:
        """Parameters that reproduce the canonical terms exactly (raises NotRepresentable);
        ``lenient=True`` drops what the model cannot hold instead (a refit's start)."""
        if self.recipe is not None:
            return _recipe_params(self.recipe, self.frame, t, cam, self.name, lenient)
        if self.params_fn is None:
            raise NotRepresentable(f"{self.name} has no exact polynomial form", [self.name])
        return self.params_fn(t, cam, self.name, lenient)


_SPECS: dict[str, ModelSpec] = {}


def _register(spec: ModelSpec) -> None:
    _SPECS[spec.name] = spec


_OPENCV_PARAMS = (
    "fx",
    "fy",
    "cx",
    "cy",
    "k1",
    "k2",
    "p1",
    "p2",
    "k3",
    "k4",
    "k5",
    "k6",
    "s1",
    "s2",
    "s3",
    "s4",
    "tau_x",
    "tau_y",
)
_register(
    ModelSpec(
        "opencv",
        "opencv",
        _OPENCV_PARAMS,
        "opencv",
        "forward",
        "OpenCV standard: k1..k6 rational, p1 p2, thin prism s1..s4, tilt tau_x tau_y (radians)",
        ("fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2", "k3"),
        recipe=_Recipe(
            "fxfy",
            num=("k1", "k2", "k3"),
            den=("k4", "k5", "k6"),
            p=("p1", "p2"),
            s=("s1", "s2", "s3", "s4"),
            tau=("tau_x", "tau_y"),
        ),
    )
)
_register(
    ModelSpec(
        "opencv_fisheye",
        "opencv",
        ("fx", "fy", "cx", "cy", "alpha", "k1", "k2", "k3", "k4"),
        "opencv",
        "forward",
        "OpenCV fisheye (Kannala-Brandt): theta_d = theta (1 + k1 theta^2 ...)",
        ("fx", "fy", "cx", "cy", "k1", "k2", "k3", "k4"),
        recipe=_Recipe("fxfy", "equidistant", num=("k1", "k2", "k3", "k4"), alpha="alpha"),
    )
)

_COLMAP_RECIPES = {
    "SIMPLE_PINHOLE": (("f", "cx", "cy"), _Recipe("f")),
    "PINHOLE": (("fx", "fy", "cx", "cy"), _Recipe("fxfy")),
    "SIMPLE_RADIAL": (("f", "cx", "cy", "k"), _Recipe("f", num=("k",))),
    "RADIAL": (("f", "cx", "cy", "k1", "k2"), _Recipe("f", num=("k1", "k2"))),
    "OPENCV": (
        ("fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2"),
        _Recipe("fxfy", num=("k1", "k2"), p=("p1", "p2")),
    ),
    "FULL_OPENCV": (
        ("fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2", "k3", "k4", "k5", "k6"),
        _Recipe("fxfy", num=("k1", "k2", "k3"), den=("k4", "k5", "k6"), p=("p1", "p2")),
    ),
    "OPENCV_FISHEYE": (
        ("fx", "fy", "cx", "cy", "k1", "k2", "k3", "k4"),
        _Recipe("fxfy", "equidistant", num=("k1", "k2", "k3", "k4")),
    ),
    "SIMPLE_RADIAL_FISHEYE": (("f", "cx", "cy", "k"), _Recipe("f", "equidistant", num=("k",))),
    "RADIAL_FISHEYE": (
        ("f", "cx", "cy", "k1", "k2"),
        _Recipe("f", "equidistant", num=("k1", "k2")),
    ),
    "THIN_PRISM_FISHEYE": (
        ("fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2", "k3", "k4", "sx1", "sy1"),
        _Recipe(
            "fxfy",
            "equidistant",
            num=("k1", "k2", "k3", "k4"),
            p=("p1", "p2"),
            s=("sx1", None, "sy1", None),
        ),
    ),
    "SIMPLE_FISHEYE": (("f", "cx", "cy"), _Recipe("f", "equidistant")),
    "FISHEYE": (("fx", "fy", "cx", "cy"), _Recipe("fxfy", "equidistant")),
    "RAD_TAN_THIN_PRISM_FISHEYE": (
        (
            "fx",
            "fy",
            "cx",
            "cy",
            "k0",
            "k1",
            "k2",
            "k3",
            "k4",
            "k5",
            "p0",
            "p1",
            "s0",
            "s1",
            "s2",
            "s3",
        ),
        _Recipe(
            "fxfy",
            "equidistant",
            num=("k0", "k1", "k2", "k3", "k4", "k5"),
            p=("p1", "p0"),
            s=("s0", "s1", "s2", "s3"),
            split=True,
        ),
    ),
}
for _cname, (_params, _rc) in _COLMAP_RECIPES.items():
    _register(
        ModelSpec(
            f"colmap:{_cname}",
            "colmap",
            _params,
            "colmap",
            "forward",
            f"COLMAP {_cname}",
            _params,
            colmap_name=_cname,
            recipe=_rc,
        )
    )
for _cname, _params in (
    ("SIMPLE_DIVISION", ("f", "cx", "cy", "k")),
    ("DIVISION", ("fx", "fy", "cx", "cy", "k")),
):
    _register(
        ModelSpec(
            f"colmap:{_cname}",
            "colmap",
            _params,
            "colmap",
            "inverse",
            f"COLMAP {_cname}: undistorted = distorted / (1 + k r_d^2)",
            _params,
            colmap_name=_cname,
            identity={"k": 0.0},
            explicit_fn=_division_inverse,
            guess_fn=_division_guess,
            terms_fn=_custom_pinhole_terms(lambda p: p["k"] == 0, "colmap"),
            params_fn=_custom_pinhole_params({"k": 0.0}, _cname == "SIMPLE_DIVISION", "colmap"),
        )
    )
_register(
    ModelSpec(
        "colmap:FOV",
        "colmap",
        ("fx", "fy", "cx", "cy", "omega"),
        "colmap",
        "forward",
        "COLMAP FOV (Devernay-Faugeras field of view)",
        ("fx", "fy", "cx", "cy", "omega"),
        colmap_name="FOV",
        identity={"omega": 0.0},
        explicit_fn=_fov_forward,
        guess_fn=_pinhole_guess,
        terms_fn=_custom_pinhole_terms(lambda p: p["omega"] == 0, "colmap"),
        params_fn=_custom_pinhole_params({"omega": 0.0}, False, "colmap"),
    )
)
_register(
    ModelSpec(
        "colmap:EUCM",
        "colmap",
        ("fx", "fy", "cx", "cy", "alpha", "beta"),
        "colmap",
        "forward",
        "COLMAP EUCM (enhanced unified camera model)",
        ("fx", "fy", "cx", "cy", "alpha", "beta"),
        colmap_name="EUCM",
        identity={"alpha": 0.0, "beta": 1.0},
        explicit_fn=_eucm_forward,
        guess_fn=_pinhole_guess,
        terms_fn=_custom_pinhole_terms(lambda p: p["alpha"] == 0, "colmap"),
        params_fn=_custom_pinhole_params({"alpha": 0.0, "beta": 1.0}, False, "colmap"),
    )
)
_register(
    ModelSpec(
        "metashape",
        "metashape",
        ("f", "cx", "cy", "b1", "b2", "k1", "k2", "k3", "k4", "p1", "p2", "p3", "p4"),
        "metashape",
        "forward",
        "Agisoft Metashape frame camera: f, cx cy from the centre, b1 b2, k1..k4, P1..P4 "
        "(P1 = OpenCV p2)",
        ("f", "cx", "cy", "k1", "k2", "k3", "p1", "p2"),
        recipe=_Recipe("metashape", num=("k1", "k2", "k3", "k4"), p=("p2", "p1"), q=("p3", "p4")),
    )
)
_register(
    ModelSpec(
        "australis",
        "australis",
        ("c", "xp", "yp", "K1", "K2", "K3", "P1", "P2", "b1", "b2"),
        "photo_mm",
        "inverse",
        "Brown/Fraser 10-parameter model (Australis): mm, y up, correction measured -> ideal",
        ("c", "xp", "yp", "K1", "K2", "K3", "P1", "P2"),
        explicit_fn=_australis_inverse,
        guess_fn=_australis_guess,
        terms_fn=_australis_terms,
        params_fn=_australis_params,
    )
)

#: every model name
MODEL_NAMES: tuple[str, ...] = tuple(_SPECS)
_ALIASES = {
    "fisheye": "opencv_fisheye",
    "kannala_brandt": "opencv_fisheye",
    "brown": "australis",
    "fraser": "australis",
    "photoscan": "metashape",
}

#: OpenCV coefficient vectors by length (the orders cv2 accepts)
OPENCV_ORDERS: dict[int, tuple[str, ...]] = {
    4: ("k1", "k2", "p1", "p2"),
    5: ("k1", "k2", "p1", "p2", "k3"),
    8: ("k1", "k2", "p1", "p2", "k3", "k4", "k5", "k6"),
    12: ("k1", "k2", "p1", "p2", "k3", "k4", "k5", "k6", "s1", "s2", "s3", "s4"),
    14: ("k1", "k2", "p1", "p2", "k3", "k4", "k5", "k6", "s1", "s2", "s3", "s4", "tau_x", "tau_y"),
}


def model_name(name: str) -> str:
    """The registry name of a model (case and aliases resolved: ``"colmap:full_opencv"`` →
    ``"colmap:FULL_OPENCV"``, ``"fisheye"`` → ``"opencv_fisheye"``); DataError if unknown."""
    if not isinstance(name, str):
        raise DataError(f"camera model name must be a string, got {name!r}")
    key = name.strip()
    low = key.lower()
    if low.startswith("colmap:"):
        key = "colmap:" + key.split(":", 1)[1].strip().upper()
    else:
        key = _ALIASES.get(low, low)
    if key in _SPECS:
        return key
    near = difflib.get_close_matches(key, MODEL_NAMES, n=3)
    hint = f"; did you mean {', '.join(near)}?" if near else ""
    raise DataError(f"unknown camera model {name!r}{hint} (models: {', '.join(MODEL_NAMES)})")


def model_spec(name: str) -> ModelSpec:
    """The :class:`ModelSpec` of a model name."""
    return _SPECS[model_name(name)]


# ---- the camera model object --------------------------------------------------------------------
@dataclass(frozen=True)
class CameraModel:
    """One calibrated camera: a model, its parameters and the image it belongs to.

    Attributes
    ----------
    model:
        Registry name (:data:`MODEL_NAMES`): ``"opencv"``, ``"opencv_fisheye"``,
        ``"colmap:FULL_OPENCV"``, ``"metashape"``, ``"australis"``, …
    params:
        Values in the order of ``spec.params``, in the target's units and conventions.
    width, height:
        Image size in pixels.
    pixel_size_mm:
        (pitch_x, pitch_y) in mm: needed by models in mm (``australis``) and to relate pixels to
        a sensor; optional otherwise. Checked by
        :func:`~distortion.camera.sensor.check_pixel_size_mm` (0.0003..1 mm; above 0.1 mm the
        sensor it makes with the image size must stay within 1000 mm).
    """

    model: str
    params: tuple[float, ...]
    width: int
    height: int
    pixel_size_mm: tuple[float, float] | None = None

    def __post_init__(self) -> None:
        name = model_name(self.model)
        object.__setattr__(self, "model", name)
        spec = _SPECS[name]
        if isinstance(self.params, Mapping):
            vals = _params_from_mapping(spec, self.params, require_all=True)
        else:
            vals = tuple(float(v) for v in self.params)
        if len(vals) != len(spec.params):
            raise DataError(
                f"camera model {name} takes {len(spec.params)} parameters "
                f"({', '.join(spec.params)}), got {len(vals)}"
            )
        bad = [n for n, v in zip(spec.params, vals, strict=True) if not math.isfinite(v)]
        if bad:
            raise DataError(f"camera model {name}: parameters {', '.join(bad)} are not finite")
        object.__setattr__(self, "params", vals)
        for n in ("width", "height"):
            v = getattr(self, n)
            if isinstance(v, bool) or not float(v) == int(v) or int(v) < 1:
                raise DataError(f"camera model {name}: image {n} must be a positive integer")
            object.__setattr__(self, n, int(v))
        if self.pixel_size_mm is not None:
            ps = check_pixel_size_mm(
                self.pixel_size_mm, f"camera model {name}: ", (self.width, self.height)
            )
            object.__setattr__(self, "pixel_size_mm", ps)
        elif spec.frame == "photo_mm":
            raise DataError(
                f"camera model {name} works in mm: give pixel_size_mm=(pitch_x, pitch_y) in mm "
                "(or build it with camera_from_sensor)"
            )
        focal = [n for n in ("f", "fx", "fy", "c") if n in spec.params]
        for n in focal:
            if not vals[spec.params.index(n)] > 0:
                raise DataError(f"camera model {name}: {n} must be positive")

    @classmethod
    def create(
        cls,
        model: str,
        width: int,
        height: int,
        *,
        pixel_size_mm: tuple[float, float] | None = None,
        **params: float,
    ) -> CameraModel:
        """A camera from keyword parameters; coefficients left out are zero (the model's
        identity: e.g. EUCM beta = 1). Focal lengths and principal points are required."""
        spec = model_spec(model)
        return cls(spec.name, _params_from_mapping(spec, params), width, height, pixel_size_mm)

    @property
    def spec(self) -> ModelSpec:
        return _SPECS[self.model]

    def as_dict(self) -> dict[str, float]:
        return dict(zip(self.spec.params, self.params, strict=True))

    def __getitem__(self, name: str) -> float:
        try:
            return self.params[self.spec.params.index(name)]
        except ValueError:
            raise KeyError(f"{self.model} has no parameter {name!r}") from None

    def replace(self, **params: float) -> CameraModel:
        """A copy with some parameters changed."""
        d = self.as_dict()
        for k in params:
            if k not in d:
                raise DataError(_unknown_param(self.spec, k))
        d.update({k: float(v) for k, v in params.items()})
        return CameraModel(
            self.model,
            tuple(d[n] for n in self.spec.params),
            self.width,
            self.height,
            self.pixel_size_mm,
        )

    @property
    def n_opencv_coefficients(self) -> int:
        """Shortest OpenCV vector length (4, 5, 8, 12, 14) holding every nonzero coefficient
        (``opencv`` models only)."""
        if self.model != "opencv":
            raise DataError(f"{self.model} is not an OpenCV standard model")
        d = self.as_dict()
        for n, names in OPENCV_ORDERS.items():
            if all(d[k] == 0 for k in OPENCV_ORDERS[14] if k not in names):
                return n
        return 14

    def project(self, ideal, *, pixels: str = "native") -> MappedPoints:
        """:func:`project` with this camera."""
        return project(self, ideal, pixels=pixels)

    def unproject(self, image, *, pixels: str = "native") -> MappedPoints:
        """:func:`unproject` with this camera."""
        return unproject(self, image, pixels=pixels)

    def __repr__(self) -> str:
        d = self.as_dict()
        shown = ", ".join(
            f"{k}={v:.6g}"
            for k, v in d.items()
            if v != 0 or k in ("f", "fx", "fy", "cx", "cy", "c", "xp", "yp")
        )
        return f"CameraModel({self.model}, {self.width}x{self.height} px, {shown})"


def _unknown_param(spec: ModelSpec, name: str) -> str:
    near = difflib.get_close_matches(name, spec.params, n=2)
    hint = f"; did you mean {', '.join(near)}?" if near else ""
    return f"camera model {spec.name} has no parameter {name!r}{hint} ({', '.join(spec.params)})"


def _params_from_mapping(spec: ModelSpec, values: Mapping, require_all: bool = False):
    for k in values:
        if k not in spec.params:
            raise DataError(_unknown_param(spec, k))
    required = [n for n in spec.params if n in ("f", "fx", "fy", "cx", "cy", "c")]
    missing = [n for n in (spec.params if require_all else required) if n not in values]
    if missing:
        raise DataError(f"camera model {spec.name}: give {', '.join(missing)}")
    defaults = {**{n: 0.0 for n in spec.params}, **spec.identity}
    return tuple(float(values.get(n, defaults[n])) for n in spec.params)


def pinhole_camera(
    model: str,
    width: int,
    height: int,
    fx: float,
    fy: float,
    cx: float,
    cy: float,
    *,
    pixel_size_mm: tuple[float, float] | None = None,
) -> CameraModel:
    """A camera of ``model`` without distortion (every coefficient at its identity) whose
    undistorted projection has focal lengths fx, fy (px) and principal point cx, cy in OpenCV
    pixels — in the model's projection (perspective, or equidistant for fisheye models). A
    model with a single f takes the mean of fx and fy."""
    spec = model_spec(model)
    size = _SizeOnly(int(width), int(height), pixel_size_mm)
    if spec.frame == "photo_mm" and pixel_size_mm is None:
        raise DataError(f"{spec.name} works in mm: give pixel_size_mm=(pitch_x, pitch_y) in mm")
    t = _Terms(fx=float(fx), fy=float(fy), cx=float(cx), cy=float(cy), projection=spec.projection)
    try:
        params = spec.from_terms(t, size)
    except NotRepresentable:
        f = 0.5 * (float(fx) + float(fy))
        params = spec.from_terms(
            _Terms(fx=f, fy=f, cx=t.cx, cy=t.cy, projection=t.projection), size
        )
    return CameraModel.create(spec.name, width, height, pixel_size_mm=pixel_size_mm, **params)


def focal_lengths_px(camera: CameraModel) -> tuple[float, float]:
    """(fx, fy) in pixels of the camera's undistorted projection (Metashape: f + b1, f;
    Australis: c / pitch)."""
    p = camera.as_dict()
    if "c" in p:
        return p["c"] / camera.pixel_size_mm[0], p["c"] / camera.pixel_size_mm[1]
    if camera.model == "metashape":
        return p["f"] + p["b1"], p["f"]
    return _focal(p)


def camera_from_sensor(
    model: str, sensor: Sensor, principal_distance_mm: float, **coefficients: float
) -> CameraModel:
    """A camera of ``model`` for a sensor and a principal distance (mm): focal lengths
    c / pitch, principal point from the sensor's offset, the given coefficients, others at
    their identity.

    Parameters
    ----------
    model : str
        A camera model name (:data:`MODEL_NAMES`: ``"opencv"``, ``"opencv_fisheye"``,
        ``"colmap:OPENCV"``, ``"metashape"``, ``"australis"``, …).
    sensor : Sensor
        Gives the image size (pixels), the pixel pitch and the principal-point offset.
    principal_distance_mm : float
        c in mm (positive, finite): fx = c / pitch_x and fy = c / pitch_y in pixels.
    **coefficients : float
        Model parameters by name (e.g. ``k1=-0.05``), in the model's own units and conventions.

    Returns
    -------
    CameraModel

    Raises
    ------
    DataError
        A principal distance that is not positive and finite, or in metres (a field angle at
        the sensor's farthest corner above 87°:
        :func:`~distortion.camera.sensor.check_principal_distance_mm`), an unknown model, a
        parameter the model does not have.

    Warns
    -----
    UnitWarning
        A principal distance that may be in µm (a field angle at the sensor's farthest corner
        below 0.057°; a telescope can have one): it is taken in mm.
    """
    dx, dy = sensor.principal_point_offset_mm
    largest = math.hypot(sensor.width_mm / 2.0 + abs(dx), sensor.height_mm / 2.0 + abs(dy))
    c = check_principal_distance_mm(
        principal_distance_mm, largest, f"principal_distance_mm={principal_distance_mm!r}:"
    )
    px, py = sensor.pixel_size_mm
    cu, cv = sensor.principal_point("opencv")
    cam = pinhole_camera(
        model,
        sensor.width_px,
        sensor.height_px,
        c / px,
        c / py,
        cu,
        cv,
        pixel_size_mm=sensor.pixel_size_mm,
    )
    return cam.replace(**coefficients) if coefficients else cam


class _SizeOnly:
    """What ``ModelSpec.from_terms`` needs of a camera: its size and pixel size."""

    def __init__(self, width, height, pixel_size_mm):
        self.width, self.height, self.pixel_size_mm = width, height, pixel_size_mm


# ---- points in, points out ---------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class MappedPoints:
    """Points mapped by a camera model.

    ``points`` (N, 2): image points in ``frame`` (a pixel convention, or ``"photo_mm"``), or
    ideal normalised coordinates (``frame="ideal"``); NaN where ``status`` is not OK.
    ``status`` (N,): codes of :data:`STATUS_NAMES`. ``residual_px`` (N,): the image-space error
    estimate of the Newton solution in pixels (0 for the explicit direction).
    ``iterations``: Newton iterations used (0 for the explicit direction).
    """

    points: np.ndarray
    status: np.ndarray
    residual_px: np.ndarray
    frame: str
    iterations: int = 0

    @property
    def ok(self) -> np.ndarray:
        return self.status == OK

    def __repr__(self) -> str:
        n = self.status.size
        bad = int(np.count_nonzero(self.status != OK))
        res = float(np.max(self.residual_px[self.ok])) if n - bad else float("nan")
        return f"MappedPoints({n} points in {self.frame}, {bad} not ok, max residual {res:.3g} px)"


def _as_ideal(ideal) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    a = np.asarray(ideal, dtype=float)
    if a.ndim == 1:
        a = a[None, :]
    if a.ndim != 2 or a.shape[1] not in (2, 3):
        raise DataError(
            "ideal points must be an (N, 2) array of X/Z, Y/Z or an (N, 3) array of directions"
        )
    if a.shape[1] == 3:
        z = a[:, 2]
        bad = ~(z > 0)
        zs = np.where(bad, 1.0, z)
        x, y = a[:, 0] / zs, a[:, 1] / zs
        return x, y, bad
    return a[:, 0].copy(), a[:, 1].copy(), np.zeros(a.shape[0], bool)


def _as_image(image) -> np.ndarray:
    a = np.asarray(image, dtype=float)
    if a.ndim == 1:
        a = a[None, :]
    if a.ndim != 2 or a.shape[1] != 2:
        raise DataError("image points must be an (N, 2) array")
    return a


def native_to_frame(cam: CameraModel, pts: np.ndarray, frame: str) -> np.ndarray:
    """Native image points of ``cam`` → ``frame`` ("native", a pixel convention, "photo_mm")."""
    native = cam.spec.frame
    if frame in ("native", native):
        return pts
    if native == "photo_mm":
        cv = photo_mm_to_opencv_pixels(pts, cam.width, cam.height, cam.pixel_size_mm)
    else:
        cv = pts - pixel_centre_offset(native)
    if frame == "photo_mm":
        if cam.pixel_size_mm is None:
            raise DataError(f"{cam.model}: photo_mm needs the camera's pixel_size_mm")
        return opencv_pixels_to_photo_mm(cv, cam.width, cam.height, cam.pixel_size_mm)
    return cv + pixel_centre_offset(frame)


def frame_to_native(cam: CameraModel, pts: np.ndarray, frame: str) -> np.ndarray:
    """Inverse of :func:`native_to_frame`."""
    native = cam.spec.frame
    if frame in ("native", native):
        return pts
    if frame == "photo_mm":
        if cam.pixel_size_mm is None:
            raise DataError(f"{cam.model}: photo_mm needs the camera's pixel_size_mm")
        cv = photo_mm_to_opencv_pixels(pts, cam.width, cam.height, cam.pixel_size_mm)
    else:
        cv = pts - pixel_centre_offset(frame)
    if native == "photo_mm":
        return opencv_pixels_to_photo_mm(cv, cam.width, cam.height, cam.pixel_size_mm)
    return cv + pixel_centre_offset(native)


def _native_px_scale(cam: CameraModel) -> tuple[float, float]:
    """Pixels per native image unit (1 for pixel frames; 1/pitch for mm)."""
    if cam.spec.frame == "photo_mm":
        return 1.0 / cam.pixel_size_mm[0], 1.0 / cam.pixel_size_mm[1]
    return 1.0, 1.0


def _solve(cam, fn, target_a, target_b, p_a, p_b, image_side: str, tol_px: float, max_iter: int):
    """Newton: find p with fn(p) = target. ``image_side`` "residual" when the residual is in
    native image units (unknown = ideal), "step" when the unknown is the image point. The value
    and Jacobian of an accepted trial step are kept for the next iteration (one evaluation of
    the model per iteration when no backtracking is needed)."""
    n = target_a.size
    sx, sy = _native_px_scale(cam)
    status = np.full(n, NOT_CONVERGED, dtype=np.int8)
    resid = np.full(n, np.inf)
    pa, pb = p_a.astype(float).copy(), p_b.astype(float).copy()
    active = np.isfinite(target_a) & np.isfinite(target_b) & np.isfinite(pa) & np.isfinite(pb)
    status[~active] = INVALID
    # rounding floor of the image coordinates, in pixels
    if image_side == "residual":
        mag = np.maximum(np.abs(target_a) * sx, np.abs(target_b) * sy)
    else:
        mag = np.full(n, float(max(cam.width, cam.height)))
    floor = np.maximum(tol_px, ROUNDING_ULPS * _EPS * np.maximum(mag, 1.0))
    val = np.full((2, n), np.nan)  # model value at p
    jac = np.full((4, n), np.nan)  # its Jacobian
    fresh = np.zeros(n, bool)  # val/jac belong to the current p

    def evaluate(sel):
        a, b, j = fn(pa[sel], pb[sel])
        val[0, sel], val[1, sel] = a, b
        for c in range(4):
            jac[c, sel] = np.broadcast_to(j[c], np.shape(a))
        fresh[sel] = True

    used = 0
    for it in range(max_iter + 1):
        idx = np.nonzero(active)[0]
        if idx.size == 0:
            break
        used = it
        stale = idx[~fresh[idx]]
        if stale.size:
            evaluate(stale)
        ra, rb = val[0, idx] - target_a[idx], val[1, idx] - target_b[idx]
        j = jac[:, idx]
        det = j[0] * j[3] - j[1] * j[2]
        bad = ~(np.isfinite(ra) & np.isfinite(rb) & np.isfinite(det))
        sing = ~bad & (np.abs(det) <= 1e-300)
        with np.errstate(divide="ignore", invalid="ignore"):
            da = (j[3] * ra - j[1] * rb) / det
            db = (-j[2] * ra + j[0] * rb) / det
        if image_side == "residual":
            err = np.hypot(ra * sx, rb * sy)
        else:
            err = np.hypot(da * sx, db * sy)
        done = ~bad & ~sing & (err <= floor[idx])
        resid[idx] = np.where(bad, np.inf, err)
        status[idx[bad]] = INVALID
        status[idx[sing]] = SINGULAR
        status[idx[done]] = OK
        active[idx[bad | sing | done]] = False
        if it == max_iter:
            break
        go = ~(bad | sing | done)
        if not np.any(go):
            break
        gi = idx[go]
        merit = ra[go] ** 2 + rb[go] ** 2
        step_a, step_b = da[go], db[go]
        lam = np.ones(gi.size)
        pending = np.ones(gi.size, bool)
        for _ in range(30):
            k = np.nonzero(pending)[0]
            ta, tb = pa[gi[k]] - lam[k] * step_a[k], pb[gi[k]] - lam[k] * step_b[k]
            na, nb, nj = fn(ta, tb)
            nm = (na - target_a[gi[k]]) ** 2 + (nb - target_b[gi[k]]) ** 2
            accept = np.isfinite(nm) & (nm < merit[k])
            acc = gi[k[accept]]
            pa[acc], pb[acc] = ta[accept], tb[accept]
            val[0, acc], val[1, acc] = na[accept], nb[accept]
            for c in range(4):
                jac[c, acc] = np.broadcast_to(nj[c], na.shape)[accept]
            fresh[acc] = True
            pending[k[accept]] = False
            lam[k[~accept]] *= 0.5
            if not np.any(pending):
                break
        # no descent at all: we are at the rounding floor or stuck; take the full step once
        k = np.nonzero(pending)[0]
        pa[gi[k]] -= step_a[k]
        pb[gi[k]] -= step_b[k]
        fresh[gi[k]] = False
    # a solution on a branch where the map has folded back is not the inverse: relative to the
    # Jacobian at the centre, M = J_centre⁻¹ J must keep both eigenvalues in the right half
    # plane (det M > 0 and trace M > 0); a mirrored far branch fails the trace
    ok = np.nonzero(status == OK)[0]
    if ok.size:
        r = [float(np.real(np.ravel(v)[0])) for v in fn(*_centre_point(cam, fn))[2]]
        rdet = r[0] * r[3] - r[1] * r[2]
        inv = (r[3] / rdet, -r[1] / rdet, -r[2] / rdet, r[0] / rdet)
        m = _mul(inv, tuple(jac[:, ok]))
        mdet = m[0] * m[3] - m[1] * m[2]
        folded = ~((mdet > 0) & (m[0] + m[3] > 0))
        status[ok[folded]] = FOLDED
    out_a = np.where(status == OK, pa, np.nan)
    out_b = np.where(status == OK, pb, np.nan)
    return out_a, out_b, status, np.where(status == OK, resid, np.nan), used


def _centre_point(cam, fn):
    """The point of the unknown's domain where the orientation of the map is taken."""
    spec = cam.spec
    p = cam.as_dict()
    if spec.explicit == "forward":
        return np.zeros(1), np.zeros(1)  # unknown is ideal: the axis
    a, b = spec.guess(p, np.zeros(1), np.zeros(1), cam)
    return np.atleast_1d(a), np.atleast_1d(b)


def _explicit(camera: CameraModel, a: np.ndarray, b: np.ndarray, invalid=None):
    """The model's explicit direction at (a, b): (N, 2) points, status OK / INVALID (INVALID
    where a value is not finite or ``invalid``; those points NaN) and residual (0 / NaN)."""
    with np.errstate(all="ignore"):
        u, v, _j = camera.spec.evaluate(camera.as_dict(), a, b, camera)
    good = np.isfinite(u) & np.isfinite(v)
    if invalid is not None:
        good &= ~invalid
    status = np.where(good, OK, INVALID).astype(np.int8)
    pts = np.stack([np.where(status == OK, u, np.nan), np.where(status == OK, v, np.nan)], 1)
    return pts, status, np.where(status == OK, 0.0, np.nan)


def _newton(camera: CameraModel, a, b, ga, gb, image_side: str, tol_px: float, max_iter: int):
    """The direction opposite to the explicit one: :func:`_solve` for target (a, b) from the
    guess (ga, gb)."""
    spec = camera.spec
    p = camera.as_dict()
    with np.errstate(all="ignore"):
        return _solve(
            camera,
            lambda s, t: spec.evaluate(p, s, t, camera),
            a,
            b,
            np.asarray(ga, float),
            np.asarray(gb, float),
            image_side,
            tol_px,
            max_iter,
        )


def project(
    camera: CameraModel,
    ideal,
    *,
    pixels: str = "native",
    tol_px: float = TOL_PX,
    max_iter: int = MAX_ITER,
) -> MappedPoints:
    """Ideal directions → image points (the *forward* map: ideal → distorted).

    Parameters
    ----------
    camera:
        The camera model.
    ideal:
        (N, 2) normalised coordinates X/Z, Y/Z (x right, y down), or (N, 3) directions with
        Z > 0 (others get status INVALID).
    pixels:
        Frame of the result: ``"native"`` (the model's own: OpenCV pixels, COLMAP/Metashape
        pixels, or photogrammetric mm for ``australis``), or ``"opencv"``, ``"colmap"``,
        ``"metashape"``, ``"photo_mm"``.

    Returns
    -------
    MappedPoints
        Image points with a status per point; for models whose explicit direction is the
        inverse (``australis``, COLMAP division) the points come from Newton's method.
    """
    spec = camera.spec
    p = camera.as_dict()
    x, y, behind = _as_ideal(ideal)
    if spec.explicit == "forward":
        pts, status, resid = _explicit(camera, x, y, behind)
        it = 0
    else:
        x = np.where(behind, np.nan, x)
        y = np.where(behind, np.nan, y)
        ga, gb = spec.guess(p, x, y, camera)
        u, v, status, resid, it = _newton(camera, x, y, ga, gb, "step", tol_px, max_iter)
        pts = np.stack([u, v], 1)
    frame = spec.frame if pixels == "native" else pixels
    return MappedPoints(native_to_frame(camera, pts, pixels), status, resid, frame, it)


def unproject(
    camera: CameraModel,
    image,
    *,
    pixels: str = "native",
    tol_px: float = TOL_PX,
    max_iter: int = MAX_ITER,
) -> MappedPoints:
    """Image points → ideal normalised coordinates X/Z, Y/Z (the *inverse* map: distorted →
    ideal; ``frame="ideal"``). ``pixels`` names the frame of the input points (as in
    :func:`project`). Newton's method for models whose explicit direction is the forward one."""
    spec = camera.spec
    p = camera.as_dict()
    pts = frame_to_native(camera, _as_image(image), pixels)
    a, b = pts[:, 0], pts[:, 1]
    if spec.explicit == "inverse":
        out, status, resid = _explicit(camera, a, b)
        return MappedPoints(out, status, resid, "ideal", 0)
    with np.errstate(all="ignore"):
        ga, gb = spec.guess(p, a, b, camera)
    x, y, status, resid, it = _newton(camera, a, b, ga, gb, "residual", tol_px, max_iter)
    return MappedPoints(np.stack([x, y], 1), status, resid, "ideal", it)


def project_jacobian(camera: CameraModel, ideal) -> np.ndarray:
    """d(native image point)/d(ideal x, y) at ideal points: (N, 2, 2), analytic (for models
    whose explicit direction is the inverse, the inverse of its Jacobian at the projected
    point; NaN where the projection fails)."""
    spec = camera.spec
    p = camera.as_dict()
    x, y, behind = _as_ideal(ideal)
    if spec.explicit == "forward":
        _u, _v, j = spec.evaluate(p, x, y, camera)
        j = [np.broadcast_to(np.asarray(c, float), x.shape) for c in j]
        out = np.stack([np.stack([j[0], j[1]], -1), np.stack([j[2], j[3]], -1)], -2)
    else:
        m = project(camera, np.stack([x, y], 1))
        _a, _b, j = spec.evaluate(p, m.points[:, 0], m.points[:, 1], camera)
        j = [np.broadcast_to(np.asarray(c, float), x.shape) for c in j]
        fwd = np.stack([np.stack([j[0], j[1]], -1), np.stack([j[2], j[3]], -1)], -2)
        with np.errstate(all="ignore"):
            out = np.linalg.inv(fwd)
    out = out.copy()
    out[behind] = np.nan
    return out
