"""Forbes Q-type aspheres (OpticStudio's ``QED_TYPE`` surface): the surface terms
(:class:`QType`), the Qbfs recurrence, the sag and the vertex curvature.

Sag (ρ the radial coordinate, mm; c, k the curvature and conic constant of the *base* conic; u =
ρ/ρ_max, x = u²)::

    Qbfs:  z = cρ²/(1 + √(1 − (1+k)c²ρ²)) + φ(ρ) x(1 − x) Σ_m a_m Q_m^bfs(x),
           φ = √((1 − k c²ρ²) / (1 − (1+k)c²ρ²))
    Qcon:  z = cρ²/(1 + √(1 − (1+k)c²ρ²)) + x² Σ_m a_m Q_m^con(x)

with a_m in mm. With k = 0 the Qbfs form is Forbes's (G. W. Forbes, "Shape specification for
axially symmetric optical surfaces", Opt. Express 15, 5218 (2007)): the departure from the
best-fit sphere measured along its normal, φ = 1/√(1 − c²ρ²). With a conic base the departure is
measured along the conic's normal, φ = √(1 + z_conic'²) — the form optiland 0.6.3's
``ForbesQNormalSlopeGeometry`` implements, and the one that reproduces OpticStudio's
``QED_TYPE`` file of the Thorlabs ASL5040-UV (``CONI −0.676``; tests/test_qtype.py): the
catalog EFL of 40.000 mm and a focus corrected to 0.1 µm over its 45.72 mm pupil, where the
k = 0 factor misses by millimetres. The Qcon form is Forbes 2007's (the conic carries the
base; Q^con_m(x) = P_m^(0,4)(2x − 1)). Beyond ρ_max the polynomials are evaluated as they are
(optiland 0.6.3 sets the departure to 0 there; what OpticStudio does is not known here).

The Qbfs sum is evaluated by Clenshaw's method in :mod:`raytrace.kernels.forbes` (the kernels
and this module share it). The Qbfs coefficients are first changed to the basis P_m (Forbes 2010,
"Robust, efficient computational methods for axially symmetric optical aspheres", Opt. Express
18, 19700): with ``f_0 = 2``, ``g_0 = −1/2``, ``f_1 = √19/2``, and for m ≥ 2 ``h_{m−2} = −m(m −
1)/(2 f_{m−2})``, ``g_{m−1} = −(1 + g_{m−2} h_{m−2})/f_{m−1}``, ``f_m = √(m(m + 1) + 3 −
g_{m−1}² − h_{m−2}²)``, the polynomials are ``Q_m = (P_m − g_{m−1} Q_{m−1} − h_{m−2} Q_{m−2}) /
f_m`` (Q_0 = 1, Q_1 = (13 − 16x)/√19), so Σ a_m Q_m = Σ b_m P_m with ``b_M = a_M/f_M``,
``b_{M−1} = (a_{M−1} − g_{M−1} b_M)/f_{M−1}``, ``b_m = (a_m − g_m b_{m+1} − h_m b_{m+2})/f_m``.

Qcon: ``Q^con_m(x) = P_m^(0,4)(2x − 1)`` obeys the Jacobi three-term recurrence (DLMF 18.9.2
with α = 0, β = 4, t = 2x − 1) ``Q_{m+1} = (A_m + B_m x) Q_m − C_m Q_{m−1}``,
``A_m = −(2m + 5)(m² + 5m + 10)/((m + 1)(m + 2)(m + 5))``, ``B_m = 2(2m + 5)(m + 3)/((m + 1)(m +
5))``, ``C_m = m(m + 3)(m + 4)/((m + 1)(m + 2)(m + 5))`` (Q_0 = 1, Q_1 = 6x − 5); the sum here
by Clenshaw (``β_m = a_m + (A_m + B_m x) β_{m+1} − C_{m+1} β_{m+2}``, S = β_0, and its
derivative). For the kernels a Qcon sum is turned into the Qbfs evaluation's basis P_m
(:func:`qcon_to_p_basis`: interpolation at Chebyshev points, exact for a polynomial of that
degree), so both forms share one Clenshaw loop (:func:`raytrace.kernels.surface.qtype_sag`).

Vertex (paraxial) curvature: near the axis φ → 1 and x(1 − x) → ρ²/ρ_max², so a Qbfs surface
has z ≈ (c/2 + S(0)/ρ_max²) ρ², c_vertex = c + 2 Σ a_m Q_m^bfs(0)/ρ_max² (the best-fit
sphere's curvature c is not the paraxial one); the Qcon departure starts at ρ⁴, so c_vertex = c
there. The paraxial layer uses c_vertex (:attr:`raytrace.lens.Surface.
vertex_curvature`).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from .kernels.forbes import qbfs_sum

#: the forms of a Q-type surface
FORMS = ("qbfs", "qcon")


@dataclass(frozen=True)
class QType:
    """The Q-type terms of a surface (module docstring): ``form`` ``"qbfs"`` or ``"qcon"``,
    ``norm_radius`` ρ_max (mm, > 0) and ``terms`` (a_0, a_1, ...) in mm. The surface's
    ``curvature`` and ``conic`` are those of the base conic."""

    form: str
    norm_radius: float
    terms: tuple[float, ...] = ()

    def __post_init__(self) -> None:
        if self.form not in FORMS:
            raise ValueError(f"Q-type form must be one of {', '.join(FORMS)}, got {self.form!r}")
        r = self.norm_radius
        if (
            isinstance(r, bool)
            or not isinstance(r, int | float)
            or not (math.isfinite(r) and r > 0)
        ):
            raise ValueError(f"Q-type norm_radius must be a positive number of mm, got {r!r}")
        object.__setattr__(self, "norm_radius", float(r))
        t = tuple(self.terms)
        for a in t:
            if isinstance(a, bool) or not isinstance(a, int | float) or not math.isfinite(a):
                raise ValueError(f"Q-type terms must be finite numbers (mm), got {a!r}")
        object.__setattr__(self, "terms", tuple(float(a) + 0.0 for a in t))

    @property
    def is_zero(self) -> bool:
        """True when every term is 0: the surface is its base conic."""
        return not any(self.terms)

    def describe(self) -> str:
        """E.g. ``Qbfs rn 27: -0.8148, -0.3231``."""
        name = "Qbfs" if self.form == "qbfs" else "Qcon"
        return f"{name} rn {self.norm_radius:g}: " + ", ".join(f"{a:.4g}" for a in self.terms)

    def scaled(self, factor: float) -> QType:
        """The terms of the surface scaled by ``factor`` (ρ_max and the a_m are lengths)."""
        return QType(self.form, self.norm_radius * factor, tuple(a * factor for a in self.terms))

    def packed_row(self) -> tuple[float, ...]:
        """The row the kernels read (:func:`raytrace.packing.pack`, array ``asph``): 1/ρ_max²,
        then the coefficients of the sum in the basis P_m (:func:`qbfs_to_p_basis`,
        :func:`qcon_to_p_basis`)."""
        w = 1.0 / (self.norm_radius * self.norm_radius)
        if self.form == "qbfs":
            return (w, *qbfs_to_p_basis(self.terms))
        return (w, *qcon_to_p_basis(self.terms))


@functools.lru_cache(maxsize=64)
def qbfs_recurrence(n: int) -> tuple[tuple[float, ...], tuple[float, ...], tuple[float, ...]]:
    """(f, g, h): Forbes 2010's recurrence coefficients f_m, g_m, h_m of the Qbfs polynomials for
    m = 0 .. n−1 (module docstring; h_{n−1} is not needed by n polynomials and is 0 here)."""
    n = max(int(n), 0)
    f = [2.0, math.sqrt(19.0) / 2.0][:n]
    g = [-0.5][:n]
    h: list[float] = []
    for m in range(2, n + 1):
        h.append(-m * (m - 1) / (2.0 * f[m - 2]))
        g.append(-(1.0 + g[m - 2] * h[m - 2]) / f[m - 1])
        if m < n:
            f.append(math.sqrt(m * (m + 1) + 3.0 - g[m - 1] ** 2 - h[m - 2] ** 2))
    h += [0.0] * (n - len(h))
    return tuple(f), tuple(g[:n]), tuple(h[:n])


def qbfs_to_p_basis(terms) -> tuple[float, ...]:
    """The coefficients b_m with Σ a_m Q_m^bfs = Σ b_m P_m (module docstring; Forbes 2010),
    for a_m = ``terms``."""
    a = [float(v) for v in terms]
    n = len(a)
    if n == 0:
        return ()
    f, g, h = qbfs_recurrence(n)
    b = [0.0] * (n + 2)
    for m in range(n - 1, -1, -1):
        b[m] = (a[m] - g[m] * b[m + 1] - h[m] * b[m + 2]) / f[m]
    return tuple(b[:n])


def qcon_recurrence(m: int) -> tuple[float, float, float]:
    """(A_m, B_m, C_m) of ``Q^con_{m+1} = (A_m + B_m x) Q^con_m − C_m Q^con_{m−1}`` (module
    docstring: Jacobi P^(0,4)(2x − 1), DLMF 18.9.2)."""
    den = (m + 1.0) * (m + 2.0) * (m + 5.0)
    a = -(2.0 * m + 5.0) * (m * m + 5.0 * m + 10.0) / den
    b = 2.0 * (2.0 * m + 5.0) * (m + 3.0) / ((m + 1.0) * (m + 5.0))
    c = m * (m + 3.0) * (m + 4.0) / den
    return a, b, c


def qcon_sum(terms, x) -> tuple[np.ndarray, np.ndarray]:
    """(S, dS/dx) of S(x) = Σ_m a_m Q_m^con(x), a_m = ``terms``, by Clenshaw's method (module
    docstring); ``x`` a float or an array."""
    x = np.asarray(x, dtype=float)
    b1 = b2 = d1 = d2 = np.zeros_like(x)
    for m in range(len(terms) - 1, -1, -1):
        a, b, _ = qcon_recurrence(m)
        cn = qcon_recurrence(m + 1)[2]
        t = a + b * x
        b0 = terms[m] + t * b1 - cn * b2
        d0 = b * b1 + t * d1 - cn * d2
        b1, b2, d1, d2 = b0, b1, d0, d1
    return b1, d1


def p_basis(x, n: int) -> np.ndarray:
    """P_0(x) .. P_(n−1)(x) of the Qbfs evaluation's basis (:mod:`raytrace.kernels.forbes`),
    shape (n, *x.shape): each by the Clenshaw sum of its unit coefficient vector."""
    x = np.asarray(x, dtype=float)
    out = np.empty((n, *x.shape))
    for m in range(n):
        row = np.zeros((1, n + 1))
        row[0, m + 1] = 1.0
        out[m] = qbfs_sum(row, 0, x)[0]
    return out


def qcon_to_p_basis(terms) -> tuple[float, ...]:
    """The coefficients b_m with Σ a_m Q_m^con = Σ b_m P_m (a_m = ``terms``): both sides are
    polynomials of degree M in x, so interpolation at M + 1 Chebyshev points of [0, 1] gives b
    exactly up to round-off (P_m = 2 W_m(1 − 2x) is well conditioned there)."""
    n = len(terms)
    if n == 0:
        return ()
    x = 0.5 - 0.5 * np.cos(np.pi * (np.arange(n) + 0.5) / n)
    b = np.linalg.solve(p_basis(x, n).T, qcon_sum(tuple(terms), x)[0])
    return tuple(float(v) for v in b)


def _row(qt: QType) -> np.ndarray:
    return np.asarray(qt.packed_row(), dtype=float)[None, :]


def qtype_sum(qt: QType, x) -> tuple[np.ndarray, np.ndarray]:
    """(S, dS/dx): Σ_m a_m Q_m(x) of ``qt``'s form and its derivative at x = u² (numpy)."""
    x = np.asarray(x, dtype=float)
    if qt.form == "qbfs":
        s, ds = qbfs_sum(_row(qt), 0, x)
    else:
        s, ds = qcon_sum(qt.terms, x)
    return np.asarray(s + 0.0 * x), np.asarray(ds + 0.0 * x)


