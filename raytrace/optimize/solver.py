"""Damped least squares on ``scipy.optimize.least_squares`` (trust-region reflective with the
variable bounds): the spec's continuous variables applied to the start lens, the operands
evaluated, the weighted residuals minimised. ``glass`` variables are held (the global search,
:mod:`.global_search`, substitutes them). :func:`optimize` runs the spec's ``method``: this one,
or minimax (:mod:`.minimax`)."""

from __future__ import annotations

import math
import numbers
import time
from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np
from scipy.optimize import least_squares

from ..errors import OrthoscopeError, TraceError
from ..lens import Lens, require_lens
from ..materials import Material
from ..paraxial import gaussian_solved, paraxial
from .operands import OperandValue, evaluate, merit, operand_lens_problems
from .spec import (
    ABBE_BOUNDS,
    ASPHERIC_KINDS,
    INDEX_BOUNDS,
    METHODS,
    PICKUP_KINDS,
    VARIABLE_KINDS,
    DesignSpec,
    SpecError,
    Variable,
    evaluation_limit,
    operand_problems,
    suggest,
)


@dataclass(frozen=True, eq=False)
class OptimizationResult:
    """The outcome of one local optimization run (damped least squares or minimax).

    lens: the optimized lens; x: the continuous variables' values (spec order, glass variables
    left out); merit_start / merit: before / after — for ``method == "least_squares"`` the sum
    of squared weighted residuals (bound operands: their weighted violations), for
    ``"minimax"`` the largest |weighted residual| of the target operands (the bound operands
    are constraints, reported in ``violation``); operands: every operand's value and residual;
    evaluations: merit evaluations used; converged: whether the run met its stopping test (and
    the spec's merit goal; minimax: and its constraints); message: why it stopped; seconds:
    wall time; stopped: ``""``, or why it was cut short from outside (``"time"``,
    ``"interrupted"``) — the result is then the best design evaluated so far; method: the
    method that ran; violation: the largest weighted violation of a bound operand (0: all met).
    """

    lens: Lens
    x: np.ndarray
    merit_start: float
    merit: float
    operands: tuple[OperandValue, ...]
    evaluations: int
    converged: bool
    message: str
    seconds: float
    stopped: str = ""
    method: str = "least_squares"
    violation: float = 0.0

    @property
    def worst(self) -> OperandValue:
        return max(self.operands, key=lambda o: abs(o.residual))

    def __repr__(self) -> str:
        return (
            f"OptimizationResult(merit {self.merit_start:.6g} -> {self.merit:.6g}, "
            f"{self.evaluations} evaluations, converged={self.converged})"
        )


class Stopped(Exception):
    """Raised inside a merit evaluation when the caller's ``stop()`` asks to stop."""

    def __init__(self, reason: str) -> None:
        super().__init__(reason)
        self.reason = reason


# ----------------------------------------------------------------------------- variables
def continuous(spec: DesignSpec) -> tuple[Variable, ...]:
    """The spec's variables that damped least squares varies (all but ``glass``)."""
    return tuple(v for v in spec.variables if v.kind != "glass")


def get_value(lens: Lens, kind: str, surface: int) -> float:
    s = lens.surfaces[surface - 1]
    if kind == "curvature":
        return s.curvature
    if kind == "thickness":
        return s.thickness
    if kind == "index":
        return s.material.nd
    if kind == "abbe":
        return s.material.vd
    if kind == "conic":
        return s.conic
    if kind in ASPHERIC_KINDS:
        j = ASPHERIC_KINDS.index(kind)
        return s.aspheric[j] if j < len(s.aspheric) else 0.0
    raise SpecError(f"unknown variable kind {kind!r}{suggest(kind, VARIABLE_KINDS)}")


def set_values(lens: Lens, kinds_surfaces: list[tuple[str, int]], values) -> Lens:
    """A copy of ``lens`` with the given (kind, surface) parameters replaced (no validation of the
    physical sense beyond the Lens model's own). ``index`` and ``abbe`` turn a catalog glass into
    a model glass (``abbe``) or a fixed index (``index`` on a non-model medium)."""
    surfaces = list(lens.surfaces)
    for (kind, i), v in zip(kinds_surfaces, values, strict=True):
        s = surfaces[i - 1]
        v = float(v)
        if kind == "curvature":
            s = replace(s, curvature=v)
        elif kind == "thickness":
            s = replace(s, thickness=v)
        elif kind == "conic":
            s = replace(s, conic=v)
        elif kind in ASPHERIC_KINDS:
            j = ASPHERIC_KINDS.index(kind)
            a = list(s.aspheric) + [0.0] * max(0, j + 1 - len(s.aspheric))
            a[j] = v
            while a and a[-1] == 0.0:
                a.pop()
            s = replace(s, aspheric=tuple(a))
        elif kind == "abbe":
            m = s.material
            s = replace(s, material=Material("model", m.nd, v, model=m.model))
        elif kind == "index":
            m = s.material
            s = replace(s, material=Material("model" if m.kind == "model" else "index", v, m.vd))
        else:
            raise SpecError(f"variable kind {kind!r} has no continuous value")
        surfaces[i - 1] = s
    return replace(lens, surfaces=tuple(surfaces), image_solve=None)


