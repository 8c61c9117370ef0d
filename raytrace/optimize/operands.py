"""Operands: what a design spec can target, computed for a lens by :func:`evaluate`.

Operand types (all lengths in mm, angles in degrees, wavelengths in nm, signs as in
docs/design.md, "Conventions"; the spec language is documented in ``docs/spec.md``):

====================  ========================================================================
``efl``               equivalent focal length.
``m_e``               Pestrecov's m_e (Eq. 6).
``HE0``, ``HpE0p``    paraxial entrance / exit pupil from the principal points (Table III).
``distortion``        characteristic linear distortion D0 = y' − F0 tan α (or y' − M0 y) at
                      ``field`` in the image ``plane`` (Pestrecov Eqs. 8–9), real chief ray.
``distortion_rel``    the same as a relative distortion Dr (fraction, not %).
``distortion_slope``  ∂D0/∂s' at ``field`` for the operand's object (mm per mm of s'): D0 is
                      affine in s' for a fixed object (straight final segment, M0 affine in s',
                      Eq. 8), so the slope is exact and the same in every plane.
``image_height``      real chief-ray image height y' at ``field`` in ``plane``.
``landing_angle``     angle of the real chief ray with the axis after the last surface, degrees,
                      signed like its direction cosine M (0 = telecentric in image space).
``best_focus``        the plane of least RMS spot for a ``field`` bundle (default on axis) at
                      ``aperture`` (fraction of the pupil radius), given as s' from H'.
``rms_spot``          RMS spot radius at ``field`` in ``plane`` (``plane = "best"``: at the plane
                      of least RMS spot of that bundle). Every ray of a ``best_focus`` or
                      ``rms_spot`` bundle must pass: a failing ray is an evaluation error,
                      unless the operand says ``drop_failed = true`` (left out, as vignetted).
``ray_height``        distance from the axis (mm, ≥ 0) at which one real ray meets ``surface``: the
                      ray from ``field`` through ``pupil = [px, py]`` (fractions of the paraxial
                      entrance-pupil radius, centred on the axis; default [0, 1], the upper rim
                      of the meridional section), built as the spot operands' rays; as a
                      ``max`` bound it keeps a footprint inside a clear aperture.
``element_power``     paraxial power (1/mm) of the surfaces ``surface`` .. ``last`` (default
                      ``surface + 1``: an element in air; refused inside a cemented group),
                      :func:`raytrace.paraxial.element_power`.
``axial_color``       paraxial axial colour: the Gaussian image plane at ``wavelengths[0]`` minus
                      the one at ``wavelengths[1]`` (default F 486.1327 − C 656.2725 nm), mm.
``center_thickness``  axial thickness after ``surface``.
``edge_thickness``    axial gap at height ``height`` between ``surface`` and the next surface.
====================  ========================================================================

Every operand has a ``target`` or is one-sided with ``min`` and/or ``max`` (in its unit;
:attr:`Operand.bounded`): its residual is then the weighted violation of the bounds
(:meth:`Operand.residual`).

``plane`` is ``"gaussian"`` (default), ``"file"`` (the lens file's image plane), or a table with
one of ``s_prime`` (from H'), ``from_last_vertex`` (from the last vertex; ``from_vertex`` is
the old spelling) or ``defocus`` (from the Gaussian plane). The object of an operand is the
lens's unless it gives ``object_distance`` (a positive magnitude from the first vertex, "inf"
or "Nx"), ``object_s`` (Pestrecov's s from H) or ``object_scale``. ``wavelength`` (nm) defaults
to the lens's.

Chief rays are aimed once per evaluation for each (object, field kind, wavelength): one kernel
call for all the fields of all the chief-ray operands of that object, and each image plane is
reached by moving the final segments analytically (as :mod:`raytrace.trace` does), so targets in
several planes for one object cost one trace.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import TraceError
from ..kernels.codes import STATUS_AIM_FAILED, STATUS_NAMES, STATUS_TIR, status_message
from ..lens import Lens
from ..packing import pack
from ..paraxial import (
    ImagePlane,
    ParaxialResult,
    distortion_slope,
    element_power,
    ideal_heights,
    orthoscopy_abscissa,
    paraxial,
    resolve_object_distance,
)
from .spec import SURFACE_OPERANDS, Operand, SpecError, operand_problems


@dataclass(frozen=True)
class OperandValue:
    operand: Operand
    value: float
    residual: float  # weight × (value − target) (one-sided operands: weight × violation)


class ChiefRayError(TraceError):
    """The real chief ray of a chief-ray operand fails on the lens evaluated.

    Attributes
    ----------
    problem : str
        ``LABEL: the chief ray fails (WORD: what happened)`` without the fix, for a caller that
        knows a better one (the command line, for a start lens it edited); the message is
        ``problem; FIX``.
    status, surface : int
        The ray's status code (:data:`raytrace.kernels.codes.STATUS_NAMES`) and the 1-based
        surface where it failed (0 when unknown, as for ``aim_failed``).
    """

    #: what to do, for any lens: the field is the operand's, the lens the one evaluated
    FIX = "lower the operand's field, or change the lens so that it passes that field"

    def __init__(self, label: str, status: int, surface: int = 0) -> None:
        word = STATUS_NAMES.get(status, f"status {status}")
        if status == STATUS_AIM_FAILED:  # the kernel keeps no surface: say what it means
            why = (
                "the aim found no ray from this field through the stop centre that passes "
                "every surface"
            )
        else:
            why = status_message(status, surface)
        self.problem = f"{label}: the chief ray fails ({word}: {why})"
        self.status, self.surface = status, surface
        super().__init__(f"{self.problem}; {self.FIX}")


# ----------------------------------------------------------------------------- operands
def spec_plane(plane) -> ImagePlane:
    """A spec's ``plane``: ``"gaussian"`` (default), ``"file"`` or a one-key table
    ``{s_prime | from_last_vertex | defocus = LENGTH}`` (``from_vertex`` is the old spelling of
    ``from_last_vertex``): a number in mm or a string with its unit (``"50.5mm"``), read by
    :class:`~raytrace.paraxial.ImagePlane` as given. A value it refuses is a :class:`SpecError`
    with its message (the callers name the operand)."""
    if plane is None or plane in ("gaussian", "file"):
        return ImagePlane(plane or "gaussian")
    if isinstance(plane, dict) and len(plane) == 1:
        ((key, v),) = plane.items()
        k = "from_last_vertex" if key == "from_vertex" else key
        if k in ("s_prime", "from_last_vertex", "defocus"):
            if isinstance(v, bool):  # a TOML true is no length (ImagePlane would read 1 mm)
                raise SpecError(
                    f"plane {key}: {v!r} is not a length; give mm or a length with its unit, "
                    "e.g. 50.5mm"
                )
            try:
                return ImagePlane(k, v)
            except TraceError as e:  # its message starts with the kind: say the key as written
                msg = str(e)
                rest = msg[len(k) :] if msg.startswith(k) else f": {msg}"
                raise SpecError(f"plane {key}{rest}") from None
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


def _pupil_rays(
    par: ParaxialResult, field_value: float, kind: str, px: np.ndarray, py: np.ndarray
) -> tuple[np.ndarray, ...]:
    """Rays from one field through points of the paraxial entrance pupil: start arrays for
    trace_rays / ray_paths, ``(x, y, z, L, M, N)``.

    ``px``, ``py`` are the points in mm in the pupil plane z_E0, centred on the axis (a point at
    fraction ρ of the pupil radius lies at ρ ``par.epd / 2``); +y is the side of the field's
    image for a positive field. An object at infinity sends parallel rays at the field angle; a
    finite object sends them from the object point (``kind`` "angle": nominal angle, height
    p0 tan α; "height": object height in mm). Every ray starts on one plane before the first
    vertex.
    """
    if kind == "angle" and not abs(field_value) < 90.0:
        raise TraceError(
            f"field {field_value:g} deg: field angles must lie strictly between -90 and 90 degrees"
        )
    if kind == "height" and par.infinite:
        raise TraceError(
            f"field {field_value:g} mm: object heights need a finite object distance "
            "(give object_distance, object_s or object_scale, or an angle)"
        )
    a = par.epd / 2.0
    px, py = np.asarray(px, float), np.asarray(py, float)
    zE = par.z_E0
    if par.infinite:
        t = math.tan(math.radians(field_value))
        L = np.zeros_like(px)
        M = np.full_like(px, t / math.sqrt(1 + t * t))
        N = np.full_like(px, 1.0 / math.sqrt(1 + t * t))
    else:
        if kind == "angle":
            yobj = par.p0 * math.tan(math.radians(field_value))
        else:
            yobj = field_value
        dx, dy, dz = px, py - yobj, zE - par.z_object
        nrm = np.sqrt(dx * dx + dy * dy + dz * dz)
        L, M, N = dx / nrm, dy / nrm, dz / nrm
    # start left of every surface: back along each ray to a plane before the first vertex
    z_start = -(abs(zE) + 2.0 * a + float(np.max(np.abs(py))) + 1.0)
    s = (z_start - zE) / N
    return px + s * L, py + s * M, np.full_like(px, z_start), L, M, N


def _bundle(
    par: ParaxialResult,
    field_value: float,
    kind: str,
    aperture: float,
    n_ring: int = 10,
    per_ring: int = 24,
):
    """A pupil grid of rays for one field (:func:`_pupil_rays`): start arrays for trace_rays.

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
    return _pupil_rays(par, field_value, kind, a * rho * np.cos(theta), a * rho * np.sin(theta))


