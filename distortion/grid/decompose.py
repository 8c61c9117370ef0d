"""Decomposition of a 2-D distortion field into radial, decentering and thin-prism parts, with the
camera constant and the principal point fitted together with them (linear least squares with
covariance).

The model (distortion form: ideal → actual image point, mm, lens image frame x right, y up as
seen looking along −z; docs/design.md, "2-D distortion")
    With the normalised ideal coordinates t = (tx, ty) of a field (direction tangents of the
    object-space chief ray, or object coordinates / p0 for a finite object), the ideal image
    coordinates about the principal point are (x, y) = c·t, r² = x² + y², and ::

        x' = x0 + x + x (K1 r² + K2 r⁴ + K3 r⁶) + P1 (r² + 2x²) + 2 P2 x y + S1 r²
        y' = y0 + y + y (K1 r² + K2 r⁴ + K3 r⁶) + 2 P1 x y + P2 (r² + 2y²) + S2 r²

    c: camera constant (mm); (x0, y0): principal point (mm) = the image of t = 0;
    K_i (mm^-2i): radial; P1, P2 (mm^-1): decentering (Brown 1966, *Decentering distortion of
    lenses*, Photogramm. Eng. 32(3); the P1, P2 placement of Fraser 1997, *Digital camera
    self-calibration*, ISPRS J. 52, Eq. 3); S1, S2 (mm^-1): thin prism (Weng, Cohen & Herniou
    1992, *Camera calibration with distortion models and accuracy evaluation*, IEEE PAMI 14(10),
    Eq. 9). Written with a_i = K_i c^(2i+1), q_j = P_j c², σ_j = S_j c² the model is LINEAR in
    (x0, y0, c, a, q, σ); it is solved by least squares (columns scaled to unit norm) and the
    physical parameters and their covariance follow by the delta method.

    Signs and forms: this is *distortion* (actual − ideal, pincushion K1 > 0) evaluated at the
    ideal radius, which is OpenCV's form: exactly, with normalised OpenCV coordinates
    (x_n, y_n) = (tx, −ty) (OpenCV's y points down), k_i = K_i c^2i, p1 = −c P2, p2 = c P1,
    s1 = c S1, s3 = −c S2. The Australis / Fraser model is a *correction* at the measured radius:
    to first order its K_i, P_j are the negatives of these (docs/design.md, "Camera models").

Why decentering and thin prism separate: their radial-to-tangential ratio
    Write a field point at azimuth φ, x = r cos φ, y = r sin φ, and take the radial and
    tangential components δr = δx cos φ + δy sin φ, δt = −δx sin φ + δy cos φ.

    *Decentering* with P2 = 0: δx = P1 (r² + 2 r² cos²φ), δy = 2 P1 r² cos φ sin φ, so
    δr = P1 r² (cos φ + 2 cos³φ + 2 cos φ sin²φ) = 3 P1 r² cos φ and
    δt = P1 r² (−sin φ − 2 cos²φ sin φ + 2 cos²φ sin φ) = −P1 r² sin φ.
    In general, with P1 = J cos ψ, P2 = J sin ψ: δr = 3 J r² cos(φ − ψ), δt = −J r² sin(φ − ψ):
    the radial profile along the decentering axis ψ is THREE times the tangential profile across
    it (Conrady's 3:1; Brown 1966). Brown's φ0, the axis of maximum tangential distortion, is
    ψ − 90°, with P1 = −J sin φ0, P2 = J cos φ0.

    *Thin prism* with S2 = 0: δx = S1 r², δy = 0, so δr = S1 r² cos φ, δt = −S1 r² sin φ: radial
    and tangential profiles are EQUAL (1:1). In general S = (S1, S2) = S (cos χ, sin χ):
    δr = S r² cos(φ − χ), δt = −S r² sin(φ − χ).

    Both are r² fields with the same angular harmonic (cos, sin of φ − axis); only the ratio of
    the radial to the tangential amplitude tells them apart, and two unknowns per axis are
    therefore determined by the two components of the vector field — the least-squares solution
    on any grid that samples several azimuths separates them exactly. A principal-point offset
    has the 1:1 pattern too, but at r⁰, and the camera constant is radial at r¹.

Why the reference must be named
    The split is unique only once the reference directions and point are fixed. (i) A rotation
    of the reference direction by ε about the y axis changes the ideal directions by
    Δt = ε (1 + tx², tx ty) to first order, i.e. the image by c ε (1, 0) + (ε/c)(x², x y), and
    (x², x y) = ½ (r² + 2x², 2 x y) − ½ (r², 0): a principal-point shift Δx0 = c ε together with
    ΔP1 = ε/(2c) and ΔS1 = −ε/(2c). Here the directions are those of the lens frame (its z axis);
    a bundle adjustment that frees the camera's rotation cannot tell these apart. (ii) With the
    directions fixed, the principal point may be fitted (``principal_point="fit"``: the
    calibrated principal point, correlated with P and S — the correlations are reported) or held
    at a named point: the image of the axial object point, the principal point of
    autocollimation (PPA) or of best symmetry (PPBS) (:mod:`distortion.grid.field` defines them).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from ..errors import DataError

#: the principal-point choices: fitted, or held at a named reference point
PRINCIPAL_POINTS = ("fit", "axial", "ppa", "ppbs")
CAMERA_CONSTANTS = ("fit", "characteristic")


def point_pairs(
    t: npt.ArrayLike, image: npt.ArrayLike, image_name: str = "image"
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Correspondences checked for a fit: ideal points ``t`` and image points of the same shape.

    Parameters
    ----------
    t : array_like
        (N, 2) normalised ideal coordinates (tx, ty): direction tangents (dimensionless).
    image : array_like
        (N, 2) image points (mm).
    image_name : str
        What ``image`` is called in the message (the caller's keyword).

    Returns
    -------
    t, image : ndarray
        Both as (N, 2) float arrays, every row kept (dimensionless; mm).
    good : ndarray of bool
        (N,) the rows where both points are finite: the ones a fit uses.

    Raises
    ------
    DataError
        ``t`` and ``image`` are not (N, 2) arrays of the same shape.
    """
    t = np.asarray(t, dtype=float)
    img = np.asarray(image, dtype=float)
    if t.shape != img.shape or t.ndim != 2 or t.shape[1] != 2:
        raise DataError(f"t and {image_name} must be (N, 2) arrays of the same shape")
    good = np.all(np.isfinite(t), axis=1) & np.all(np.isfinite(img), axis=1)
    return t, img, good


