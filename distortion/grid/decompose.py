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

from raytrace.units import is_whole

from ..errors import DataError

#: the principal-point choices: fitted, or held at a named reference point
PRINCIPAL_POINTS = ("fit", "axial", "ppa", "ppbs")
CAMERA_CONSTANTS = ("fit", "characteristic")
#: singular values of the column-scaled design matrix below this fraction of the largest count
#: as zero: a parameter combination that weak moves with the float64 round-off of the traced
#: points (~1e-16 relative) by more than 1e-6 of its scale, so the points do not determine it.
#: (Measured on the Cooke triplet: determined grids from 2x9 up give 1/cond >= 5e-4, grids with
#: too few distinct radii ~1e-17: a regression pin of the gap, not a reference value.)
RANK_RCOND = 1e-10
#: relative tolerance (of the largest radius) within which two field radii count as one
RADIUS_RTOL = 1e-9


class UndeterminedFit(DataError):
    """The points cannot determine the model's parameters: fewer distinct field radii than
    radial unknowns, fewer equations than unknowns, or a rank-deficient design matrix. The
    message says which and what to change."""


def distinct_radii(t: npt.ArrayLike) -> int:
    """The number of distinct nonzero radii |t| among the finite rows of ``t`` (N, 2); radii
    within ``RADIUS_RTOL`` of the largest count as one.

    A radial profile r·(c + a1 r² + a2 r⁴ + ...) with k unknowns is sampled only at these
    radii (its values at the points follow from them), so it is determined only when there are
    at least k of them: a 3x3 grid on a square sensor has two (the edge centres and the corners)
    and cannot give c, K1, K2, K3."""
    t = np.asarray(t, dtype=float).reshape(-1, 2)
    r = np.hypot(t[:, 0], t[:, 1])
    r = r[np.isfinite(r)]
    if r.size == 0 or not float(r.max()) > 0:
        return 0
    tol = RADIUS_RTOL * float(r.max())
    r = np.sort(r[r > tol])
    return int(r.size > 0) + int(np.count_nonzero(np.diff(r) > tol))


def radial_shortfall(t: npt.ArrayLike, radial_names: tuple[str, ...]) -> str:
    """Why the points ``t`` cannot determine the radial unknowns ``radial_names`` (the camera
    constant when free, and K1..Kn): too few distinct nonzero radii (:func:`distinct_radii`);
    "" when they can."""
    n = distinct_radii(t)
    if n >= len(radial_names):
        return ""
    return (
        f"the traced fields lie at {n} distinct nonzero field radii, fewer than the "
        f"{len(radial_names)} radial unknowns ({', '.join(radial_names)}) they must determine: "
        "use a grid with more fields (5x5 or more)"
    )


def rank_shortfall(As: np.ndarray, names: tuple[str, ...]) -> str:
    """Why the column-scaled design matrix ``As`` (columns ``names``) does not determine its
    parameters: singular values below ``RANK_RCOND`` of the largest, naming the parameters of
    the undetermined combinations; "" when it has full column rank."""
    if As.shape[0] < As.shape[1]:
        return (
            f"{As.shape[0]} equations for {As.shape[1]} unknowns: use a grid with more fields "
            "(5x5 or more)"
        )
    _, sv, vt = np.linalg.svd(As, full_matrices=False)
    small = ~(sv > RANK_RCOND * sv[0])
    if not small.any():
        return ""
    weight = np.max(np.abs(vt[small]), axis=0)
    involved = [n for n, w in zip(names, weight, strict=True) if w > 0.1]
    return (
        f"the traced fields do not separate {', '.join(involved)} (design matrix rank "
        f"{int(np.count_nonzero(~small))} of {len(names)}): use a grid with more fields "
        "(5x5 or more)"
    )


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