def set_materials(lens: Lens, materials: dict[int, Material]) -> Lens:
    """A copy of ``lens`` with the media after the given 1-based surfaces replaced."""
    if not materials:
        return lens
    surfaces = list(lens.surfaces)
    for i, m in materials.items():
        surfaces[i - 1] = replace(surfaces[i - 1], material=m)
    return replace(lens, surfaces=tuple(surfaces))


def apply(lens: Lens, spec: DesignSpec, x) -> Lens:
    """The lens with the continuous variables ``x`` (in the order of :func:`continuous`) and the
    spec's pick-ups applied (a ``glass`` pick-up copies the medium after its source).

    A start lens whose image plane is a Gaussian solve (``image_solve == "gaussian"``) keeps it:
    the last thickness is re-solved for every new lens unless it is itself a variable or pick-up.
    """
    ks = [(v.kind, v.surface) for v in continuous(spec)]
    out = set_values(lens, ks, x)
    glass_pk = {
        p.surface: out.surfaces[p.source - 1].material for p in spec.pickups if p.kind == "glass"
    }
    out = set_materials(out, glass_pk)
    num_pk = [p for p in spec.pickups if p.kind != "glass"]
    if num_pk:
        vals = [p.factor * get_value(out, p.kind, p.source) + p.offset for p in num_pk]
        out = set_values(out, [(p.kind, p.surface) for p in num_pk], vals)
    last = ("thickness", lens.n_surfaces)
    if lens.image_solve == "gaussian" and last not in ks + [(p.kind, p.surface) for p in num_pk]:
        out = gaussian_solved(out)
    return out


def bounds(spec: DesignSpec) -> tuple[np.ndarray, np.ndarray]:
    """Lower and upper bounds of the continuous variables (index and Abbe variables are kept
    within glass-like limits, :data:`INDEX_BOUNDS`, :data:`ABBE_BOUNDS`)."""
    lo, hi = [], []
    for v in continuous(spec):
        b = {"index": INDEX_BOUNDS, "abbe": ABBE_BOUNDS}.get(v.kind, (-math.inf, math.inf))
        lo.append(max(v.lower, b[0]))
        hi.append(min(v.upper, b[1]))
    return np.array(lo, dtype=float), np.array(hi, dtype=float)


def start_values(lens: Lens, spec: DesignSpec) -> np.ndarray:
    """The continuous variables' values in ``lens``, clipped into their bounds."""
    x0 = np.array([get_value(lens, v.kind, v.surface) for v in continuous(spec)], dtype=float)
    lo, hi = bounds(spec)
    return np.clip(x0, lo, hi)


