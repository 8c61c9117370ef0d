"""The distortion outputs of many perturbed instances of a lens, computed together: compensator,
real chief rays (one kernel launch, :func:`raytrace.tolerance.aim_instances`), the radial curve
and a 2-D Brown fit per instance — no Python loop over lenses.

Per instance ``i`` (docs/tolerance.md; units in :class:`ToleranceOutputs`):

1. the perturbed lens is packed (:func:`raytrace.tolerance.pack_instances`) and its centred
   part's paraxial data found (:func:`raytrace.tolerance.paraxial_batch`);
2. the compensator (:mod:`.compensators`) chooses the image plane ``z_i``;
3. the real chief rays of the curve fields (0, α) and of the 2-D fit points are aimed through
   the centre of the instance's real stop and carried to ``z_i``;
4. **raw** distortion along +y: ``D = y' − K0_i tan α`` (Pestrecov Eq. 9 with the instance's
   own constant of orthoscopy ``K0_i`` of Eq. 8 in its plane; the boresight shift of a decentered
   lens stays in D); ``Dx = x'`` along the same fields;
5. **calibrated**: the linear model of :mod:`distortion.grid.decompose` (camera constant c,
   principal point (x0, y0), K1..Kn, P1, P2, S1, S2) fitted by least squares to the 2-D grid
   (rings × azimuths, symmetric about the axis, so that a centred lens gives x0 = y0 = P = S = 0);
   ``D_cal = y' − y0 − c tan α`` (what a calibration absorbs — camera constant and principal
   point — removed). The **raw** decentering ``P1_raw``, ``P2_raw`` comes from the same model
   with c held at ``K0_i`` and the principal point at (0, 0);
6. when asked for (``g_object_distance``), Fraser & Shortis's variation factor g_ss' for the
   lens focused at the run's object distance and the object plane at ``g_object_distance``
   (:mod:`.gfactor`: one more kernel launch aims the chief rays at s').

The fit uses one pseudo-inverse for all instances (the ideal coordinates t of the fields are the
same for every instance), applied without BLAS so that an instance's numbers do not depend on how
many instances share its call (bit-identical whatever the chunking).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace

import numpy as np

from raytrace.errors import TraceError
from raytrace.lens import Lens
from raytrace.paraxial import paraxial
from raytrace.tolerance import (
    NominalAim,
    ToleranceSpec,
    aim_instances,
    check_against_lens,
    nominal_aim,
    pack_instances,
    paraxial_batch,
)

from ..errors import DataError
from ..grid.decompose import basis_columns
from .checks import check_spec
from .compensators import image_planes, pupil_bundle
from .gfactor import GSetup, instance_g, prepare_g, resolve_g_distance

#: default number of curve fields (0 .. the lens's max field)
DEFAULT_FIELDS = 50
DEFAULT_RINGS = (0.2, 0.4, 0.6, 0.8, 1.0)
DEFAULT_AZIMUTHS = 8
#: fields of :class:`ToleranceOutputs` with one value per instance
SCALARS = ("efl", "image_z", "focus_shift", "k0", "c", "x0", "y0", "P1", "P2", "S1", "S2",
           "P1_raw", "P2_raw", "fit_rms_um", "g")  # fmt: skip
#: fields with one value per instance and curve field
CURVES = ("D_um", "Dx_um", "D_cal_um")


@dataclass(frozen=True, eq=False)
class ToleranceOutputs:
    """Distortion outputs of I instances (leading axis I; NaN where ``ok`` is False).

    Attributes
    ----------
    fields_deg : (F,) curve fields α, degrees, traced along +y ((αx, αy) = (0, α)).
    efl : (I,) paraxial EFL of the instance's centred part, mm.
    image_z : (I,) image plane after the compensator, mm from the nominal first vertex.
    focus_shift : (I,) ``image_z`` minus the nominal lens's, mm (+ away from the lens).
    k0 : (I,) Pestrecov's K0 in that plane (F0 in mm for an object at infinity; M0·p0 for a
        finite one), mm per unit tan α.
    D_um : (I, F) raw distortion y' − K0 tan α along +y, µm (pincushion positive).
    Dx_um : (I, F) x' along the same fields, µm (0 for a centred lens).
    D_cal_um : (I, F) calibrated distortion y' − y0 − c tan α, µm.
    c : (I,) calibrated camera constant Fc, mm.
    x0, y0 : (I,) calibrated principal point, mm (image frame: x right, y up).
    K : (I, radial_terms) radial coefficients K1.., mm^-2, mm^-4, ... (distortion form).
    P1, P2 : (I,) decentering, mm^-1 (calibrated fit: c, x0, y0 free).
    S1, S2 : (I,) thin prism, mm^-1 (calibrated fit).
    P1_raw, P2_raw : (I,) decentering with c = K0 and (x0, y0) = (0, 0) held, mm^-1.
    fit_rms_um : (I,) RMS residual of the calibrated fit, µm.
    g : (I,) Fraser & Shortis's variation factor g_ss' (Eq. 6; dimensionless) for the lens
        focused at the run's object distance s and the object plane s' = ``g_object_distance``
        (:mod:`distortion.tolerance.gfactor`); NaN when not requested, or where undetermined.
    ok : (I,) bool, every chief ray of the curve and the fit traced (the rays at s' of g are
        not part of it: a failure there makes only g NaN).
    """

    fields_deg: np.ndarray
    efl: np.ndarray
    image_z: np.ndarray
    focus_shift: np.ndarray
    k0: np.ndarray
    D_um: np.ndarray
    Dx_um: np.ndarray
    D_cal_um: np.ndarray
    c: np.ndarray
    x0: np.ndarray
    y0: np.ndarray
    K: np.ndarray
    P1: np.ndarray
    P2: np.ndarray
    S1: np.ndarray
    S2: np.ndarray
    P1_raw: np.ndarray
    P2_raw: np.ndarray
    fit_rms_um: np.ndarray
    g: np.ndarray
    ok: np.ndarray

    @property
    def n_instances(self) -> int:
        return int(self.efl.shape[0])

    def arrays(self) -> dict:
        """Every per-instance array by name (for files)."""
        return {f.name: getattr(self, f.name) for f in fields(self) if f.name != "fields_deg"}

    def take(self, rows) -> ToleranceOutputs:
        """The instances ``rows`` (index array or slice)."""
        kw = {k: v[rows] for k, v in self.arrays().items()}
        return ToleranceOutputs(fields_deg=self.fields_deg, **kw)

    @staticmethod
    def concat(parts: list[ToleranceOutputs]) -> ToleranceOutputs:
        """The instances of ``parts`` one after the other."""
        keys = parts[0].arrays().keys()
        kw = {k: np.concatenate([p.arrays()[k] for p in parts], axis=0) for k in keys}
        return ToleranceOutputs(fields_deg=parts[0].fields_deg, **kw)

    @staticmethod
    def from_arrays(fields_deg, d: dict) -> ToleranceOutputs:
        d = dict(d)
        if "g" not in d:  # chunk files written before g existed
            d["g"] = np.full(np.asarray(d["efl"]).shape[0], np.nan)
        return ToleranceOutputs(fields_deg=np.asarray(fields_deg), **{k: d[k] for k in d})

    def __repr__(self) -> str:
        return f"ToleranceOutputs({self.n_instances} instances, {self.fields_deg.size} fields)"


@dataclass(frozen=True, eq=False)
class ToleranceSetup:
    """What every chunk of a run shares (computed once by :func:`prepare`; picklable, sent to
    Dask workers once): the lens, the spec, the fields, the nominal chief-ray aim, the fit's
    pseudo-inverses and the nominal outputs."""

    lens: Lens
    spec: ToleranceSpec
    fields_deg: np.ndarray
    points_deg: np.ndarray  # (P, 2) (αx, αy): the F curve fields first, then the fit grid
    object_distance: float
    wavelength: float
    object_per_t: float | None
    aim: NominalAim
    t: np.ndarray  # (P, 2) ideal coordinates (tan αx, tan αy)
    radial_terms: int
    fit: bool
    A_cal: np.ndarray | None  # (2P, m) scaled design matrices, pseudo-inverses (None: no fit)
    pinv_cal: np.ndarray | None
    scale_cal: np.ndarray | None
    A_raw: np.ndarray | None
    pinv_raw: np.ndarray | None
    scale_raw: np.ndarray | None
    bundle: np.ndarray | None  # (6, R) axial rays for the best-focus compensator
    nominal_image_z: float
    grid_rings: tuple
    grid_azimuths: int
    g: GSetup | None = None  # the object plane s' of g_ss' (None: g not computed)

    @property
    def n_curve(self) -> int:
        return int(self.fields_deg.size)


def _basis(t: np.ndarray, radial_terms: int) -> list[tuple[str, np.ndarray]]:
    """The columns (x part stacked on y part) of the linear model of
    :mod:`distortion.grid.decompose` (:func:`~distortion.grid.decompose.basis_columns`, with the
    decentering and thin-prism terms) at the direction tangents ``t`` (N, 2)."""
    cols = basis_columns(t[:, 0], t[:, 1], radial_terms, True)
    return [(n, np.concatenate([cx, cy])) for n, cx, cy in cols]


def _design(t: np.ndarray, radial_terms: int, held: tuple[str, ...]):
    cols = [(n, v) for n, v in _basis(t, radial_terms) if n not in held]
    A = np.stack([v for _, v in cols], axis=1)
    scale = np.linalg.norm(A, axis=0)
    As = A / scale
    return [n for n, _ in cols], np.ascontiguousarray(As), np.linalg.pinv(As), scale


def _matvec(M: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``M @ b_i`` for every row b_i of ``b`` (I, k) without BLAS: (I, m); the sum over k runs
    along a contiguous axis of fixed length, so row i's result does not depend on I."""
    return np.ascontiguousarray(M[None, :, :] * b[:, None, :]).sum(axis=-1)


