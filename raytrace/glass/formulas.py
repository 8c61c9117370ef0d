"""Dispersion formulas: refractive index from a formula id, its coefficients and λ in µm.

Numbering follows the source programs. Integer ids are the Zemax AGF formula numbers (the ``NM``
line of an ``.agf`` catalog; equations as the Zemax/OpticStudio manual states them in its glass
catalog chapter, "dispersion formulas"). String ids cover what AGF does not number:

============  ==========================================================================
id            equation (λ in µm; coefficients in the order listed)
============  ==========================================================================
1  Schott     n² = a0 + a1 λ² + a2 λ⁻² + a3 λ⁻⁴ + a4 λ⁻⁶ + a5 λ⁻⁸
2  Sellmeier1 n² − 1 = K1 λ²/(λ² − L1) + K2 λ²/(λ² − L2) + K3 λ²/(λ² − L3)
              coefficients K1, L1, K2, L2, K3, L3
3  Herzberger n = A + B L + C L² + D λ² + E λ⁴ + F λ⁶,  L = 1/(λ² − 0.028)
4  Sellmeier2 n² − 1 = A + B1 λ²/(λ² − λ1²) + B2/(λ² − λ2²);  A, B1, λ1, B2, λ2
5  Conrady    n = n0 + A/λ + B/λ^3.5;  n0, A, B
6  Sellmeier3 n² − 1 = Σ_{i=1..4} Ki λ²/(λ² − Li);  K1, L1, ..., K4, L4
7  Handbook1  n² = A + B/(λ² − C) − D λ²
8  Handbook2  n² = A + B λ²/(λ² − C) − D λ²
9  Sellmeier4 n² = A + B λ²/(λ² − C) + D λ²/(λ² − E)
10 Extended   n² = a0 + a1 λ² + a2 λ⁻² + a3 λ⁻⁴ + a4 λ⁻⁶ + a5 λ⁻⁸ + a6 λ⁻¹⁰ + a7 λ⁻¹²
11 Sellmeier5 n² − 1 = Σ_{i=1..5} Ki λ²/(λ² − Li);  K1, L1, ..., K5, L5
12 Extended2  n² = a0 + a1 λ² + a2 λ⁻² + a3 λ⁻⁴ + a4 λ⁻⁶ + a5 λ⁻⁸ + a6 λ⁴ + a7 λ⁶
13 Extended3  n² = a0 + a1 λ² + a2 λ⁴ + a3 λ⁻² + a4 λ⁻⁴ + a5 λ⁻⁶ + a6 λ⁻⁸ + a7 λ⁻¹⁰ + a8 λ⁻¹²
"rii1"        refractiveindex.info formula 1 (Sellmeier):
              n² − 1 = C1 + Σ C(2i) λ²/(λ² − C(2i+1)²)
"rii2"        refractiveindex.info formula 2 (Sellmeier-2):
              n² − 1 = C1 + Σ C(2i) λ²/(λ² − C(2i+1))
"rii3"        refractiveindex.info formula 3 (polynomial): n² = C1 + Σ C(2i) λ^C(2i+1)
"cauchy"      Cauchy power series (refractiveindex.info formula 5): n = C1 + Σ C(2i) λ^C(2i+1)
"tabulated"   a table n(λ): coefficients λ1..λN, n1..nN (λ ascending); piecewise-linear
              interpolation in λ (numpy.interp), held constant beyond the table's ends
"spline"      a table n(λ) (same coefficients) through a cubic spline in λ with not-a-knot
              ends, extrapolated with the end cubics — the interpolation ray-optics applies to
              CODE V private glasses (scipy ``interp1d(kind="cubic")``); 3 points: the
              parabola, 2: the line, 1: a constant
"buchdahl"    Buchdahl's chromatic-coordinate polynomial (Robb & Mercado 1983, Appl. Opt. 22,
              1198): n = n0 + ν1 ω + ν2 ω² + …, ω = Δλ/(1 + α Δλ), Δλ = λ − λ0;
              coefficients λ0 (µm), α, n0, ν1, ν2, …
============  ==========================================================================

refractiveindex.info formula 7 is the Herzberger formula (AGF 3, same coefficient order) and is
stored as 3; its formulas 4, 6, 8 and 9 are not used by any shipped material and are not
implemented. Equations of the refractiveindex.info numbering: "Dispersion formulas.pdf" of the
refractiveindex.info database (``optiland/database/doc`` in the optiland wheel).

The functions return the index in the basis of the data (relative to air for vendor catalogs);
:mod:`raytrace.materials` applies the basis conversion. This module needs only numpy and imports
nothing else from the project (the catalog generator loads it on its own).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

Coefficients = Sequence[float]


def _power_sum(lam: np.ndarray, c: Coefficients, powers: Sequence[float]) -> np.ndarray:
    """Σ c_k λ^p_k."""
    out = np.zeros_like(lam)
    for ck, pk in zip(c, powers, strict=False):
        if ck != 0.0:
            out = out + ck * lam**pk
    return out


def _poles(l2: np.ndarray, terms: Sequence[tuple[float, float, bool]]) -> np.ndarray:
    """Σ K · (λ² or 1) / (λ² − L) over ``terms`` = [(K, L, numerator_is_λ²)]."""
    out = np.zeros_like(l2)
    for k, pole, lam2_num in terms:
        if k != 0.0:
            out = out + k * (l2 if lam2_num else 1.0) / (l2 - pole)
    return out


def _pairs(c: Coefficients, n: int) -> list[tuple[float, float, bool]]:
    c = list(c) + [0.0] * (2 * n - len(c))
    return [(c[2 * i], c[2 * i + 1], True) for i in range(n)]


_SCHOTT_POWERS = (0, 2, -2, -4, -6, -8)
_EXTENDED_POWERS = (0, 2, -2, -4, -6, -8, -10, -12)
_EXTENDED2_POWERS = (0, 2, -2, -4, -6, -8, 4, 6)
_EXTENDED3_POWERS = (0, 2, 4, -2, -4, -6, -8, -10, -12)


def _schott(lam, c):
    return np.sqrt(_power_sum(lam, c, _SCHOTT_POWERS))


def _sellmeier(n_terms: int):
    def f(lam, c):
        return np.sqrt(1.0 + _poles(lam * lam, _pairs(c, n_terms)))

    return f


def _herzberger(lam, c):
    a, b, cc, d, e, f = (list(c) + [0.0] * 6)[:6]
    l2 = lam * lam
    L = 1.0 / (l2 - 0.028)
    return a + b * L + cc * L * L + d * l2 + e * l2 * l2 + f * l2 * l2 * l2


def _sellmeier2(lam, c):
    a, b1, l1, b2, l2_ = (list(c) + [0.0] * 5)[:5]
    l2 = lam * lam
    return np.sqrt(1.0 + a + _poles(l2, [(b1, l1 * l1, True), (b2, l2_ * l2_, False)]))


def _conrady(lam, c):
    return _power_sum(lam, c, (0, -1, -3.5))


def _handbook1(lam, c):
    a, b, cc, d = (list(c) + [0.0] * 4)[:4]
    l2 = lam * lam
    return np.sqrt(a + _poles(l2, [(b, cc, False)]) - d * l2)


def _handbook2(lam, c):
    a, b, cc, d = (list(c) + [0.0] * 4)[:4]
    l2 = lam * lam
    return np.sqrt(a + _poles(l2, [(b, cc, True)]) - d * l2)


def _sellmeier4(lam, c):
    a, b, cc, d, e = (list(c) + [0.0] * 5)[:5]
    return np.sqrt(a + _poles(lam * lam, [(b, cc, True), (d, e, True)]))


def _extended(lam, c):
    return np.sqrt(_power_sum(lam, c, _EXTENDED_POWERS))


def _extended2(lam, c):
    return np.sqrt(_power_sum(lam, c, _EXTENDED2_POWERS))


def _extended3(lam, c):
    return np.sqrt(_power_sum(lam, c, _EXTENDED3_POWERS))


def _rii_sellmeier(squared: bool):
    def f(lam, c):
        c = list(c)
        terms = [
            (c[i], c[i + 1] ** 2 if squared else c[i + 1], True) for i in range(1, len(c) - 1, 2)
        ]
        return np.sqrt(1.0 + c[0] + _poles(lam * lam, terms))

    return f


def _rii_polynomial(lam, c):
    c = list(c)
    return np.sqrt(c[0] + _power_sum(lam, c[1::2], c[2::2]))


def _cauchy(lam, c):
    c = list(c)
    return c[0] + _power_sum(lam, c[1::2], c[2::2])


def _tabulated(lam, c):
    m = len(c) // 2
    return np.interp(lam, np.asarray(c[:m]), np.asarray(c[m:]))


def _spline(lam, c):
    m = len(c) // 2
    x = np.asarray(c[:m], dtype=float)
    y = np.asarray(c[m:], dtype=float)
    if m <= 3:
        poly = np.polyfit(x, y, m - 1) if m > 1 else np.array([y[0]])
        return np.polyval(poly, lam)
    h = np.diff(x)
    a = np.zeros((m, m))
    r = np.zeros(m)
    for i in range(1, m - 1):  # continuity of the first derivative (second derivatives M)
        a[i, i - 1 : i + 2] = h[i - 1], 2.0 * (h[i - 1] + h[i]), h[i]
        r[i] = 6.0 * ((y[i + 1] - y[i]) / h[i] - (y[i] - y[i - 1]) / h[i - 1])
    # not-a-knot: the third derivative is continuous at the second and the last-but-one point
    a[0, :3] = h[1], -(h[0] + h[1]), h[0]
    a[-1, -3:] = h[-1], -(h[-2] + h[-1]), h[-2]
    mm = np.linalg.solve(a, r)
    j = np.clip(np.searchsorted(x, lam, side="right") - 1, 0, m - 2)
    hj = h[j]
    t1 = x[j + 1] - lam
    t0 = lam - x[j]
    return (
        mm[j] * t1**3 / (6.0 * hj)
        + mm[j + 1] * t0**3 / (6.0 * hj)
        + (y[j] / hj - mm[j] * hj / 6.0) * t1
        + (y[j + 1] / hj - mm[j + 1] * hj / 6.0) * t0
    )


def _buchdahl(lam, c):
    lam0, alpha, *nu = list(c)
    d = lam - lam0
    omega = d / (1.0 + alpha * d)
    n = np.zeros_like(lam) + nu[0]
    for k, v in enumerate(nu[1:], start=1):
        n = n + v * omega**k
    return n


@dataclass(frozen=True)
class Formula:
    """One dispersion formula: ``id``, its ``name``, the ``equation`` as text and the
    function ``n(λ_µm, coefficients)``."""

    id: int | str
    name: str
    equation: str
    function: Callable[[np.ndarray, Coefficients], np.ndarray]


FORMULAS: dict[int | str, Formula] = {
    f.id: f
    for f in (
        Formula(1, "Schott", "n² = a0 + a1λ² + a2λ⁻² + a3λ⁻⁴ + a4λ⁻⁶ + a5λ⁻⁸", _schott),
        Formula(2, "Sellmeier 1", "n² − 1 = Σ₁³ Kᵢλ²/(λ² − Lᵢ)", _sellmeier(3)),
        Formula(
            3, "Herzberger", "n = A + BL + CL² + Dλ² + Eλ⁴ + Fλ⁶, L = 1/(λ² − 0.028)", _herzberger
        ),
        Formula(4, "Sellmeier 2", "n² − 1 = A + B1λ²/(λ² − λ1²) + B2/(λ² − λ2²)", _sellmeier2),
        Formula(5, "Conrady", "n = n0 + A/λ + B/λ^3.5", _conrady),
        Formula(6, "Sellmeier 3", "n² − 1 = Σ₁⁴ Kᵢλ²/(λ² − Lᵢ)", _sellmeier(4)),
        Formula(7, "Handbook of Optics 1", "n² = A + B/(λ² − C) − Dλ²", _handbook1),
        Formula(8, "Handbook of Optics 2", "n² = A + Bλ²/(λ² − C) − Dλ²", _handbook2),
        Formula(9, "Sellmeier 4", "n² = A + Bλ²/(λ² − C) + Dλ²/(λ² − E)", _sellmeier4),
        Formula(10, "Extended", "n² = a0 + a1λ² + a2λ⁻² + a3λ⁻⁴ + … + a7λ⁻¹²", _extended),
        Formula(11, "Sellmeier 5", "n² − 1 = Σ₁⁵ Kᵢλ²/(λ² − Lᵢ)", _sellmeier(5)),
        Formula(
            12,
            "Extended 2",
            "n² = a0 + a1λ² + a2λ⁻² + a3λ⁻⁴ + a4λ⁻⁶ + a5λ⁻⁸ + a6λ⁴ + a7λ⁶",
            _extended2,
        ),
        Formula(
            13,
            "Extended 3",
            "n² = a0 + a1λ² + a2λ⁴ + a3λ⁻² + a4λ⁻⁴ + … + a8λ⁻¹²",
            _extended3,
        ),
        Formula(
            "rii1",
            "Sellmeier (refractiveindex.info formula 1)",
            "n² − 1 = C1 + Σ C(2i)λ²/(λ² − C(2i+1)²)",
            _rii_sellmeier(True),
        ),
        Formula(
            "rii2",
            "Sellmeier-2 (refractiveindex.info formula 2)",
            "n² − 1 = C1 + Σ C(2i)λ²/(λ² − C(2i+1))",
            _rii_sellmeier(False),
        ),
        Formula(
            "rii3",
            "Polynomial (refractiveindex.info formula 3)",
            "n² = C1 + Σ C(2i)λ^C(2i+1)",
            _rii_polynomial,
        ),
        Formula(
            "cauchy",
            "Cauchy (refractiveindex.info formula 5)",
            "n = C1 + Σ C(2i)λ^C(2i+1)",
            _cauchy,
        ),
        Formula(
            "tabulated",
            "tabulated n(λ)",
            "piecewise-linear interpolation in λ of the table (λ1..λN, n1..nN)",
            _tabulated,
        ),
        Formula(
            "buchdahl",
            "Buchdahl chromatic coordinate",
            "n = n0 + ν1ω + ν2ω² + …, ω = (λ − λ0)/(1 + α(λ − λ0))",
            _buchdahl,
        ),
        Formula(
            "spline",
            "tabulated n(λ), cubic spline",
            "not-a-knot cubic spline in λ through the table (λ1..λN, n1..nN)",
            _spline,
        ),
    )
}


def formula(formula_id: int | str) -> Formula:
    """The :class:`Formula` of ``formula_id``; ``KeyError`` naming the known ids otherwise."""
    try:
        return FORMULAS[formula_id]
    except KeyError:
        raise KeyError(
            f"unknown dispersion formula {formula_id!r}; known: {', '.join(map(str, FORMULAS))}"
        ) from None


def evaluate(formula_id: int | str, coefficients: Coefficients, wavelength_um) -> np.ndarray:
    """Refractive index by formula ``formula_id`` at ``wavelength_um`` (µm; scalar or array).

    Returns a float64 array of the shape of ``wavelength_um`` (0-d for a scalar), in the basis of
    the coefficients (no air or temperature correction).
    """
    lam = np.asarray(wavelength_um, dtype=float)
    return np.asarray(formula(formula_id).function(lam, coefficients), dtype=float)
