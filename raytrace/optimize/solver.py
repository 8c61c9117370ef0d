"""Damped least squares on ``scipy.optimize.least_squares`` (trust-region reflective with the
variable bounds): the spec's variables applied to the start lens, the operands evaluated, the
weighted residuals minimised."""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np
from scipy.optimize import least_squares

from ..errors import OrthoscopeError
from ..lens import Lens
from ..materials import Material
from ..paraxial import paraxial
from .operands import OperandValue, evaluate, merit
from .spec import (
    ASPHERIC_KINDS,
    INDEX_BOUNDS,
    OPERAND_TYPES,
    VARIABLE_KINDS,
    DesignSpec,
    SpecError,
)

@dataclass(frozen=True)
class OptimizationResult:
    lens: Lens
    x: np.ndarray
    merit_start: float
    merit: float
    operands: tuple[OperandValue, ...]
    evaluations: int
    converged: bool
    message: str
    seconds: float

    @property
    def worst(self) -> OperandValue:
        return max(self.operands, key=lambda o: abs(o.residual))


# ----------------------------------------------------------------------------- variables
def get_value(lens: Lens, kind: str, surface: int) -> float:
    s = lens.surfaces[surface - 1]
    if kind == "curvature":
        return s.curvature
    if kind == "thickness":
        return s.thickness
    if kind == "index":
        return s.material.nd
    if kind == "conic":
        return s.conic
    if kind in ASPHERIC_KINDS:
        j = ASPHERIC_KINDS.index(kind)
        return s.aspheric[j] if j < len(s.aspheric) else 0.0
    raise SpecError(f"unknown variable kind {kind!r} (use one of {', '.join(VARIABLE_KINDS)})")


def set_values(lens: Lens, kinds_surfaces: list[tuple[str, int]], values) -> Lens:
    """A copy of ``lens`` with the given (kind, surface) parameters replaced (no validation of the
    physical sense beyond the Lens model's own)."""
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
        else:
            m = s.material
            s = replace(s, material=Material("model" if m.kind == "model" else "index", v, m.vd))
        surfaces[i - 1] = s
    return replace(lens, surfaces=tuple(surfaces), image_solve=None)


def apply(lens: Lens, spec: DesignSpec, x) -> Lens:
    """The lens with variables ``x`` and the spec's pick-ups applied.

    A start lens whose image plane is a Gaussian solve (``image_solve == "gaussian"``) keeps it:
    the last thickness is re-solved for every new lens unless it is itself a variable or pick-up.
    """
    ks = [(v.kind, v.surface) for v in spec.variables]
    out = set_values(lens, ks, x)
    if spec.pickups:
        vals = [p.factor * get_value(out, p.kind, p.source) + p.offset for p in spec.pickups]
        out = set_values(out, [(p.kind, p.surface) for p in spec.pickups], vals)
    last = ("thickness", lens.n_surfaces)
    if lens.image_solve == "gaussian" and last not in ks + [
        (p.kind, p.surface) for p in spec.pickups
    ]:
        out = replace(
            out.with_image_distance(paraxial(out).gaussian_image_distance), image_solve="gaussian"
        )
    return out


# ----------------------------------------------------------------------------- solver
def check_spec(lens: Lens, spec: DesignSpec) -> None:
    """Raise :class:`SpecError` for a spec that cannot apply to ``lens``."""
    n = lens.n_surfaces
    for v in spec.variables:
        if v.kind not in VARIABLE_KINDS:
            raise SpecError(f"unknown variable kind {v.kind!r} (use {', '.join(VARIABLE_KINDS)})")
        if not 1 <= v.surface <= n:
            raise SpecError(f"variable {v.kind} on surface {v.surface}: the lens has {n} surfaces")
        if v.lower >= v.upper:
            raise SpecError(
                f"variable {v.kind} {v.surface}: bounds inverted ({v.lower} ≥ {v.upper})"
            )
        if v.kind == "index" and lens.surfaces[v.surface - 1].material.is_air:
            raise SpecError(f"variable index {v.surface}: the medium after it is air")
    seen = {(v.kind, v.surface) for v in spec.variables}
    for pk in spec.pickups:
        if pk.kind not in VARIABLE_KINDS:
            raise SpecError(f"unknown pick-up kind {pk.kind!r}")
        for s in (pk.surface, pk.source):
            if not 1 <= s <= n:
                raise SpecError(
                    f"pick-up {pk.kind} {pk.surface} <- {pk.source}: surface {s} "
                    f"does not exist (the lens has {n})"
                )
        if (pk.kind, pk.surface) in seen:
            raise SpecError(f"{pk.kind} {pk.surface} is both a variable and a pick-up")
    if not spec.variables:
        raise SpecError("the spec has no variables")
    if not spec.operands:
        raise SpecError("the spec has no operands")
    for op in spec.operands:
        if op.type not in OPERAND_TYPES:
            raise SpecError(f"unknown operand type {op.type!r} (use {', '.join(OPERAND_TYPES)})")
        if op.type in ("distortion", "distortion_rel", "image_height") and "field" not in op.params:
            raise SpecError(f"operand {op.type} needs a 'field'")
        if op.type in ("center_thickness", "edge_thickness"):
            s = op.params.get("surface")
            last = n - 1 if op.type == "edge_thickness" else n
            if not isinstance(s, int) or not 1 <= s <= last:
                raise SpecError(
                    f"operand {op.type}: surface {s!r} does not exist (1..{last} for this lens)"
                )
            if "min" not in op.params and "max" not in op.params:
                raise SpecError(f"operand {op.type} on surface {s} needs 'min' and/or 'max'")
            if op.type == "edge_thickness" and "height" not in op.params:
                raise SpecError(f"operand edge_thickness on surface {s} needs 'height'")
        if not (math.isfinite(op.weight) and op.weight >= 0):
            raise SpecError(f"operand {op.label()}: weight must be a non-negative number")