def _check_radial_terms(radial_terms) -> None:
    """DataError unless ``radial_terms`` is a whole number ≥ 0 (an int or numpy integer; not a
    bool, a float such as 2.5 or a string)."""
    if not (is_whole(radial_terms) and radial_terms >= 0):
        why = "" if is_whole(radial_terms) else f" (a whole number), got {radial_terms!r}"
        raise DataError(f"radial_terms must be 0 or more{why}")


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
    Non-finite points are left out.

    Raises
    ------
    UndeterminedFit
        The points do not determine the free parameters: too few points, fewer distinct
        nonzero radii than radial unknowns (:func:`distinct_radii`), or a design matrix of
        lower rank than the free parameters (``RANK_RCOND``). No values are made up then.
    DataError
        Bad shapes, or a fitted camera constant that is not positive."""
    t, img, good = point_pairs(t, image)
    _check_radial_terms(radial_terms)
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
        raise UndeterminedFit(
            f"{len(names)} free parameters need more than {len(names) // 2} traced points, "
            f"there are {tx.size}: use a grid with more fields (5x5 or more)"
        )
    why = radial_shortfall(t[good], tuple(n for n in names if n == "c" or n[0] == "K"))
    if why:
        raise UndeterminedFit(why)
    A = np.stack([np.concatenate([cx, cy]) for _, cx, cy in free_cols], axis=1)
    b = np.concatenate([bx, by])
    scale = np.linalg.norm(A, axis=0)
    if np.any(scale == 0.0):
        zero = [n for n, s in zip(names, scale, strict=True) if s == 0.0]
        raise UndeterminedFit(f"the points do not determine {', '.join(zero)} (all zero)")
    As = A / scale
    why = rank_shortfall(As, names)
    if why:
        raise UndeterminedFit(why)
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
    not_determined : str
        "" for a solved decomposition; else why the grid does not determine it (too few
        distinct field radii or traced points, a rank-deficient design): then every value not
        held is NaN, ``std_errors`` and ``free`` are empty and the components are NaN.
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
    not_determined: str = ""

    @property
    def determined(self) -> bool:
        """Whether the grid determined the decomposition (else ``not_determined`` says why)."""
        return not self.not_determined

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
        if not self.determined:
            return (
                f"GridDecomposition(plane {self.plane}, principal point {self.principal_point}: "
                f"not determined: {self.not_determined})"
            )
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
        When the grid cannot determine the model (fewer distinct field radii than radial
        unknowns, e.g. a 3x3 grid; too few traced fields; a rank-deficient design) it is
        returned with ``not_determined`` saying why and NaN values: no numbers are made up.
    """
    if principal_point not in PRINCIPAL_POINTS:
        raise DataError(
            f"principal_point={principal_point!r}; use one of {', '.join(PRINCIPAL_POINTS)}"
        )
    _check_radial_terms(radial_terms)
    if camera_constant not in CAMERA_CONSTANTS:
        raise DataError(
            f"camera_constant={camera_constant!r}; use one of {', '.join(CAMERA_CONSTANTS)}"
        )
    p = grid.plane_index(plane)
    pp = None if principal_point == "fit" else tuple(grid.named_point(principal_point)[p])
    if pp is not None and not all(math.isfinite(v) for v in pp):
        raise DataError(f"the {principal_point} point of plane {p} could not be traced")
    cc = None if camera_constant == "fit" else float(grid.camera_constant[p])
    t = np.stack([grid.tx.ravel(), grid.ty.ravel()], axis=1)
    img = grid.actual[p].reshape(-1, 2)
    shape = grid.shape + (2,)
    D = grid.D[p]
    ref = grid.reference_xy[p]
    try:
        fit = solve_linear(
            t, img, radial_terms=radial_terms, principal_point=pp, camera_constant=cc
        )
    except UndeterminedFit as e:
        return _undetermined(p, principal_point, camera_constant, ref, D, radial_terms, pp, cc,
                             str(e))  # fmt: skip
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


def _undetermined(p, principal_point, camera_constant, ref, D, radial_terms, pp, cc, why):
    """A :class:`GridDecomposition` the grid does not determine: held values kept, the rest
    NaN, no standard errors, NaN components."""
    nan = math.nan
    values = {"c": nan if cc is None else cc, "x0": nan, "y0": nan}
    if pp is not None:
        values["x0"], values["y0"] = (float(v) for v in pp)
    values.update({f"K{i}": nan for i in range(1, radial_terms + 1)})
    values.update({k: nan for k in ("P1", "P2", "S1", "S2")})
    blank = np.full(D.shape, nan)
    comps = {k: blank.copy() for k in ("offset", "scale", "radial", "decentering", "thin_prism",
                                      "residual")}  # fmt: skip
    return GridDecomposition(
        plane=p,
        principal_point=principal_point,
        camera_constant=camera_constant,
        reference_xy=(float(ref[0]), float(ref[1])),
        values=values,
        std_errors={},
        free=(),
        correlation=np.zeros((0, 0)),
        D=D,
        components=comps,
        rms_mm=nan,
        max_mm=nan,
        condition=math.inf,
        not_determined=why,
    )