def _lstsq(As, pinv, b):
    """Least squares for every row of b, with one step of iterative refinement (as
    :func:`distortion.grid.decompose.solve_linear`)."""
    sol = _matvec(pinv, b)
    sol = sol + _matvec(pinv, b - _matvec(As, sol))
    return sol


def default_fields(lens: Lens, n: int = DEFAULT_FIELDS) -> np.ndarray:
    """``n`` curve fields from 0 to the lens's maximum field angle, degrees."""
    if lens.field.kind != "angle":
        raise TraceError(
            f"{lens.name}: the lens's field is given as object heights; pass fields_deg"
        )
    return np.linspace(0.0, float(lens.field.value), n)


def prepare(
    lens: Lens,
    spec: ToleranceSpec,
    *,
    fields_deg=None,
    object_distance: float | str | None = None,
    wavelength: float | str | None = None,
    grid_rings=DEFAULT_RINGS,
    grid_azimuths: int = DEFAULT_AZIMUTHS,
    radial_terms: int = 3,
    g_object_distance=None,
) -> ToleranceSetup:
    """The :class:`ToleranceSetup` of a sensitivity or Monte Carlo run (arguments as
    :func:`distortion.tolerance.monte_carlo`). ``g_object_distance``: the object plane s' of
    Fraser & Shortis's g_ss' (mm from the object plane to the first vertex, ``inf``, a length
    string such as ``"2m"`` or an image scale ``"10x"``); None takes the spec's ``[outputs]
    g_object_distance``, and without one g is not computed. Raises ToleranceSpecError for a spec
    that does not fit the lens, TraceError when a nominal chief ray fails or the object lies
    inside the front focal length (a virtual nominal image: :func:`raytrace.paraxial.plane_z`, as
    :func:`distortion.characteristic.characteristic_distortion`), DataError when g cannot be
    defined (:func:`distortion.tolerance.gfactor.prepare_g`)."""
    from raytrace.lens import require_lens
    from raytrace.paraxial.conjugates import (
        ImagePlane,
        checked_wavelength,
        plane_z,
        resolve_object_distance,
    )

    require_lens(lens)
    if not isinstance(spec, ToleranceSpec):
        raise TypeError(
            f"spec must be a ToleranceSpec, not {type(spec).__name__}: read it first, e.g. "
            "spec = osc.read_tolerance_spec('cooke-triplet-f4')"
        )
    check_against_lens(spec, lens)
    check_spec(spec)
    fd = default_fields(lens) if fields_deg is None else np.asarray(fields_deg, dtype=float).ravel()
    if fd.size == 0 or not np.all(np.isfinite(fd)) or np.any(np.abs(fd) >= 90.0):
        raise TraceError("fields_deg must be finite angles strictly between -90 and 90 degrees")
    if np.any(fd < 0.0):
        raise TraceError(
            f"fields_deg {float(np.min(fd)):g}: the curve is traced along +y; give angles >= 0 "
            "(degrees)"
        )
    wl = checked_wavelength(wavelength) or float(lens.wavelength)  # nm, "0.55um", "d"
    od = resolve_object_distance(lens, object_distance=object_distance, wavelength=wl)
    rings = tuple(float(r) for r in grid_rings)
    amax = float(np.max(np.abs(fd)))
    pts = [np.column_stack([np.zeros_like(fd), fd])]
    fit = bool(rings) and grid_azimuths >= 3 and amax > 0.0
    if fit and len(set(rings)) < radial_terms + 2:
        raise DataError(
            f"grid_rings {rings}: the 2-D fit has {radial_terms + 1} radial unknowns (c, K1..K"
            f"{radial_terms}); give at least {radial_terms + 2} distinct rings, or fewer "
            "radial_terms"
        )
    if fit:
        phi = 2.0 * np.pi * np.arange(grid_azimuths) / grid_azimuths
        for r in rings:
            tr = math.tan(math.radians(r * amax))
            tx, ty = tr * np.cos(phi), tr * np.sin(phi)
            pts.append(np.degrees(np.column_stack([np.arctan(tx), np.arctan(ty)])))
    P = np.concatenate(pts, axis=0)
    par = paraxial(lens.nominal(), object_distance=od, wavelength=wl)
    # the nominal image plane: an object inside the front focal length has a virtual image
    # (before the last surface), refused in characteristic_distortion's words (its check)
    plane_z(par, [ImagePlane("gaussian")])
    aim = nominal_aim(lens, spec, P[:, 0], P[:, 1], object_distance=od, wavelength=wl)
    t = np.tan(np.radians(P))
    object_per_t = None if math.isinf(od) else float(par.p0)
    F = fd.size
    _, As, pinv, sc = _design(t[F:], radial_terms, ()) if fit else (None, None, None, None)
    _, Ar, pinvr, scr = (
        _design(t[F:], radial_terms, ("x0", "y0", "c")) if fit else (None, None, None, None)
    )
    bundle = None
    if spec.compensator.type == "best-focus":
        bundle = pupil_bundle(par, od, spec.compensator.rings)
    gsetup = None
    if g_object_distance is None:
        g_object_distance = spec.outputs.get("g_object_distance")
        where = f"{spec.path or 'tolerance spec'}: [outputs] g_object_distance"
    else:
        where = "g_object_distance"
    if g_object_distance is not None:
        od2 = resolve_g_distance(lens, g_object_distance, wl, where)
        gsetup = prepare_g(lens, spec, fd, od, od2, wl)
    setup = ToleranceSetup(lens, spec, fd, P, od, wl, object_per_t, aim, t, int(radial_terms),
                           fit, As, pinv, sc, Ar, pinvr, scr, bundle, 0.0, rings,
                           int(grid_azimuths), gsetup)  # fmt: skip
    nom = evaluate(setup, np.zeros((1, spec.n_items)), parallel=False)
    if not nom.ok[0]:
        raise TraceError(f"{lens.name}: the nominal lens's chief rays or image plane fail")
    return replace(setup, nominal_image_z=float(nom.image_z[0]))