def optimize(
    lens: Lens,
    spec: DesignSpec,
    progress: Callable[[int, float, OperandValue], None] | None = None,
) -> OptimizationResult:
    """Run damped least squares (``least_squares``, trust-region reflective with the variable
    bounds). ``progress(evaluation, merit, worst_operand)`` is called after each evaluation.

    A run that stops on the evaluation limit, or ends above ``spec.merit_goal``, is returned with
    ``converged=False`` and a message saying why; the caller must not present it as a success.
    """
    check_spec(lens, spec)
    x0 = np.array([get_value(lens, v.kind, v.surface) for v in spec.variables])
    lo = np.array(
        [max(v.lower, INDEX_BOUNDS[0]) if v.kind == "index" else v.lower for v in spec.variables]
    )
    hi = np.array(
        [min(v.upper, INDEX_BOUNDS[1]) if v.kind == "index" else v.upper for v in spec.variables]
    )
    x0 = np.clip(x0, lo, hi)  # a start value outside its bounds starts on the nearest bound
    # The solver works on x / scale: aspheric coefficients are tiny numbers (mm^(1-k)), scaled
    # so that a unit change is a sag change of the order of a tenth of the EFL at a tenth of the
    # EFL; every other kind is left unscaled.
    rref = 0.1 * abs(paraxial(lens).efl)
    sc = np.array(
        [
            rref ** (1 - (4 + 2 * ASPHERIC_KINDS.index(v.kind)))
            if v.kind in ASPHERIC_KINDS
            else 1.0
            for v in spec.variables
        ]
    )
    start_vals = evaluate(apply(lens, spec, x0), spec.operands)
    m0 = merit(start_vals)
    n_ev = [0]
    big = math.sqrt(m0 + 1.0) * 1e3
    t0 = time.perf_counter()

    def fun(xs):
        n_ev[0] += 1
        try:
            vals = evaluate(apply(lens, spec, xs * sc), spec.operands)
        except (OrthoscopeError, ValueError, ZeroDivisionError, FloatingPointError):
            # an impossible lens in the middle of a step: a large, smooth-ish penalty
            return np.full(len(spec.operands), big)
        r = np.array([o.residual for o in vals])
        if progress is not None:
            progress(n_ev[0], float(r @ r), max(vals, key=lambda o: abs(o.residual)))
        return r

    sol = least_squares(
        fun,
        x0 / sc,
        bounds=(lo / sc, hi / sc),
        method="trf",
        x_scale="jac",
        xtol=spec.tolerance,
        ftol=spec.tolerance,
        gtol=spec.tolerance,
        max_nfev=spec.max_evaluations,
        diff_step=1e-7,
    )
    x_final = sol.x * sc
    final = apply(lens, spec, x_final)
    vals = evaluate(final, spec.operands)
    m = merit(vals)
    converged = sol.status > 0
    msg = sol.message
    if spec.merit_goal is not None and m > spec.merit_goal:
        converged = False
        msg = f"merit {m:.6g} is above the goal {spec.merit_goal:.6g} ({sol.message})"
    elif sol.status == 0:
        msg = f"stopped at the evaluation limit ({spec.max_evaluations}) before converging"
    return OptimizationResult(
        lens=final,
        x=x_final,
        merit_start=m0,
        merit=m,
        operands=vals,
        evaluations=n_ev[0],
        converged=converged,
        message=msg,
        seconds=time.perf_counter() - t0,
    )


