"""Damped-least-squares lens optimization on ``scipy.optimize.least_squares``.

A design is a :class:`DesignSpec` — variables (curvature, thickness, index, conic and the
even-asphere coefficients A4–A10 of 1-based surfaces, with bounds), pick-ups (e.g. a curvature that
follows another with factor −1), and operands with targets and weights — usually read
from a TOML spec file (:func:`read_spec`). :func:`optimize` runs it and returns a
:class:`OptimizationResult`; nothing is written unless the caller writes the lens.

Operand types (all lengths in mm, angles in degrees, signs as in DESIGN.md §3):

==================  ==========================================================================
``efl``             equivalent focal length.
``m_e``             Pestrecov's m_e (Eq. 6).
``HE0``, ``HpE0p``  paraxial entrance / exit pupil from the principal points (Table III).
``distortion``      characteristic linear distortion D0 = y' − F0 tan α (or y' − M0 y) at
                    ``field`` in the image ``plane`` (Pestrecov Eqs. 8–9), real chief ray.
``distortion_rel``  the same as a relative distortion Dr (fraction, not %).
``image_height``    real chief-ray image height y' at ``field`` in ``plane``.
``best_focus``      the plane of least RMS spot for a ``field`` bundle (default on axis) at
                    ``aperture`` (fraction of the pupil radius), given as s' from H'.
``rms_spot``        RMS spot radius at ``field`` in ``plane`` (``plane = "best"``: at the plane
                    of least RMS spot of that bundle).
``center_thickness``  one-sided: thickness of ``surface`` ≥ ``min`` (and/or ≤ ``max``).
``edge_thickness``    one-sided: axial gap at height ``height`` between ``surface`` and the
                    next surface ≥ ``min``.
==================  ==========================================================================

``plane`` is ``"gaussian"`` (default), ``"file"`` (the lens file's image plane), or a table with
one of ``s_prime`` (from H'), ``from_vertex`` (from the last vertex) or ``defocus`` (from the
Gaussian plane). ``object_distance`` on an operand overrides the lens's (a positive magnitude
from the first vertex, or "inf").
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
import tomllib
from scipy.optimize import least_squares

from .errors import LensError, OrthoscopeError, PrescriptionError, TraceError
from .lens import Lens, pack
from .materials import Material
from .paraxial import ParaxialResult, paraxial, pestrecov_constants

VARIABLE_KINDS = ("curvature", "thickness", "index", "conic", "A4", "A6", "A8", "A10")
ASPHERIC_KINDS = ("A4", "A6", "A8", "A10")  # coefficients of r^4, r^6, r^8, r^10
OPERAND_TYPES = (
    "efl",
    "m_e",
    "HE0",
    "HpE0p",
    "distortion",
    "distortion_rel",
    "image_height",
    "best_focus",
    "rms_spot",
    "center_thickness",
    "edge_thickness",
)
INDEX_BOUNDS = (1.40, 2.05)  # glass-like bounds for index variables


class SpecError(OrthoscopeError):
    """A design spec is invalid (unknown variable, operand on a missing surface, bad bounds)."""


@dataclass(frozen=True)
class Variable:
    """A free parameter: ``kind`` of ``surface`` (1-based), within [lower, upper]."""

    kind: str
    surface: int
    lower: float = -math.inf
    upper: float = math.inf


@dataclass(frozen=True)
class Pickup:
    """``kind`` of ``surface`` := factor × (``kind`` of ``source``) + offset, applied after the
    variables (e.g. ``R5 = −R4`` is curvature 5 = −1 × curvature 4)."""

    kind: str
    surface: int
    source: int
    factor: float = 1.0
    offset: float = 0.0


@dataclass(frozen=True)
class Operand:
    """A target: ``type`` (see module docstring), ``target``, ``weight`` and its parameters."""

    type: str
    target: float = 0.0
    weight: float = 1.0
    params: dict = field(default_factory=dict)

    def label(self) -> str:
        extra = ", ".join(f"{k}={v}" for k, v in self.params.items())
        return f"{self.type}({extra})" if extra else self.type


@dataclass(frozen=True)
class DesignSpec:
    """A reproducible design: start lens, variables, pick-ups, operands, solver settings."""

    start: str
    variables: tuple[Variable, ...]
    operands: tuple[Operand, ...]
    pickups: tuple[Pickup, ...] = ()
    name: str = ""
    max_evaluations: int = 2000
    tolerance: float = 1e-12
    merit_goal: float | None = None  # a run that ends above it is reported as failed
    path: str | None = None


@dataclass(frozen=True)
class OperandValue:
    operand: Operand
    value: float
    residual: float  # weight × (value − target) (one-sided operands: weight × violation)


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


# ----------------------------------------------------------------------------- operands
def _plane_z(par: ParaxialResult, plane) -> float:
    if plane is None or plane == "gaussian":
        return par.z_gauss
    if plane == "file":
        return par.z_image_file
    if isinstance(plane, dict) and len(plane) == 1:
        ((k, v),) = plane.items()
        if k == "s_prime":
            return par.z_from_s_prime(float(v))
        if k == "from_vertex":
            return par.z_from_last_vertex(float(v))
        if k == "defocus":
            return par.z_from_defocus(float(v))
    raise SpecError(
        f'bad plane {plane!r}: use "gaussian", "file" or {{s_prime|from_vertex|defocus = mm}}'
    )


def _object_distance(lens: Lens, op: Operand) -> float:
    od = op.params.get("object_distance")
    if od is None:
        return lens.object_distance
    if isinstance(od, str) and od.strip().lower() in ("inf", "infinity"):
        return math.inf
    return float(od)


def _bundle(
    lens: Lens,
    par: ParaxialResult,
    field_value: float,
    kind: str,
    aperture: float,
    n_ring: int = 10,
    per_ring: int = 24,
):
    """A pupil grid of rays for one field: start arrays for trace_rays.

    Equal-area rings (the midpoint rule in ρ²): ring k = 1..n_ring at ρ = aperture·√((k − ½)/n),
    ``per_ring`` rays each (alternate rings rotated by half a step), so every ray stands for the
    same pupil area and RMS / best-focus estimates are those of a uniformly filled pupil. (A
    hexapolar grid with a ring on the rim over-weights the rim: for a lens with strong
    spherical aberration it moved the least-RMS focus by ~1 % of s'.)
    """
    k = np.arange(1, n_ring + 1)
    rho = np.repeat(aperture * np.sqrt((k - 0.5) / n_ring), per_ring)
    step = 2 * np.pi / per_ring
    theta = np.tile(np.arange(per_ring) * step, n_ring) + np.repeat((k % 2) * 0.5 * step, per_ring)
    a = par.epd / 2.0
    px, py = a * rho * np.cos(theta), a * rho * np.sin(theta)
    zE = par.z_E0
    if par.infinite:
        t = math.tan(math.radians(field_value))
        L = np.zeros_like(px)
        M = np.full_like(px, t / math.sqrt(1 + t * t))
        N = np.full_like(px, 1.0 / math.sqrt(1 + t * t))
        x0, y0 = px, py
    else:
        if kind == "angle":
            yobj = par.p0 * math.tan(math.radians(field_value))
        else:
            yobj = field_value
        dx, dy, dz = px, py - yobj, zE - par.z_object
        nrm = np.sqrt(dx * dx + dy * dy + dz * dz)
        L, M, N = dx / nrm, dy / nrm, dz / nrm
        x0, y0 = px, py
    # start left of every surface: back along each ray to a plane before the first vertex
    z_start = -(abs(zE) + 2.0 * a + float(np.max(np.abs(y0))) + 1.0)
    s = (z_start - zE) / N
    return x0 + s * L, y0 + s * M, np.full_like(px, z_start), L, M, N


def _spot_stats(batch):
    """Linear model of x, y versus z for the OK rays: (a_x, b_x, a_y, b_y), x = a + b z."""
    ok = batch.status == 0
    if ok.sum() < 3:
        raise TraceError("too few rays pass the lens to evaluate a spot")
    bx = batch.L[ok] / batch.N[ok]
    by = batch.M[ok] / batch.N[ok]
    ax = batch.x[ok] - bx * batch.z[ok]
    ay = batch.y[ok] - by * batch.z[ok]
    return ax, bx, ay, by


def _rms_at(stats, z: float) -> float:
    ax, bx, ay, by = stats
    x, y = ax + bx * z, ay + by * z
    return float(np.sqrt(np.mean((x - x.mean()) ** 2 + (y - y.mean()) ** 2)))


def _best_focus_z(stats) -> float:
    """The z of least RMS spot: the variance of a + b z is quadratic in z, so it is exact."""
    ax, bx, ay, by = stats
    cov = np.mean((ax - ax.mean()) * (bx - bx.mean())) + np.mean(
        (ay - ay.mean()) * (by - by.mean())
    )
    var = np.var(bx) + np.var(by)
    if var == 0:
        raise TraceError("all rays are parallel after the lens: no best focus")
    return float(-cov / var)


def evaluate(lens: Lens, operands: tuple[Operand, ...]) -> tuple[OperandValue, ...]:
    """Compute every operand for ``lens``. Chief rays are batched: one kernel call per
    (object distance, field kind) for all fields of all distortion / image-height operands."""
    from .trace import chief_rays, trace_rays

    pars: dict[float, ParaxialResult] = {}
    packed = None

    def par_for(od: float) -> ParaxialResult:
        if od not in pars:
            pars[od] = paraxial(lens, od)
        return pars[od]

    # batch chief rays
    groups: dict[tuple[float, str], list[float]] = {}
    for op in operands:
        if op.type in ("distortion", "distortion_rel", "image_height"):
            od = _object_distance(lens, op)
            kind = op.params.get("field_kind", "angle" if math.isinf(od) else lens.field.kind)
            groups.setdefault((od, kind), []).append(float(op.params["field"]))
    chief = {}
    for (od, kind), fl in groups.items():
        fields = np.array(sorted(set(fl)))
        cr = chief_rays(lens, fields, field_kind=kind, object_distance=od)
        chief[(od, kind)] = (fields, cr)

    out = []
    for op in operands:
        t = op.type
        p = op.params
        if t in ("efl", "m_e", "HE0", "HpE0p"):
            par = par_for(_object_distance(lens, op))
            v = {"efl": par.efl, "m_e": par.m_e, "HE0": par.HE0, "HpE0p": par.HpE0p}[t]
        elif t in ("distortion", "distortion_rel", "image_height"):
            od = _object_distance(lens, op)
            par = par_for(od)
            kind = p.get("field_kind", "angle" if math.isinf(od) else lens.field.kind)
            fields, cr = chief[(od, kind)]
            j = int(np.searchsorted(fields, float(p["field"])))
            z = _plane_z(par, p.get("plane"))
            if cr.status[j] != 0:
                raise TraceError(f"{op.label()}: the chief ray fails (status {int(cr.status[j])})")
            y_real = float(cr.heights_at(z)[j])
            if t == "image_height":
                v = y_real
            else:
                c = pestrecov_constants(par, z - par.z_Hp)
                if par.infinite:
                    ideal = c.scale * math.tan(math.radians(fields[j]))
                else:
                    y_obj = (
                        par.p0 * math.tan(math.radians(fields[j])) if kind == "angle" else fields[j]
                    )
                    ideal = c.scale * y_obj
                v = (
                    y_real - ideal
                    if t == "distortion"
                    else (y_real / ideal - 1.0 if ideal else 0.0)
                )
        elif t in ("best_focus", "rms_spot"):
            od = _object_distance(lens, op)
            par = par_for(od)
            kind = p.get("field_kind", "angle" if math.isinf(od) else lens.field.kind)
            rays = _bundle(
                lens, par, float(p.get("field", 0.0)), kind, float(p.get("aperture", 1.0))
            )
            packed = packed or pack(lens)  # once per evaluation, for every spot operand
            batch = trace_rays(packed, *rays, clip=False)
            stats = _spot_stats(batch)
            if t == "best_focus":
                v = _best_focus_z(stats) - par.z_Hp
            else:
                plane = p.get("plane")
                z = _best_focus_z(stats) if plane == "best" else _plane_z(par, plane)
                v = _rms_at(stats, z)
        elif t == "center_thickness":
            v = lens.surfaces[int(p["surface"]) - 1].thickness
        elif t == "edge_thickness":
            i = int(p["surface"]) - 1
            h = float(p["height"])
            v = float(
                lens.surfaces[i].thickness + lens.surfaces[i + 1].sag(h) - lens.surfaces[i].sag(h)
            )
            if math.isnan(v):
                raise TraceError(f"{op.label()}: height {h} is beyond the surface's sphere")
        else:  # pragma: no cover - validated in read_spec / check_spec
            raise SpecError(f"unknown operand type {t!r}")
        if t in ("center_thickness", "edge_thickness"):
            lo, hi = p.get("min", -math.inf), p.get("max", math.inf)
            viol = (lo - v) if v < lo else ((v - hi) if v > hi else 0.0)
            res = op.weight * viol
        else:
            res = op.weight * (v - op.target)
        out.append(OperandValue(op, float(v), float(res)))
    return tuple(out)


def merit(values: tuple[OperandValue, ...]) -> float:
    """Merit function: the sum of squared weighted residuals."""
    return float(sum(o.residual**2 for o in values))


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


# ----------------------------------------------------------------------------- spec files
def _num(d: dict, key: str, where: str, default=None) -> float:
    v = d.get(key, default)
    if v is None:
        raise SpecError(f"{where}: missing '{key}'")
    if isinstance(v, str) and v.strip().lower() in ("inf", "-inf"):
        return float(v)
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        raise SpecError(f"{where}: '{key}' must be a number, got {v!r}")
    return float(v)


def read_spec(path: str | Path) -> DesignSpec:
    """Read a TOML design spec (see ``lenses/*.spec.toml`` for examples)::

    name = "my-design"
    start = "cooke-triplet-f4"        # bundled name or a path relative to the spec
    max_evaluations = 500
    merit_goal = 1e-6                 # optional: above it the run is a failure
    variables = [
      { kind = "curvature", surface = 1 },
      { kind = "thickness", surface = 2, min = 0.5, max = 12 },
    ]
    pickups = [ { kind = "curvature", surface = 6, source = 1, factor = -1 } ]
    operands = [
      { type = "efl", target = 50.0, weight = 10 },
      { type = "distortion", field = 20, target = 0.0, plane = "gaussian" },
    ]
    """
    p = Path(path)
    try:
        raw = p.read_bytes()
        d = tomllib.loads(raw.decode("utf-8"))
    except FileNotFoundError:
        raise SpecError(f"{p}: no such spec file") from None
    except UnicodeDecodeError:
        raise SpecError(f"{p}: not a UTF-8 text file") from None
    except tomllib.TOMLDecodeError as e:
        raise SpecError(f"{p}: {e}") from None
    known = {
        "name",
        "start",
        "variables",
        "pickups",
        "operands",
        "max_evaluations",
        "tolerance",
        "merit_goal",
        "notes",
    }
    for k in d:
        if k not in known:
            raise SpecError(f"{p}: unknown key {k!r} (known: {', '.join(sorted(known))})")
    if "start" not in d or not isinstance(d["start"], str):
        raise SpecError(f"{p}: 'start' (the start lens: bundled name or path) is required")
    variables = []
    for i, v in enumerate(d.get("variables", []), 1):
        w = f"{p}: variables[{i}]"
        if not isinstance(v, dict) or "kind" not in v or "surface" not in v:
            raise SpecError(f"{w}: needs 'kind' and 'surface'")
        extra = set(v) - {"kind", "surface", "min", "max"}
        if extra:
            raise SpecError(f"{w}: unknown key(s) {', '.join(sorted(extra))}")
        variables.append(
            Variable(
                str(v["kind"]),
                int(_num(v, "surface", w)),
                _num(v, "min", w, -math.inf),
                _num(v, "max", w, math.inf),
            )
        )
    pickups = []
    for i, v in enumerate(d.get("pickups", []), 1):
        w = f"{p}: pickups[{i}]"
        if not isinstance(v, dict):
            raise SpecError(f"{w}: must be a table")
        pickups.append(
            Pickup(
                str(v.get("kind", "")),
                int(_num(v, "surface", w)),
                int(_num(v, "source", w)),
                _num(v, "factor", w, 1.0),
                _num(v, "offset", w, 0.0),
            )
        )
    operands = []
    for i, o in enumerate(d.get("operands", []), 1):
        w = f"{p}: operands[{i}]"
        if not isinstance(o, dict) or "type" not in o:
            raise SpecError(f"{w}: needs 'type'")
        params = {k: v for k, v in o.items() if k not in ("type", "target", "weight")}
        operands.append(
            Operand(str(o["type"]), _num(o, "target", w, 0.0), _num(o, "weight", w, 1.0), params)
        )
    return DesignSpec(
        start=d["start"],
        variables=tuple(variables),
        operands=tuple(operands),
        pickups=tuple(pickups),
        name=str(d.get("name", p.stem)),
        max_evaluations=int(d.get("max_evaluations", 2000)),
        tolerance=float(d.get("tolerance", 1e-12)),
        merit_goal=None if d.get("merit_goal") is None else float(d["merit_goal"]),
        path=str(p),
    )


def start_lens(spec: DesignSpec) -> Lens:
    """Load the spec's start lens (a path relative to the spec file, or a bundled name)."""
    from .library import load_lens

    if spec.path is not None:
        cand = Path(spec.path).parent / spec.start
        if cand.is_file():
            return load_lens(str(cand))
    try:
        return load_lens(spec.start)
    except PrescriptionError as e:
        raise SpecError(f"start lens {spec.start!r}: {e}") from None


__all__ = [
    "DesignSpec",
    "LensError",
    "Operand",
    "OperandValue",
    "OptimizationResult",
    "Pickup",
    "SpecError",
    "Variable",
    "apply",
    "check_spec",
    "evaluate",
    "merit",
    "optimize",
    "read_spec",
    "start_lens",
]