def evaluate(
    setup: ToleranceSetup, values: np.ndarray, *, parallel: bool = True
) -> ToleranceOutputs:
    """The outputs of the instances ``values`` (I, n_items) (module docstring). ``parallel``:
    numba threads over instances (False: the calling thread, as on a Dask worker); both give
    bit-identical numbers."""
    # an instance that does not trace is NaN and ok False (the callers report it): numpy's
    # warnings about its NaN are not for the person
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        return _evaluate(setup, values, parallel)


def _evaluate(setup: ToleranceSetup, values, parallel: bool) -> ToleranceOutputs:
    spec = setup.spec
    values = np.atleast_2d(np.asarray(values, dtype=float))
    arr = pack_instances(setup.lens, spec, values, setup.wavelength)
    pb = paraxial_batch(arr, setup.object_distance, setup.object_per_t)
    cr = aim_instances(arr, setup.aim, parallel=parallel)
    z = image_planes(spec.compensator.type, arr, pb, setup.bundle, parallel=parallel)
    pts = cr.points_at(z)  # (I, P, 2)
    I = values.shape[0]
    F = setup.n_curve
    ok = np.all(cr.ok, axis=1) & np.isfinite(z)
    k0 = pb.k0_at(z)
    tan_a = setup.t[:F, 1]
    xy = pts[:, :F, :]
    D = (xy[:, :, 1] - k0[:, None] * tan_a[None, :]) * 1e3
    Dx = xy[:, :, 0] * 1e3
    nan = np.full(I, np.nan)
    nk = setup.radial_terms
    if setup.fit:
        g = pts[:, F:, :]  # the fit grid (symmetric about the axis)
        b = np.concatenate([g[:, :, 0], g[:, :, 1]], axis=1)
        b = np.where(ok[:, None], b, 0.0)
        lin = _lstsq(setup.A_cal, setup.pinv_cal, b) / setup.scale_cal
        x0, y0, c = lin[:, 0], lin[:, 1], lin[:, 2]
        K = lin[:, 3 : 3 + nk] / np.stack([c ** (2 * i + 1) for i in range(1, nk + 1)], axis=1)
        q = lin[:, 3 + nk :] / (c * c)[:, None]
        fitted = _matvec(setup.A_cal, lin * setup.scale_cal)
        r = b - fitted
        P = r.shape[1] // 2
        rms = np.sqrt(np.mean(r[:, :P] ** 2 + r[:, P:] ** 2, axis=1)) * 1e3
        tt = np.concatenate([setup.t[F:, 0], setup.t[F:, 1]])
        braw = b - k0[:, None] * tt[None, :]
        linr = _lstsq(setup.A_raw, setup.pinv_raw, braw) / setup.scale_raw
        qr = linr[:, nk:] / (k0 * k0)[:, None]
        Dcal = (xy[:, :, 1] - y0[:, None] - c[:, None] * tan_a[None, :]) * 1e3
        P1, P2, S1, S2 = q[:, 0], q[:, 1], q[:, 2], q[:, 3]
        P1r, P2r = qr[:, 0], qr[:, 1]
    else:
        x0 = y0 = c = P1 = P2 = S1 = S2 = P1r = P2r = rms = nan
        K = np.full((I, nk), np.nan)
        Dcal = np.full((I, F), np.nan)
    if setup.g is not None:
        g = instance_g(setup.g, spec.compensator.type, arr, z, xy[:, :, 1], k0, tan_a,
                       parallel=parallel)  # fmt: skip
    else:
        g = nan
    dz = z - setup.nominal_image_z
    out = dict(efl=pb.efl, image_z=z, focus_shift=dz, k0=k0, D_um=D, Dx_um=Dx, D_cal_um=Dcal,
               c=c, x0=x0, y0=y0, K=K, P1=P1, P2=P2, S1=S1, S2=S2, P1_raw=P1r, P2_raw=P2r,
               fit_rms_um=rms, g=g)  # fmt: skip
    bad = ~ok
    res = {}
    for k, v in out.items():
        v = np.array(v, dtype=float, copy=True)
        if bad.any():
            v[bad] = np.nan
        res[k] = v
    return ToleranceOutputs(fields_deg=setup.fields_deg, ok=ok, **res)