def polynomials(form: str, m_max: int, x) -> np.ndarray:
    """Q_0(x) .. Q_{m_max}(x) of ``form`` (``"qbfs"`` or ``"qcon"``), shape (m_max + 1, *x.shape):
    each by the Clenshaw sum of its unit coefficient vector."""
    x = np.asarray(x, dtype=float)
    out = np.empty((m_max + 1, *x.shape))
    for m in range(m_max + 1):
        e = [0.0] * (m_max + 1)
        e[m] = 1.0
        out[m] = qtype_sum(QType(form, 1.0, tuple(e)), x)[0]
    return out


def departure(qt: QType, c: float, k: float, r) -> np.ndarray:
    """The Q-type part of the sag (mm) at radial coordinates ``r`` (mm) on a base conic of
    curvature ``c`` and conic ``k`` (module docstring); NaN where the conic is undefined."""
    r2 = np.asarray(r, dtype=float) ** 2
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        x = r2 / (qt.norm_radius * qt.norm_radius)
        s = qtype_sum(qt, x)[0]
        if qt.form == "qcon":
            return x * x * s
        arg = 1.0 - (1.0 + k) * c * c * r2
        phi = np.sqrt((1.0 - k * c * c * r2) / arg)
        return np.where(arg > 0.0, x * (1.0 - x) * phi * s, np.nan)


def vertex_curvature(qt: QType, c: float) -> float:
    """The paraxial curvature (1/mm) of a surface with base curvature ``c`` and the terms ``qt``:
    c + 2 Σ a_m Q_m^bfs(0)/ρ_max² for Qbfs, c for Qcon (module docstring)."""
    if qt.form != "qbfs" or qt.is_zero:
        return float(c)
    s0 = float(qtype_sum(qt, 0.0)[0])
    return float(c) + 2.0 * s0 / (qt.norm_radius * qt.norm_radius)
