"""Minimax optimization by sequential linear programming (SLP) with a trust region.

The objective is the largest weighted residual of the spec's *target* operands,

    F(x) = max_i |e_i(x)|,   e_i = weight_i × (value_i − target_i),

and every *bound* operand (``min`` and/or ``max``, :attr:`.spec.Operand.bounded`) is a
constraint g_j(x) ≤ 0 with g = weight × (min − value) and weight × (value − max). Damped least
squares minimises Σ e_i², which trades a large error at one operand for small ones elsewhere;
minimax is the tool when every operand must lie within a tolerance ("each table entry within
3 µm"): its optimum typically *equioscillates*, several residuals reaching ±F together.

Each iteration (after Madsen's and Fletcher's SL1QP-type methods):

1. central-difference Jacobians J = ∂e/∂x and G = ∂g/∂x (2n evaluations for n variables);
2. the linear program (``scipy.optimize.linprog``, HiGHS), in scaled steps z = dx / scale,

       min  t + P Σ s_j   s.t.  |e + J dx| ≤ t,  g + G dx ≤ s,  s ≥ 0,
            |z_k| ≤ D,  lower ≤ x + dx ≤ upper;

3. the step is accepted when it lowers the exact L1 penalty merit
   φ = max|e| + P Σ max(0, g) by at least 5 % of the decrease the LP predicted — if it does
   not, once more after a second-order correction (the least-norm step that brings the binding
   constraints and the largest residuals back to the values the linear model predicted, against
   the Maratos effect of curved constraints); the trust radius D doubles after a good step that
   reached it and shrinks after a poor or rejected one.

The run stops when the LP predicts no decrease (converged), when D falls below
:data:`MIN_RADIUS` (no further progress: converged at the precision of the differences), at the
evaluation limit, or when ``stop()`` asks (time budget, Ctrl-C in a caller) or a KeyboardInterrupt
(Ctrl-C) arrives once the start is evaluated. Every accepted step lowers φ, so the current design
is the best of the iterates; a stopped run returns the best design evaluated, by φ (a
finite-difference probe can be marginally better than the iterate).

P is the spec's ``penalty`` (default 100): it must exceed the Lagrange multipliers of the active
constraints (how much F would fall per unit of weighted relaxation of a bound) for the
constrained optimum to be a minimum of φ; a run that ends with a violated bound says so
(``converged=False``), and a larger penalty (or larger bound weights) is the fix.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable

import numpy as np
from scipy.optimize import linprog

from ..errors import TraceError
from ..lens import Lens
from ..paraxial import paraxial
from .operands import OperandValue
from .solver import (
    EVAL_FAILURES,
    EvaluationLog,
    OptimizationResult,
    StartLensError,
    Stopped,
    apply,
    bounds,
    check_spec,
    checked_evaluate,
    continuous,
    limit_message,
    local_result,
    max_violation,
    start_values,
    variable_scales,
)
from .spec import ASPHERIC_KINDS, DesignSpec, SpecError, evaluation_limit

#: the trust radius (in units of :func:`step_scales`) below which the run ends
MIN_RADIUS = 1e-9
#: the largest trust radius
MAX_RADIUS = 100.0
#: central-difference step, in units of :func:`step_scales`
DIFF_STEP = 1e-4
#: the LP's predicted decrease of φ, relative to 1 + φ, below which the run has converged
PRED_TOL = 1e-12


class _Failed(Exception):
    """A trial lens cannot be evaluated (a ray misses a surface, the lens is impossible)."""


def step_scales(lens: Lens, spec: DesignSpec) -> np.ndarray:
    """The unit of the trust region per continuous variable (spec order), from the start
    lens's EFL f: curvature 0.2/|f| (1/mm), thickness 0.002·|f| (mm), index 0.01, Abbe number 1,
    conic 0.1, aspheric coefficients 0.01 of :func:`.solver.variable_scales`' unit (a sag change of
    about f/1000 at height f/10, as a curvature unit makes)."""
    efl = abs(paraxial(lens).efl)
    asph = variable_scales(lens, spec)
    out = []
    for k, v in enumerate(continuous(spec)):
        if v.kind == "curvature":
            out.append(0.2 / efl)
        elif v.kind == "thickness":
            out.append(0.002 * efl)
        elif v.kind == "index":
            out.append(0.01)
        elif v.kind == "abbe":
            out.append(1.0)
        elif v.kind == "conic":
            out.append(0.1)
        elif v.kind in ASPHERIC_KINDS:
            out.append(0.01 * asph[k])
        else:  # pragma: no cover - continuous() holds only the kinds above
            out.append(1.0)
    return np.array(out, dtype=float)


def split(spec: DesignSpec, values: tuple[OperandValue, ...]) -> tuple[np.ndarray, np.ndarray]:
    """(e, g) of evaluated operands: e the weighted residuals of the target operands (weight >
    0), g the weighted signed bound values, weight × (min − value) and weight × (value − max)
    for each finite bound (≤ 0: met)."""
    e, g = [], []
    for o in values:
        op = o.operand
        if op.weight == 0:
            continue
        if not op.bounded:
            e.append(o.residual)
            continue
        lo, hi = op.limits
        if math.isfinite(lo):
            g.append(op.weight * (lo - o.value))
        if math.isfinite(hi):
            g.append(op.weight * (o.value - hi))
    return np.array(e, dtype=float), np.array(g, dtype=float)


def _max_abs(e: np.ndarray) -> float:
    return float(np.max(np.abs(e))) if e.size else 0.0


def exact_penalty(e: np.ndarray, g: np.ndarray, penalty: float) -> float:
    """The minimax run's merit φ = max|e| + P Σ max(0, g) (module docstring): the largest
    |weighted residual| of the target operands (``e``) plus ``penalty`` times the sum of the
    weighted bound violations (``g`` > 0: violated). It equals the max weighted residual when
    every bound is met."""
    return _max_abs(e) + penalty * float(np.sum(np.maximum(g, 0.0)))


def bounds_met(violation: float, merit: float) -> bool:
    """Whether a design's largest weighted bound violation is zero to rounding (1e-9 relative to
    1 + its max weighted residual ``merit``): the feasibility test of a minimax result."""
    return violation <= 1e-9 * (1.0 + merit)


def penalty_merit(spec: DesignSpec, values: tuple[OperandValue, ...]) -> float:
    """φ (:func:`exact_penalty`) of evaluated operands under ``spec``'s penalty: the merit by
    which minimax accepts steps and the global search ranks its minimax starts.

    Parameters
    ----------
    spec : DesignSpec
        Gives the target / bound split of the operands and ``penalty``.
    values : tuple of OperandValue
        The operands evaluated on one design (:func:`raytrace.optimize.evaluate`).

    Returns
    -------
    float
        φ in the operands' weighted units; ``inf`` when an operand is not finite.
    """
    e, g = split(spec, values)
    if not (np.all(np.isfinite(e)) and np.all(np.isfinite(g))):
        return math.inf
    return exact_penalty(e, g, float(spec.penalty))


def _lp_step(e, g, J, G, radius, zlo, zhi, penalty):
    """Solve the trust-region LP in scaled steps z; returns (z, t, model φ) or None."""
    n = J.shape[1]
    ne, ng = len(e), len(g)
    # unknowns: z (n), t, s (ng)
    c = np.concatenate([np.zeros(n), [1.0], np.full(ng, penalty)])
    A = np.zeros((2 * ne + ng, n + 1 + ng))
    b = np.zeros(2 * ne + ng)
    A[:ne, :n], A[:ne, n], b[:ne] = J, -1.0, -e
    A[ne : 2 * ne, :n], A[ne : 2 * ne, n], b[ne : 2 * ne] = -J, -1.0, e
    A[2 * ne :, :n], A[2 * ne :, n + 1 :], b[2 * ne :] = G, -np.eye(ng), -g
    lo = np.maximum(-radius, zlo)
    hi = np.minimum(radius, zhi)
    bnds = list(zip(lo, hi, strict=True)) + [(0.0, None)] * (1 + ng)
    if A.shape[0] == 0:
        return None
    res = linprog(c, A_ub=A, b_ub=b, bounds=bnds, method="highs")
    if res.status != 0:
        return None
    return res.x[:n], float(res.x[n]), float(res.fun)


def _second_order_correction(e, g, Js, Gs, z, t_lp, en, gn, f):
    """A correction step (scaled) for a trial point that the curvature of the operands spoiled
    (the Maratos effect of exact-penalty methods): the least-norm dz, dt that brings the
    constraints and objective residuals that were binding in the LP back to the values the
    linear model predicted, G_B dz = g_lin − g_new and sign·J_E dz − dt = |e_lin| − sign·e_new.
    None when nothing was binding."""
    tol = 1e-4 * (1.0 + f)
    gl = g + Gs @ z
    el = e + Js @ z
    B = gl > -tol
    E = np.abs(el) > t_lp - tol
    if not (B.any() or E.any()):
        return None
    n = Js.shape[1]
    sg = np.sign(el[E])
    M = np.vstack(
        [
            np.hstack([Gs[B], np.zeros((int(B.sum()), 1))]),
            np.hstack([sg[:, None] * Js[E], -np.ones((int(E.sum()), 1))]),
        ]
    )
    rhs = np.concatenate([gl[B] - gn[B], np.abs(el[E]) - sg * en[E]])
    return (np.linalg.pinv(M, rcond=1e-10) @ rhs)[:n]


def minimax(
    lens: Lens,
    spec: DesignSpec,
    progress: Callable[[int, float, OperandValue], None] | None = None,
    *,
    stop: Callable[[], str | None] | None = None,
    max_evaluations: int | None = None,
) -> OptimizationResult:
    """Minimise the largest |weighted residual| of the target operands subject to the bound
    operands (module docstring), over the spec's continuous variables within their bounds.

    Parameters
    ----------
    lens, spec
        The start lens and the design spec (``glass`` variables keep the start lens's glass).
    progress : callable, optional
        ``progress(evaluation, max_weighted_residual, worst_operand)`` after every evaluation
        (Jacobian evaluations included), as :func:`raytrace.optimize.optimize` calls it.
    stop : callable, optional
        Asked before each evaluation; a non-empty reason ends the run at once with the best
        design evaluated so far (by φ) and ``stopped`` set. A KeyboardInterrupt (Ctrl-C,
        or raised by ``progress``) once the start lens is evaluated does the same, with
        ``stopped == "interrupted"``.
    max_evaluations : int, optional
        Overrides ``spec.max_evaluations`` (an iteration costs 2n + 1 or more evaluations).

    Returns
    -------
    OptimizationResult
        ``method == "minimax"``; ``merit`` / ``merit_start`` are max |weight × (value − target)|
        over the target operands (0 when there are none), ``violation`` the largest weighted
        bound violation at the end. ``converged`` is False when the run hit the evaluation
        limit, was stopped, ends above ``spec.merit_goal`` or with a violated bound.
    """
    check_spec(lens, spec)
    limit = evaluation_limit(spec, max_evaluations)
    lo, hi = bounds(spec)
    x = start_values(lens, spec)
    sc = step_scales(lens, spec)
    P = float(spec.penalty)
    n = len(x)
    log = EvaluationLog()
    t0 = time.perf_counter()
    first: list = []  # (e, g, vals) of the start lens, once it is evaluated
    # (φ, x, e, g, vals) of the best design evaluated (a Jacobian probe can beat the iterate),
    # one object so that a Ctrl-C between two statements never mixes two designs: a stop
    # returns it
    best: list = [None]

    def ev(xv: np.ndarray, start: bool = False):
        try:
            # the start is always evaluated (as damped least squares does), so a stop asked
            # for at once still returns the start design, stopped; later evaluations ask stop()
            vals = checked_evaluate(lens, spec, xv, None if start else stop, log)
        except EVAL_FAILURES as err:
            if start:  # the start must evaluate: its own error, as damped least squares gives it
                if isinstance(err, TraceError):
                    raise StartLensError(spec, err) from None
                raise
            raise _Failed(str(err)) from None
        e, g = split(spec, vals)
        if not (np.all(np.isfinite(e)) and np.all(np.isfinite(g))):
            if start:
                bad = next(o for o in vals if not math.isfinite(o.residual))
                raise SpecError(f"the start lens: operand {bad.operand.label()} is not finite")
            raise _Failed("an operand is not finite")
        fv = phi(e, g)
        if best[0] is None or fv < best[0][0]:
            best[0] = (fv, xv.copy(), e, g, vals)
        if start:
            first[:] = (e, g, vals)
        if progress is not None:
            progress(log.n, _max_abs(e), max(vals, key=lambda o: abs(o.residual)))
        return e, g, vals

    def phi(e, g) -> float:
        return exact_penalty(e, g, P)

    radius = 1.0
    stopped, status, message = "", "", ""
    h = DIFF_STEP * sc
    vals = None  # the current iterate's operands
    try:
        e, g, vals = ev(x, start=True)
        f = phi(e, g)
        while True:
            if log.n + 2 * n + 1 > limit:
                status, message = "limit", limit_message(str(limit))
                break
            J = np.zeros((len(e), n))
            G = np.zeros((len(g), n))
            for k in range(n):  # central differences; one-sided next to a failing lens
                cols = []
                for sgn in (1.0, -1.0):
                    xk = x.copy()
                    xk[k] = x[k] + sgn * h[k]
                    try:
                        ek, gk, _ = ev(xk)
                        cols.append((sgn, ek, gk))
                    except _Failed:
                        pass
                if len(cols) == 2:
                    J[:, k] = (cols[0][1] - cols[1][1]) / (2 * h[k])
                    G[:, k] = (cols[0][2] - cols[1][2]) / (2 * h[k])
                elif len(cols) == 1:
                    sgn, ek, gk = cols[0]
                    J[:, k] = sgn * (ek - e) / h[k]
                    G[:, k] = sgn * (gk - g) / h[k]
            Js, Gs = J * sc, G * sc  # per unit of scaled step z
            zlo, zhi = (lo - x) / sc, (hi - x) / sc
            accepted = False
            while radius >= MIN_RADIUS:
                sol = _lp_step(e, g, Js, Gs, radius, zlo, zhi, P)
                if sol is None:
                    radius *= 0.5
                    continue
                z, t_lp, model = sol
                pred = f - model
                if pred <= PRED_TOL * (1.0 + f):
                    status = "converged"
                    message = "converged: the linearised problem predicts no further decrease"
                    break
                if log.n + 1 > limit:
                    status, message = "limit", limit_message(str(limit))
                    break
                xn = np.clip(x + z * sc, lo, hi)
                step = float(np.max(np.abs(z))) if n else 0.0
                try:
                    en, gn, vn = ev(xn)
                except _Failed:
                    radius = 0.3 * min(radius, step)
                    continue
                fn = phi(en, gn)
                ratio = (f - fn) / pred
                if not (fn < f and ratio > 0.05) and log.n + 1 <= limit:
                    corr = _second_order_correction(e, g, Js, Gs, z, t_lp, en, gn, f)
                    if corr is not None:
                        xc = np.clip(xn + corr * sc, lo, hi)
                        try:
                            ec, gc, vc = ev(xc)
                            fc = phi(ec, gc)
                            if fc < fn:
                                xn, en, gn, vn, fn = xc, ec, gc, vc, fc
                                ratio = (f - fn) / pred
                        except _Failed:
                            pass
                if fn < f and ratio > 0.05:
                    x, e, g, vals, f = xn, en, gn, vn, fn
                    accepted = True
                    if ratio > 0.75 and step > 0.9 * radius:
                        radius = min(2.0 * radius, MAX_RADIUS)
                    elif ratio < 0.25:
                        radius *= 0.5
                    break
                radius = 0.35 * min(radius, step)
            if status:
                break
            if not accepted:
                status = "converged"
                message = f"converged: no step lowers the merit (trust radius below {MIN_RADIUS:g})"
                break
    except Stopped as err:
        stopped = err.reason
    except KeyboardInterrupt:  # Ctrl-C: as a stop, once the start is evaluated
        if not first:
            raise
        stopped = "interrupted"
    if stopped:
        _, x, e, g, vals = best[0]
        message = f"stopped ({stopped}): the best design so far"
    m0 = _max_abs(first[0])
    final = apply(lens, spec, x)
    m = _max_abs(e)
    viol = max_violation(vals)
    converged = status == "converged" and not stopped
    feasible = bounds_met(viol, m)
    if converged and not feasible:
        converged = False
        worst = max((o for o in vals if o.operand.bounded), key=lambda o: abs(o.residual))
        message = (
            f"ended with a bound not met: {worst.operand.label()} = {worst.value:.6g} "
            f"(weighted violation {viol:.3g}); raise 'penalty' (now {P:g}) or the bound's weight"
        )
    elif converged and spec.merit_goal is not None and m > spec.merit_goal:
        converged = False
        message = f"max weighted residual {m:.6g} is above the goal {spec.merit_goal:.6g}"
    return local_result(log, t0, final, x, m0, m, vals, converged, message, stopped, "minimax")