def basis_columns(tx: np.ndarray, ty: np.ndarray, radial_terms: int, asymmetric: bool) -> list:
    """The model's basis vector fields, each (x-part, y-part) over the points, in the order
    x0, y0, c, a1.., q1, q2, σ1, σ2 (the last four when ``asymmetric``)."""
    one = np.ones_like(tx)
    zero = np.zeros_like(tx)
    r2 = tx * tx + ty * ty
    cols = [("x0", one, zero), ("y0", zero, one), ("c", tx, ty)]
    p = r2.copy()
    for i in range(1, radial_terms + 1):
        cols.append((f"K{i}", p * tx, p * ty))
        p = p * r2
    if asymmetric:
        cols += [
            ("P1", r2 + 2 * tx * tx, 2 * tx * ty),
            ("P2", 2 * tx * ty, r2 + 2 * ty * ty),
            ("S1", r2, zero),
            ("S2", zero, r2),
        ]
    return cols


@dataclass(frozen=True, eq=False)
class LinearFit:
    """A solved linear distortion model (see the module docstring).

    ``values``: every parameter (physical units: c mm, x0 y0 mm, K_i mm^-2i, P_j S_j mm^-1),
    free or held; ``free``: names of the fitted ones; ``std_errors``: per free parameter
    (s·√diag(cov), s² = RSS / (2N − n): for noise-free traced data it measures the model's
    misfit); ``correlation``: (n, n) of the free physical parameters (from the normal matrix,
    independent of s); ``fitted`` / ``residual``: (N, 2) model and data − model (mm);
    ``parts``: the model's vector fields per group ("offset", "scale", "radial", "decentering",
    "thin_prism"), each (N, 2) mm."""

    values: dict
    free: tuple[str, ...]
    std_errors: dict
    correlation: np.ndarray
    fitted: np.ndarray
    residual: np.ndarray
    parts: dict
    rms_mm: float
    max_mm: float
    condition: float