# ----------------------------------------------------------------------------- checks
def check_spec(lens: Lens, spec: DesignSpec, *, need_continuous: bool = True) -> None:
    """Raise :class:`SpecError` for a spec that cannot apply to ``lens`` (one line per problem).

    ``need_continuous``: damped least squares needs at least one continuous variable; the global
    search also accepts a spec whose only variables are glasses.
    """
    n = lens.n_surfaces
    probs: list[str] = []
    for v in spec.variables:
        if v.kind not in VARIABLE_KINDS:
            probs.append(f"unknown variable kind {v.kind!r}{suggest(v.kind, VARIABLE_KINDS)}")
            continue
        if not isinstance(v.surface, numbers.Integral) or isinstance(v.surface, bool):
            probs.append(f"variable {v.kind}: surface must be an integer, got {v.surface!r}")
            continue
        if not 1 <= v.surface <= n:
            probs.append(f"variable {v.kind} on surface {v.surface}: the lens has {n} surfaces")
            continue
        if v.lower >= v.upper:
            probs.append(f"variable {v.kind} {v.surface}: bounds inverted ({v.lower} ≥ {v.upper})")
        if v.kind in ("index", "abbe", "glass") and lens.surfaces[v.surface - 1].material.is_air:
            probs.append(
                f"variable {v.kind} {v.surface}: the medium after it is air (a {v.kind} "
                "variable goes on the surface in front of the glass)"
            )
    seen = {(v.kind, v.surface) for v in spec.variables}
    if len(seen) < len(spec.variables):
        probs.append("a variable is listed twice (same kind and surface)")
    for pk in spec.pickups:
        if pk.kind not in PICKUP_KINDS:
            probs.append(f"unknown pick-up kind {pk.kind!r}{suggest(pk.kind, PICKUP_KINDS)}")
            continue
        bad = [s for s in (pk.surface, pk.source) if not 1 <= s <= n]
        if bad:
            probs.append(
                f"pick-up {pk.kind} {pk.surface} <- {pk.source}: surface {bad[0]} "
                f"does not exist (the lens has {n})"
            )
            continue
        if (pk.kind, pk.surface) in seen:
            probs.append(f"{pk.kind} {pk.surface} is both a variable and a pick-up")
        if pk.kind == "glass" and lens.surfaces[pk.surface - 1].material.is_air:
            probs.append(f"glass pick-up on surface {pk.surface}: the medium after it is air")
    if not spec.variables:
        probs.append("the spec has no variables")
    elif need_continuous and not continuous(spec):
        probs.append(
            "the spec has only glass variables: glass substitution is the global search's "
            "(orthoscope optimize --global); damped least squares needs a continuous variable"
        )
    if not spec.operands:
        probs.append("the spec has no operands")
    if spec.method not in METHODS:
        probs.append(f"unknown method {spec.method!r}{suggest(spec.method, METHODS)}")
    if not (isinstance(spec.penalty, (int, float)) and spec.penalty > 0):
        probs.append(f"penalty must be a positive number, got {spec.penalty!r}")
    for i, op in enumerate(spec.operands):
        bad = operand_problems(op.type, op.params, op.target, op.weight)
        bad = bad or operand_lens_problems(lens, op)
        probs += [f"operands[{i}] ({op.label()}): {b}" for b in bad]
    if len(probs) == 1:
        raise SpecError(probs[0])
    if probs:
        raise SpecError(f"{len(probs)} problems:\n" + "\n".join(f"  {p}" for p in probs))


# ----------------------------------------------------------------------------- solver
#: what an impossible trial lens raises in an evaluation (a ray misses a surface, ...)
EVAL_FAILURES = (OrthoscopeError, ValueError, ZeroDivisionError, FloatingPointError)


@dataclass
class EvaluationLog:
    """The merit evaluations of one optimizer run (a counter, so not frozen): how many, how many
    failed (a trial lens that cannot be traced: a ray misses a surface, total internal
    reflection, ...), and the first failure's reason."""

    n: int = 0
    failed: int = 0
    first_failure: str = ""

    def note(self) -> str:
        """What to add to the run's message: nothing, or how many evaluations failed and why."""
        if not self.failed:
            return ""
        return (
            f"; {self.failed} of {self.n} evaluations failed (trial lenses that cannot be traced; "
            f"the first: {self.first_failure})"
        )


#: why scipy's least_squares ended (its ``status`` > 0), in the project's words; ``{t}`` the
#: spec's tolerance (scipy's xtol, ftol and gtol alike)
SCIPY_STATUS_WORDS = {
    1: "the gradient fell below the tolerance ({t:g})",
    2: "the last step changed the merit by less than the tolerance ({t:g}, relative)",
    3: "the last step changed the variables by less than the tolerance ({t:g}, relative)",
    4: "the last step changed the merit and the variables by less than the tolerance "
    "({t:g}, relative)",
}


def limit_message(count: str) -> str:
    """Why a local run ended at its evaluation limit, and how to raise the limit; ``count``:
    the limit as the method counts it ("400", "400 merit evaluations of ...")."""
    return (
        f"stopped at the evaluation limit ({count}) before converging; raise it: "
        "max_evaluations in the spec, or --max-evaluations N on the command line"
    )


class StartLensError(TraceError):
    """An operand cannot be evaluated on the spec's start lens (the optimizers evaluate it before
    any step): the message names the start lens, then the operand's own error.

    Attributes
    ----------
    cause : TraceError
        The operand's error (a :class:`~raytrace.optimize.operands.ChiefRayError` keeps its
        problem apart from its fix).
    """

    def __init__(self, spec: DesignSpec, cause: TraceError, when: str = "") -> None:
        self.cause = cause
        super().__init__(f"the start lens ({spec.start}){when}: {cause}")


def evaluate_start(lens: Lens, spec: DesignSpec, x: np.ndarray) -> tuple[OperandValue, ...]:
    """The operands of ``spec`` on its start design ``lens`` at ``x`` (checked against the lens
    by :func:`check_spec` before the run); a trace error is a :class:`StartLensError`."""
    try:
        return evaluate(apply(lens, spec, x), spec.operands, check=False)
    except TraceError as e:
        raise StartLensError(spec, e) from None