def _spot_stats(batch, label: str, drop_failed: bool = False):
    """Linear model of x, y versus z of a bundle's rays: (a_x, b_x, a_y, b_y), x = a + b z.

    Every ray must pass (the bundle is traced without clipping): a ray that misses a surface,
    is totally reflected or travels backwards raises :class:`TraceError` naming the first such
    ray's fate. A spot of the rays that pass would hide them, and an optimizer would learn to
    lower an RMS by making rays fail. ``drop_failed`` (the operand's ``drop_failed = true``)
    leaves failed rays out instead, as vignetted (at least 3 rays must pass).
    """
    ok = batch.status == 0
    if drop_failed:
        if ok.sum() < 3:
            raise TraceError(f"{label}: too few rays pass the lens to evaluate a spot")
    elif not ok.all():
        j = int(np.flatnonzero(~ok)[0])
        raise TraceError(
            f"{label}: {int((~ok).sum())} of {ok.size} rays of the bundle fail (first: "
            f"{status_message(int(batch.status[j]), int(batch.surface[j]))}); reduce "
            "'aperture' or change the lens"
        )
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


_CHIEF_TYPES = ("distortion", "distortion_rel", "image_height", "distortion_slope", "landing_angle")
LAMBDA_F, LAMBDA_C = 486.1327, 656.2725  # nm, hydrogen F and C lines