def solve_linear(
    t: np.ndarray,
    image: np.ndarray,
    *,
    radial_terms: int = 3,
    asymmetric: bool = True,
    principal_point: tuple[float, float] | None = None,
    camera_constant: float | None = None,
) -> LinearFit:
    """Least-squares solution of the module's model for points ``t`` (N, 2) (normalised ideal
    coordinates) and ``image`` (N, 2) (mm). ``principal_point`` / ``camera_constant`` given:
    held at those values; None: fitted. ``asymmetric=False``: radial terms only (no P, S).
    Non-finite points are left out."""
    t, img, good = point_pairs(t, image)
    if radial_terms < 0:
        raise DataError("radial_terms must be 0 or more")
    tx, ty = t[good, 0], t[good, 1]
    bx, by = img[good, 0].copy(), img[good, 1].copy()
    cols = basis_columns(tx, ty, radial_terms, asymmetric)
    held = {}
    if principal_point is not None:
        held["x0"], held["y0"] = (float(v) for v in principal_point)
    if camera_constant is not None:
        held["c"] = float(camera_constant)
    for name, cx, cy in cols:
        if name in held:
            bx -= held[name] * cx
            by -= held[name] * cy
    free_cols = [(n, cx, cy) for n, cx, cy in cols if n not in held]
    names = tuple(n for n, _, _ in free_cols)
    m = 2 * tx.size
    if m < len(names) + 1:
        raise DataError(f"{len(names)} free parameters need more than {len(names) // 2} points")
    A = np.stack([np.concatenate([cx, cy]) for _, cx, cy in free_cols], axis=1)
    b = np.concatenate([bx, by])
    scale = np.linalg.norm(A, axis=0)
    if np.any(scale == 0.0):
        zero = [n for n, s in zip(names, scale, strict=True) if s == 0.0]
        raise DataError(f"the points do not determine {', '.join(zero)} (all zero)")
    As = A / scale
    sol, *_ = np.linalg.lstsq(As, b, rcond=None)
    # one step of iterative refinement against round-off in the normal equations
    sol += np.linalg.lstsq(As, b - As @ sol, rcond=None)[0]
    lin = sol / scale
    sv = np.linalg.svd(As, compute_uv=False)
    cond = float(sv[0] / sv[-1]) if sv[-1] > 0 else math.inf
    inv = np.linalg.pinv(As.T @ As) / np.outer(scale, scale)  # (AᵀA)⁻¹ of the linear params
    lv = dict(held)
    lv.update(zip(names, lin, strict=True))
    c = lv["c"]
    if not (c > 0):
        raise DataError(f"the fitted camera constant {c:g} mm is not positive")
    # physical parameters and the Jacobian G = ∂(physical)/∂(linear) over the free ones
    values = {"c": c, "x0": lv["x0"], "y0": lv["y0"]}
    G = np.eye(len(names))
    idx = {n: i for i, n in enumerate(names)}
    for name in names + tuple(held):
        if name in ("c", "x0", "y0"):
            continue
        if name.startswith("K"):
            p = 2 * int(name[1:]) + 1
        else:  # P, S: q = P c²
            p = 2
        values[name] = lv[name] / c**p
        if name in idx:
            G[idx[name], idx[name]] = 1.0 / c**p
            if "c" in idx:
                G[idx[name], idx["c"]] = -p * lv[name] / c ** (p + 1)
    fitted_x = np.zeros_like(bx) + sum(lv[n] * cx for n, cx, _ in cols)
    fitted_y = np.zeros_like(by) + sum(lv[n] * cy for n, _, cy in cols)
    res = np.column_stack([img[good, 0] - fitted_x, img[good, 1] - fitted_y])
    d = np.hypot(res[:, 0], res[:, 1])
    rss = float(np.sum(d**2))
    dof = m - len(names)
    cov_unit = G @ inv @ G.T
    sd_unit = np.sqrt(np.clip(np.diag(cov_unit), 0.0, None))
    with np.errstate(all="ignore"):
        corr = cov_unit / np.outer(sd_unit, sd_unit)
    corr[~np.isfinite(corr)] = np.nan
    s = math.sqrt(rss / dof) if dof > 0 else math.nan
    se = {n: float(s * sd_unit[i]) for i, n in enumerate(names)}

    def group(keys):
        gx = np.zeros_like(tx)
        gy = np.zeros_like(ty)
        for n, cx, cy in cols:
            if n in keys:
                gx = gx + lv[n] * cx
                gy = gy + lv[n] * cy
        return _scatter(good, np.column_stack([gx, gy]))

    parts = {
        "offset": group(("x0", "y0")),
        "scale": group(("c",)),
        "radial": group(tuple(f"K{i}" for i in range(1, radial_terms + 1))),
        "decentering": group(("P1", "P2")),
        "thin_prism": group(("S1", "S2")),
    }
    return LinearFit(
        values=values,
        free=names,
        std_errors=se,
        correlation=corr,
        fitted=_scatter(good, np.column_stack([fitted_x, fitted_y])),
        residual=_scatter(good, res),
        parts=parts,
        rms_mm=float(np.sqrt(np.mean(d**2))) if d.size else math.nan,
        max_mm=float(np.max(d)) if d.size else math.nan,
        condition=cond,
    )


