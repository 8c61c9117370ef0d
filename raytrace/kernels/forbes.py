"""The sum Σ b_m P_m(x) of the basis of Forbes's Qbfs evaluation and its derivative, by
Clenshaw's method: the one implementation the kernels (:func:`raytrace.kernels.surface.qtype_sag`
compiles it with ``@kernel``) and the Python layer (:mod:`raytrace.qtype`, on numpy arrays)
share. Qbfs and Qcon sums both reach it through their coefficients in that basis.

Plain arithmetic only, no numba import (the paraxial layer and :class:`raytrace.lens.Surface`
use it without loading numba): ``x`` may be a float or a numpy array, and nothing branches on
its value. The coefficients are row ``j`` of a 2-D array, column 0 being the surface's
``1/ρ_max²`` (the packed row of :meth:`raytrace.qtype.QType.packed_row`), columns 1.. the
coefficients of the sum; trailing zero columns leave the sum unchanged to the last bit (every
Clenshaw term above the last nonzero coefficient is exactly 0).

Qbfs (G. W. Forbes, "Shape specification for axially symmetric optical surfaces", Opt. Express
15, 5218 (2007); the evaluation of G. W. Forbes, "Robust, efficient computational methods for
axially symmetric optical aspheres", Opt. Express 18, 19700 (2010)): the coefficients a_m of
Σ a_m Q_m^bfs(x) are first changed to the basis P_m (done once per lens by
:func:`raytrace.qtype.qbfs_to_p_basis`), where ``P_0 = 2``, ``P_1 = 6 − 8x``,
``P_{m+1} = (2 − 4x) P_m − P_{m−1}``; then with ``α_m = b_m + (2 − 4x) α_{m+1} − α_{m+2}``
(α above the last coefficient 0), ``S = 2 (α_0 + α_1)`` (as P_0 = 2 and P_1 − (2 − 4x) P_0 = 2).
Differentiating the recurrence: ``α'_m = (2 − 4x) α'_{m+1} − 4 α_{m+1} − α'_{m+2}``,
``dS/dx = 2 (α'_0 + α'_1)``.

P_m = 2 W_m(1 − 2x), W_m the Chebyshev polynomials of the fourth kind (U_m + U_(m−1)): a
well-conditioned basis on [0, 1], into which :func:`raytrace.qtype.qcon_to_p_basis` also turns a
Qcon sum (by interpolation at Chebyshev points).
"""

from __future__ import annotations


def qbfs_sum(coef, j, x):
    """(S, dS/dx) of S(x) = Σ_m b_m P_m(x) with b_m = ``coef[j, 1 + m]`` (the P-basis
    coefficients of a Qbfs sum; module docstring)."""
    a1 = 0.0 * x  # α_{m+1}
    a2 = 0.0 * x  # α_{m+2}
    d1 = 0.0 * x
    d2 = 0.0 * x
    p = 2.0 - 4.0 * x
    for col in range(coef.shape[1] - 1, 0, -1):
        a0 = coef[j, col] + p * a1 - a2
        d0 = p * d1 - 4.0 * a1 - d2
        a2 = a1
        a1 = a0
        d2 = d1
        d1 = d0
    return 2.0 * (a1 + a2), 2.0 * (d1 + d2)