def _wavelength(op: Operand) -> float | None:
    w = op.params.get("wavelength")
    return None if w is None else float(w)


def _field_kind(lens: Lens, op: Operand, od: float) -> str:
    return op.params.get("field_kind", "angle" if math.isinf(od) else lens.field.kind)


def _ray_heights(lens: Lens, ops: list[Operand], par_for, pack_for) -> dict[int, float]:
    """The ``ray_height`` operands' values, keyed by ``id(operand)``: one ray each
    (:func:`_pupil_rays`, pupil point ``pupil``), all of one wavelength traced in one
    :func:`~raytrace.trace.ray_paths` call without clipping (``par_for(od, wl)``,
    ``pack_for(wl)``: the evaluation's paraxial data and packed lenses). A ray that fails
    before it reaches its ``surface`` raises :class:`TraceError` naming its fate."""
    from ..trace import ray_paths

    by_wl: dict[float | None, list[tuple[Operand, tuple[np.ndarray, ...]]]] = {}
    for op in ops:
        p = op.params
        od = _object_distance(lens, op)
        wl = _wavelength(op)
        px, py = p.get("pupil", (0.0, 1.0))
        par = par_for(od, wl)
        a = par.epd / 2.0
        rays = _pupil_rays(
            par, float(p.get("field", 0.0)), _field_kind(lens, op, od), [a * px], [a * py]
        )
        by_wl.setdefault(wl, []).append((op, rays))
    out: dict[int, float] = {}
    for wl, items in by_wl.items():
        starts = [np.concatenate([r[k] for _, r in items]) for k in range(6)]
        paths = ray_paths(pack_for(wl), starts[:3], starts[3:])
        for j, (op, _) in enumerate(items):
            i = int(op.params["surface"]) - 1
            x, y = paths.x[j, i], paths.y[j, i]
            if not (math.isfinite(x) and math.isfinite(y)):
                st, at = int(paths.status[j]), int(paths.surface[j])
                fate = (  # reflected totally at the surface itself: it did reach it
                    "is totally reflected at"
                    if st == STATUS_TIR and at == i + 1
                    else "does not reach"
                )
                why = status_message(st, at)
                raise TraceError(f"{op.label()}: the ray {fate} surface {i + 1} ({why})")
            out[id(op)] = math.hypot(x, y)
    return out