def _scatter(good: np.ndarray, vals: np.ndarray) -> np.ndarray:
    out = np.full((good.size, 2), np.nan)
    out[good] = vals
    return out


def decentering_profile(P1: float, P2: float) -> tuple[float, float]:
    """(J, ψ): Brown's decentering profile amplitude J = √(P1² + P2²) (mm^-1; the profile is
    J r²) and the axis ψ (degrees, from +x toward +y) along which the radial decentering
    distortion is largest (3 J r²); the tangential one is largest across it (J r²). Brown's φ0
    (axis of maximum tangential distortion) is ψ − 90°."""
    return math.hypot(P1, P2), math.degrees(math.atan2(P2, P1))


@dataclass(frozen=True, eq=False)
class GridDecomposition:
    """A 2-D distortion field split into its parts in one image plane (module docstring).

    Attributes
    ----------
    plane : int
        The plane of the :class:`~distortion.grid.field.DistortionGrid` (0-based).
    principal_point : str
        ``"fit"`` (fitted with the distortion terms) or the named point it was held at.
    camera_constant : str
        ``"fit"`` or ``"characteristic"`` (held at Pestrecov's constant of the plane).
    reference_xy : (float, float)
        The grid's reference point (mm) that ``D`` is measured from.
    values, std_errors : dict
        Parameters (c mm; x0, y0 mm; K_i mm^-2i; P1, P2, S1, S2 mm^-1) and the standard errors
        of the free ones.
    free : tuple of str
        The fitted parameters, in the order of ``correlation``.
    correlation : ndarray
        (n, n) correlations of the free parameters.
    D : ndarray
        (*shape, 2) the grid's distortion vectors (mm) about its reference point with its
        constant.
    components : dict of ndarray
        (*shape, 2) mm each: ``offset`` (principal point − reference point), ``scale``
        ((c − c_grid)·t), ``radial``, ``decentering``, ``thin_prism``, ``residual``; their sum
        is ``D``.
    rms_mm, max_mm : float
        RMS and maximum length of the residual vectors.
    condition : float
        Condition number of the column-scaled design matrix.
    """

    plane: int
    principal_point: str
    camera_constant: str
    reference_xy: tuple[float, float]
    values: dict
    std_errors: dict
    free: tuple[str, ...]
    correlation: np.ndarray
    D: np.ndarray
    components: dict
    rms_mm: float
    max_mm: float
    condition: float

    @property
    def decentering(self) -> tuple[float, float]:
        """(J, ψ) of :func:`decentering_profile`."""
        return decentering_profile(self.values["P1"], self.values["P2"])

    @property
    def thin_prism(self) -> tuple[float, float]:
        """(S, χ): amplitude √(S1² + S2²) (mm^-1; profile S r², radial = tangential) and axis χ
        (degrees from +x toward +y)."""
        s1, s2 = self.values["S1"], self.values["S2"]
        return math.hypot(s1, s2), math.degrees(math.atan2(s2, s1))

    def correlation_of(self, a: str, b: str) -> float:
        return float(self.correlation[self.free.index(a), self.free.index(b)])

    def __repr__(self) -> str:
        v = self.values
        terms = ", ".join(f"{k} = {v[k]:.4g}" for k in ("K1", "P1", "P2", "S1", "S2") if k in v)
        return (
            f"GridDecomposition(plane {self.plane}, principal point {self.principal_point}: "
            f"c = {v['c']:.6f} mm, x0 = {v['x0']:.3g}, y0 = {v['y0']:.3g} mm, {terms}; "
            f"residual RMS {self.rms_mm:.3g} mm)"
        )