def checked_evaluate(
    lens: Lens,
    spec: DesignSpec,
    x: np.ndarray,
    stop: Callable[[], str | None] | None,
    log: EvaluationLog,
) -> tuple[OperandValue, ...]:
    """One merit evaluation of an optimizer: ask ``stop()`` first (raise :class:`Stopped` with
    its reason), count it in ``log``, evaluate the operands of ``spec`` (checked against the
    lens by :func:`check_spec` before the run) applied to ``lens`` at ``x``. An impossible trial
    lens raises one of :data:`EVAL_FAILURES`, counted in ``log`` with the first reason."""
    if stop is not None:
        why = stop()
        if why:
            raise Stopped(why)
    log.n += 1
    try:
        return evaluate(apply(lens, spec, x), spec.operands, check=False)
    except EVAL_FAILURES as e:
        log.failed += 1
        if not log.first_failure:
            log.first_failure = " ".join(str(e).split())[:300]
        raise


def variable_scales(lens: Lens, spec: DesignSpec) -> np.ndarray:
    """The solver works on x / scale: aspheric coefficients are tiny numbers (mm^(1-k)), scaled
    so that a unit change is a sag change of the order of a tenth of the EFL at a tenth of the
    EFL; every other kind is left unscaled."""
    rref = 0.1 * abs(paraxial(lens).efl)
    return np.array(
        [
            rref ** (1 - (4 + 2 * ASPHERIC_KINDS.index(v.kind)))
            if v.kind in ASPHERIC_KINDS
            else 1.0
            for v in continuous(spec)
        ]
    )