def operand_lens_problems(lens: Lens, op: Operand) -> list[str]:
    """What makes a well-formed operand (:func:`~raytrace.optimize.spec.operand_problems` found
    nothing) impossible on ``lens``: a surface it names that the lens lacks (or that rays do not
    meet), a run of surfaces that ends inside glass by default, a field the object cannot have.
    Empty when it applies."""
    n = lens.n_surfaces
    p = op.params
    out: list[str] = []
    if op.type in SURFACE_OPERANDS:
        s = p["surface"]
        pair = op.type == "edge_thickness" or (op.type == "element_power" and "last" not in p)
        last = n - 1 if pair else n  # the surface and the next one
        if pair and s == n:
            out.append(
                f"surface {s} is the last; it needs the next surface"
                + (" (give 'last' for a run of surfaces)" if op.type == "element_power" else "")
            )
        elif not 1 <= s <= last:
            out.append(f"surface {s!r} does not exist (1..{last} for this lens)")
        elif not p.get("last", s) <= n:
            out.append(f"last surface {p['last']!r} does not exist (the lens has {n})")
        elif op.type in ("ray_height", "element_power") and lens.surfaces[s - 1].coordinate_break:
            out.append(
                f"surface {s} is a coordinate break (not traced); name "
                + (
                    "a surface rays meet"
                    if op.type == "ray_height"
                    else "the element's first surface"
                )
            )
        elif (
            op.type == "element_power"
            and "last" not in p
            and not (
                lens.surfaces[s].material.is_air
                and (s == 1 or lens.surfaces[s - 2].material.is_air)
            )
        ):
            out.append(
                f"surfaces {s}-{s + 1} are not an element in air (glass before or after them: "
                "a cemented group); give 'last' for the run of surfaces whose power you mean, e.g. "
                "the whole group, which is then taken between the media around it"
            )
    if "field" in p:
        try:
            od = _object_distance(lens, op)
        except SpecError as e:
            return [*out, str(e).split(": ", 1)[-1]]
        f = float(p["field"])
        if _field_kind(lens, op, od) == "angle" and not abs(f) < 90.0:
            out.append(f"field {f:g} deg: field angles lie strictly between -90 and 90 degrees")
        elif _field_kind(lens, op, od) == "height" and math.isinf(od):
            out.append(
                f"field {f:g} mm is an object height, which needs a finite object distance "
                '(give object_distance, or field_kind = "angle")'
            )
    return out