def decompose_distortion(
    grid,
    plane: int = 0,
    *,
    principal_point: str = "fit",
    camera_constant: str = "fit",
    radial_terms: int = 3,
) -> GridDecomposition:
    """Split the distortion field of ``grid`` (a :class:`~distortion.grid.field.DistortionGrid`)
    in ``plane`` into offset, scale, radial, decentering and thin-prism parts (module docstring).

    Parameters
    ----------
    grid : DistortionGrid
    plane : int
        0-based image plane of the grid.
    principal_point : {"fit", "axial", "ppa", "ppbs"}
        Fit (x0, y0) together with the terms (the calibrated principal point), or hold it at the
        image of the axial object point, the PPA or the PPBS of that plane.
    camera_constant : {"fit", "characteristic"}
        Fit c, or hold it at Pestrecov's constant of the plane (the grid's ``camera_constant``).
    radial_terms : int
        Number of radial coefficients K1.. (default 3).

    Returns
    -------
    GridDecomposition
    """
    if principal_point not in PRINCIPAL_POINTS:
        raise DataError(
            f"principal_point={principal_point!r}; use one of {', '.join(PRINCIPAL_POINTS)}"
        )
    if camera_constant not in CAMERA_CONSTANTS:
        raise DataError(
            f"camera_constant={camera_constant!r}; use one of {', '.join(CAMERA_CONSTANTS)}"
        )
    if not 0 <= int(plane) < grid.n_planes:
        raise DataError(f"plane={plane}: the grid has {grid.n_planes} image plane(s) (0-based)")
    p = int(plane)
    pp = None if principal_point == "fit" else tuple(grid.named_point(principal_point)[p])
    if pp is not None and not all(math.isfinite(v) for v in pp):
        raise DataError(f"the {principal_point} point of plane {p} could not be traced")
    cc = None if camera_constant == "fit" else float(grid.camera_constant[p])
    t = np.stack([grid.tx.ravel(), grid.ty.ravel()], axis=1)
    img = grid.actual[p].reshape(-1, 2)
    fit = solve_linear(t, img, radial_terms=radial_terms, principal_point=pp, camera_constant=cc)
    shape = grid.shape + (2,)
    D = grid.D[p]
    ref = grid.reference_xy[p]
    c0 = float(grid.camera_constant[p])
    off = np.array([fit.values["x0"] - ref[0], fit.values["y0"] - ref[1]])
    comps = {
        "offset": np.where(np.isfinite(fit.parts["offset"]), off, np.nan).reshape(shape),
        "scale": ((fit.values["c"] - c0) * t).reshape(shape),
        "radial": fit.parts["radial"].reshape(shape),
        "decentering": fit.parts["decentering"].reshape(shape),
        "thin_prism": fit.parts["thin_prism"].reshape(shape),
        "residual": fit.residual.reshape(shape),
    }
    comps["scale"] = np.where(np.isfinite(comps["residual"]), comps["scale"], np.nan)
    return GridDecomposition(
        plane=p,
        principal_point=principal_point,
        camera_constant=camera_constant,
        reference_xy=(float(ref[0]), float(ref[1])),
        values=fit.values,
        std_errors=fit.std_errors,
        free=fit.free,
        correlation=fit.correlation,
        D=D,
        components=comps,
        rms_mm=fit.rms_mm,
        max_mm=fit.max_mm,
        condition=fit.condition,
    )
