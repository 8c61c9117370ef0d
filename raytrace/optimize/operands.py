"""Damped-least-squares lens optimization on ``scipy.optimize.least_squares``.

A design is a :class:`DesignSpec` — variables (curvature, thickness, index, conic and the
even-asphere coefficients A4–A10 of 1-based surfaces, with bounds), pick-ups (e.g. a curvature that
follows another with factor −1), and operands with targets and weights — usually read
from a TOML spec file (:func:`read_spec`). :func:`optimize` runs it and returns a
:class:`OptimizationResult`; nothing is written unless the caller writes the lens.

Operand types (all lengths in mm, angles in degrees, signs as in docs/design.md, "Conventions"):

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
from dataclasses import dataclass

import numpy as np

from ..errors import TraceError
from ..lens import Lens
from ..packing import pack
from ..paraxial import (
    ImagePlane,
    ParaxialResult,
    ideal_heights,
    orthoscopy_abscissa,
    paraxial,
    resolve_object_distance,
)
from .spec import Operand, SpecError

@dataclass(frozen=True)
class OperandValue:
    operand: Operand
    value: float
    residual: float  # weight × (value − target) (one-sided operands: weight × violation)


# ----------------------------------------------------------------------------- operands
def spec_plane(plane) -> ImagePlane:
    """A spec's ``plane``: ``"gaussian"`` (default), ``"file"`` or a one-key table
    ``{s_prime | from_last_vertex | defocus = mm}`` (``from_vertex`` is the old spelling of
    ``from_last_vertex``)."""
    if plane is None or plane in ("gaussian", "file"):
        return ImagePlane(plane or "gaussian")
    if isinstance(plane, dict) and len(plane) == 1:
        ((k, v),) = plane.items()
        k = "from_last_vertex" if k == "from_vertex" else k
        if k in ("s_prime", "from_last_vertex", "defocus") and isinstance(v, (int, float)):
            return ImagePlane(k, float(v))
    raise SpecError(
        f'bad plane {plane!r}: use "gaussian", "file" or {{s_prime|from_last_vertex|defocus = mm}}'
    )


def _plane_z(par: ParaxialResult, plane) -> float:
    return spec_plane(plane).z(par)


def _object_distance(lens: Lens, op: Operand) -> float:
    """The operand's object: ``object_distance`` (mm from the first vertex, ``inf`` or ``"12x"``),
    ``object_s`` or ``object_scale`` (docs/design.md, "Vocabulary"); default the lens's."""
    p = op.params
    try:
        return resolve_object_distance(
            lens,
            object_distance=p.get("object_distance"),
            object_s=p.get("object_s"),
            object_scale=p.get("object_scale"),
        )
    except TraceError as e:
        raise SpecError(f"operand {op.label()}: {e}") from None


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
    from ..trace import aim, trace_rays

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
        cr = aim(lens, fields, kind, od)
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
            else:  # Pestrecov Eqs. 8-9: D0 = y' - K0 x in the plane z
                x = orthoscopy_abscissa(par, fields[j], kind)
                ideal = float(ideal_heights(par, x, par.s_prime_of(z)))
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
            batch = trace_rays(packed, rays[:3], rays[3:], clip=False)
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