def evaluate(
    lens: Lens, operands: tuple[Operand, ...], *, check: bool = True
) -> tuple[OperandValue, ...]:
    """Compute every operand for ``lens``.

    Chief rays are batched: one kernel call per (object distance, field kind, wavelength) for all
    fields of all chief-ray operands (distortion, distortion_rel, image_height,
    distortion_slope, landing_angle); every image plane is reached by analytic transfer of the
    final segments. Paraxial data are computed once per (object, wavelength), the lens is packed
    once per wavelength for the spot operands.

    ``check``: first check every operand (its keys and types, and that it applies to ``lens``:
    :func:`operand_lens_problems`) and raise :class:`SpecError` naming it; the optimizers, which
    checked the spec once with :func:`~raytrace.optimize.check_spec`, pass False.
    """
    from ..trace import aim, trace_rays

    if check:
        for i, op in enumerate(operands):
            bad = operand_problems(op.type, op.params, op.target, op.weight)
            bad = bad or operand_lens_problems(lens, op)
            if bad:
                raise SpecError(f"operands[{i}] ({op.label()}): {bad[0]}")

    pars: dict[tuple[float, float | None], ParaxialResult] = {}
    packs: dict[float | None, object] = {}

    def par_for(od: float, wl: float | None = None) -> ParaxialResult:
        if (od, wl) not in pars:
            pars[(od, wl)] = paraxial(lens, od, wl)
        return pars[(od, wl)]

    # batch chief rays: one aim per (object, field kind, wavelength)
    groups: dict[tuple[float, str, float | None], set[float]] = {}
    for op in operands:
        if op.type in _CHIEF_TYPES:
            od = _object_distance(lens, op)
            key = (od, _field_kind(lens, op, od), _wavelength(op))
            groups.setdefault(key, set()).add(float(op.params["field"]))
    chief = {}
    for (od, kind, wl), fl in groups.items():
        fields = np.array(sorted(fl))
        chief[(od, kind, wl)] = (fields, aim(lens, fields, kind, od, wl))

    def pack_for(wl: float | None):  # once per evaluation and wavelength, for every ray operand
        if wl not in packs:
            packs[wl] = pack(lens, wl)
        return packs[wl]

    heights = _ray_heights(
        lens, [op for op in operands if op.type == "ray_height"], par_for, pack_for
    )

    out = []
    for op in operands:
        t = op.type
        p = op.params
        wl = _wavelength(op)
        if t in ("efl", "m_e", "HE0", "HpE0p"):
            par = par_for(_object_distance(lens, op), wl)
            v = {"efl": par.efl, "m_e": par.m_e, "HE0": par.HE0, "HpE0p": par.HpE0p}[t]
        elif t == "axial_color":
            od = _object_distance(lens, op)
            w1, w2 = p.get("wavelengths", (LAMBDA_F, LAMBDA_C))
            v = par_for(od, float(w1)).z_gauss - par_for(od, float(w2)).z_gauss
        elif t in _CHIEF_TYPES:
            od = _object_distance(lens, op)
            par = par_for(od, wl)
            kind = _field_kind(lens, op, od)
            fields, cr = chief[(od, kind, wl)]
            j = int(np.searchsorted(fields, float(p["field"])))
            if cr.status[j] != 0:
                raise ChiefRayError(op.label(), int(cr.status[j]), int(cr.surface[j]))
            if t == "landing_angle":
                v = float(cr.landing_angle_deg[j])
            elif t == "distortion_slope":  # dD0/ds' (raytrace.paraxial.distortion_slope)
                x = orthoscopy_abscissa(par, fields[j], kind)
                v = float(distortion_slope(par, x, cr.tan_out[j]))
            else:
                z = _plane_z(par, p.get("plane"))
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
            par = par_for(od, wl)
            kind = _field_kind(lens, op, od)
            rays = _bundle(par, float(p.get("field", 0.0)), kind, float(p.get("aperture", 1.0)))
            batch = trace_rays(pack_for(wl), rays[:3], rays[3:], clip=False)
            stats = _spot_stats(batch, op.label(), bool(p.get("drop_failed", False)))
            if t == "best_focus":
                v = _best_focus_z(stats) - par.z_Hp
            else:
                plane = p.get("plane")
                z = _best_focus_z(stats) if plane == "best" else _plane_z(par, plane)
                v = _rms_at(stats, z)
        elif t == "ray_height":
            v = heights[id(op)]
        elif t == "element_power":
            first = int(p["surface"])
            v = element_power(lens, first, int(p.get("last", first + 1)), wl)
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
        out.append(OperandValue(op, float(v), float(op.residual(float(v)))))
    return tuple(out)


def merit(values: tuple[OperandValue, ...]) -> float:
    """Merit function: the sum of squared weighted residuals."""
    return float(sum(o.residual**2 for o in values))