def optimize(
    lens: Lens,
    spec: DesignSpec,
    progress: Callable[[int, float, OperandValue], None] | None = None,
    *,
    stop: Callable[[], str | None] | None = None,
    max_evaluations: int | None = None,
    method: str | None = None,
) -> OptimizationResult:
    """Run damped least squares (``least_squares``, trust-region reflective with the variable
    bounds) over the spec's continuous variables; ``glass`` variables keep the start lens's
    glass. ``progress(evaluation, merit, worst_operand)`` is called after each evaluation.

    ``method`` (default the spec's ``method``): ``"least_squares"``, or ``"minimax"`` to run
    :func:`raytrace.optimize.minimax.minimax` with the same arguments (its merit is the largest
    |weighted residual|; the bound operands are constraints).

    ``stop()`` is asked before each evaluation; when it returns a reason (a non-empty string)
    the run ends at once and returns the best design evaluated so far with ``stopped`` set.
    A KeyboardInterrupt (Ctrl-C, or raised by ``progress``) once the start lens is evaluated
    does the same, with ``stopped == "interrupted"``; one during the start's evaluation
    propagates (there is no design to return).
    ``max_evaluations`` overrides the spec's limit (a whole number ≥ 1). Least squares counts it
    as scipy's ``max_nfev`` (the evaluations of its steps; the finite-difference Jacobians, n
    evaluations each for n variables, come on top), minimax counts every evaluation
    (docs/spec.md, ``max_evaluations``); ``OptimizationResult.evaluations`` counts every one.

    A run that stops on the evaluation limit, or ends above ``spec.merit_goal``, is returned with
    ``converged=False`` and a message saying why; the caller must not present it as a success.

    Parameters
    ----------
    lens : Lens
        The start lens.
    spec : DesignSpec
        Variables, pick-ups and operands (:func:`raytrace.optimize.read_spec`).
    progress : callable(int, float, OperandValue), optional
        Called after each evaluation with its number, the merit and the worst operand.
    stop : callable() -> str or None, optional
        Asked before each evaluation; a non-empty string ends the run.
    max_evaluations : int, optional
        The evaluation limit (≥ 1); default the spec's.
    method : {"least_squares", "minimax"}, optional
        Default the spec's ``method``.

    Returns
    -------
    OptimizationResult
        The final lens, the variable values, the start and final merit (the sum of squared
        weighted residuals for least squares), the operand values, the evaluation count,
        ``converged``, the message, the time in seconds, ``stopped`` and the largest bound
        violation.

    Raises
    ------
    TypeError
        ``lens`` is not a Lens or ``spec`` not a DesignSpec.
    SpecError
        The spec does not fit the lens, or ``max_evaluations`` is not a whole number ≥ 1.
    """
    require_lens(lens, "lens")
    if not isinstance(spec, DesignSpec):
        raise TypeError(
            f"spec must be a DesignSpec, not {type(spec).__name__}: read it first, e.g. "
            "spec = osc.read_spec('my-spec.toml')"
        )
    if method is not None:
        spec = replace(spec, method=method)
    if spec.method == "minimax":  # it checks the spec itself
        from .minimax import minimax

        return minimax(lens, spec, progress, stop=stop, max_evaluations=max_evaluations)
    check_spec(lens, spec)
    limit = evaluation_limit(spec, max_evaluations)
    lo, hi = bounds(spec)
    x0 = start_values(lens, spec)  # a start value outside its bounds starts on the nearest bound
    sc = variable_scales(lens, spec)
    log = EvaluationLog()
    # (merit, x) of the best design evaluated so far, one object so that a Ctrl-C between two
    # statements never pairs a merit with another design's x; None until the start is evaluated
    best: list = [None]
    big = math.inf
    t0 = time.perf_counter()

    def fun(xs):
        try:
            vals = checked_evaluate(lens, spec, xs * sc, stop, log)
        except EVAL_FAILURES:
            # an impossible lens in the middle of a step: a large, smooth-ish penalty
            return np.full(len(spec.operands), big)
        r = np.array([o.residual for o in vals])
        m = float(r @ r)
        if m < best[0][0]:
            best[0] = (m, xs * sc)
        if progress is not None:
            progress(log.n, m, max(vals, key=lambda o: abs(o.residual)))
        return r

    stopped = ""
    try:
        start_vals = evaluate_start(lens, spec, x0)
        m0 = merit(start_vals)
        big = math.sqrt(m0 + 1.0) * 1e3
        best[0] = (m0, x0.copy())
        sol = least_squares(
            fun,
            x0 / sc,
            bounds=(lo / sc, hi / sc),
            method="trf",
            x_scale="jac",
            xtol=spec.tolerance,
            ftol=spec.tolerance,
            gtol=spec.tolerance,
            max_nfev=limit,
            diff_step=1e-7,
        )
        x_final, status, message = sol.x * sc, sol.status, sol.message
    except Stopped as e:
        stopped = e.reason
        x_final, status, message = best[0][1], -99, f"stopped ({e.reason}): the best design so far"
    except KeyboardInterrupt:  # Ctrl-C: as a stop, once the start is evaluated
        if best[0] is None:
            raise
        stopped = "interrupted"
        x_final, status, message = best[0][1], -99, "stopped (interrupted): the best design so far"
    final = apply(lens, spec, x_final)
    vals = evaluate(final, spec.operands, check=False)
    m = merit(vals)
    converged = status > 0
    # why scipy's least squares stopped, in the project's words (not scipy's sentence)
    why = SCIPY_STATUS_WORDS[status].format(t=spec.tolerance) if status > 0 else message
    msg = f"converged: {why}" if status > 0 else message
    if status == 0:  # scipy's max_nfev, said in our words (not scipy's sentence)
        msg = limit_message(
            f"{limit} merit evaluations of the solver's steps; {log.n} with its "
            "finite-difference Jacobians"
        )
    if stopped:
        converged = False
    elif spec.merit_goal is not None and m > spec.merit_goal:
        converged = False
        msg = f"merit {m:.6g} is above the goal {spec.merit_goal:.6g}" + (
            f": {msg}" if status == 0 else f" (the solver stopped: {why})"
        )
    return local_result(log, t0, final, x_final, m0, m, vals, converged, msg, stopped)


def max_violation(values: tuple[OperandValue, ...]) -> float:
    """The largest weighted violation of a bound operand (0 when every bound is met)."""
    return max((abs(o.residual) for o in values if o.operand.bounded), default=0.0)


def local_result(
    log: EvaluationLog,
    t0: float,
    lens: Lens,
    x,
    merit_start: float,
    merit: float,
    operands: tuple[OperandValue, ...],
    converged: bool,
    message: str,
    stopped: str,
    method: str = "least_squares",
) -> OptimizationResult:
    """The :class:`OptimizationResult` of a local run (damped least squares or minimax), its
    fields in their order less the run's bookkeeping: ``log`` gives the evaluation count and
    adds its note on failed evaluations to ``message``, ``t0`` (``time.perf_counter()`` at the
    start) the wall time, and ``operands`` the largest bound violation."""
    return OptimizationResult(
        lens=lens,
        x=np.asarray(x, dtype=float),
        merit_start=merit_start,
        merit=merit,
        operands=operands,
        evaluations=log.n,
        converged=converged,
        message=message + log.note(),
        seconds=time.perf_counter() - t0,
        stopped=stopped,
        method=method,
        violation=max_violation(operands),
    )
