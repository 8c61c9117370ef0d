"""The perturbation model: a drawn instance (one value per tolerance item) applied to a centred
lens — as arrays over many instances for the instance kernel (:func:`pack_instances`), or as one
:class:`~raytrace.lens.Lens` (:func:`perturbed_lens`).

Geometry (the conventions of :mod:`raytrace.frames`: frames ``(R, o)``, moves composed as
``F ∘ (Q, d) = (R Q, o + R d)``, right-handed tilts):

* thicknesses change first (TTHI; the adjust surface takes the opposite change), giving the
  perturbed vertex positions ``zv_j`` on the axis;
* an **element** move (TEDX, TEDY, TETX, TETY on surfaces a..b, grouped by their range) is the
  coordinate-break pair OpticStudio inserts around the element: decenter (dx, dy), then tilt
  about x, then about the new y (order flag 0), about the pivot point ``zv_a + pivot`` on the
  axis: ``E = T(z_p) ∘ (Rx(tx) Ry(ty), (dx, dy, 0)) ∘ T(−z_p)``; the surfaces after b return
  to their places. Nested elements compose outer first (the inner move is expressed in the
  outer element's moved frame); ranges that overlap without nesting are refused;
* a **surface** move (TSDX, TSDY, TSTX, TSTY, TIRX, TIRY) turns or shifts one surface about its
  own vertex, the next surfaces returning: ``(Rx(a) Ry(b), (dx, dy, 0))``; TIRX turns by
  ``atan(TIR / 2 sd)`` about y (runout along x), TIRY about x;
* the surface frame of surface j is ``S_j = E_j ∘ T(zv_j) ∘ own_j`` (``E_j`` the composed moves
  of the elements containing j, identity for none); its axis frame ``S_j ∘ T(−zv_j)``.

Shape: TRAD ``R' = R + ΔR``; TCUR ``c' = c + Δc``; TFRN: the sphere through the vertex whose
sag at the semi-diameter h is changed by ``N λ_test / 2`` (one fringe of a double-pass test
plate is λ/2 of sag): with ``z = c h²/(1 + √(1 − c² h²))``, ``c' = 2 z'/(z'² + h²)``,
``z' = z + N λ/2`` (to first order Δc = N λ / h²); TCON ``k + Δk``; TASP adds to
the coefficient of r^term; TIRR adds the irregularity ``Zs ρ⁴ + Za ρ_y²`` (ρ = r/sd, ρ_y =
y/sd) with ``Zs = Za = N λ_test / 4`` (half spherical, half astigmatism; Δsag N λ/2 in all — our
reading of OpticStudio's TIRR, not checked against OpticStudio).

Glass (through the material model, :meth:`raytrace.lens.Lens.indices`): with n(λ) the glass's
index, nd = n(587.5618 nm) and Vd = (nd − 1)/(n_F − n_C) evaluated from the same model,
``n'(λ) = n(λ) + Δnd + (n(λ) − nd)·(Vd/(Vd + ΔVd) − 1)``: TIND shifts every wavelength, TABB
rescales the dispersion about nd.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from ..frames import Placement
from ..kernels.codes import (
    F_FRAME,
    F_SKIP,
    G_ABS,
    G_ABST,
    G_FLAGS,
    G_REL,
    G_RELT,
    G_ZV,
    KIND_ASPHERE,
    KIND_PLANE,
    KIND_QUADRIC,
    NGEO,
)
from ..kernels.instances import KIND_IRREGULAR
from ..lens import Lens
from ..materials import LAMBDA_C, LAMBDA_D, LAMBDA_F, fixed_index
from ..packing import pack
from ..paraxial import ynu_matrix, ynu_trace
from .spec import ToleranceSpec, ToleranceSpecError, check_against_lens

#: OpticStudio's element-move types, and the surface-move types
_ELEMENT = ("TEDX", "TEDY", "TETX", "TETY")
_SURFACE_MOVE = ("TSDX", "TSDY", "TSTX", "TSTY", "TIRX", "TIRY")


@dataclass(frozen=True, eq=False)
class InstanceArrays:
    """Many perturbed instances of one lens as the instance kernel reads them (one row per
    instance; ``n`` lens surfaces plus one image-frame row, as :func:`raytrace.packing.pack`
    appends it).

    kind (I, n+1) int64; c, k (I, n+1); asph (I, n+1, m); geo (I, n+1, NGEO) placement tables
    (:mod:`raytrace.kernels.codes`); n_in, n_out (I, n+1) indices at ``wavelength``; sd (I,
    n+1); irr (I, n+1, 3): (Zs, Za, normalisation radius) of irregular surfaces (mm).
    thickness (I, n): perturbed thicknesses (last: to the image surface of the stack);
    vertex_z (I, n): perturbed vertex positions on the axis; stop: 0-based stop surface;
    wavelength: nm.
    """

    kind: np.ndarray
    c: np.ndarray
    k: np.ndarray
    asph: np.ndarray
    geo: np.ndarray
    n_in: np.ndarray
    n_out: np.ndarray
    sd: np.ndarray
    irr: np.ndarray
    thickness: np.ndarray
    vertex_z: np.ndarray
    stop: int
    wavelength: float

    @property
    def n_instances(self) -> int:
        return int(self.c.shape[0])

    @property
    def n_surfaces(self) -> int:
        return int(self.thickness.shape[1])

    @property
    def lens_tuple(self) -> tuple:
        """The arrays in the order the instance kernels take them."""
        return (self.kind, self.c, self.k, self.asph, self.geo, self.n_in, self.n_out, self.sd,
                self.irr)  # fmt: skip

    @property
    def image_z_stack(self) -> np.ndarray:
        """z of the surface after the last thickness (the image surface of the stack), (I,)."""
        return self.vertex_z[:, -1] + self.thickness[:, -1]

    @property
    def nbytes(self) -> int:
        return int(sum(a.nbytes for a in self.lens_tuple) + self.thickness.nbytes * 2)


# ------------------------------------------------------------------------------ rotations
def _rx(a: np.ndarray) -> np.ndarray:
    """Right-handed rotations about x by ``a`` radians, (I, 3, 3)."""
    c, s = np.cos(a), np.sin(a)
    R = np.zeros(a.shape + (3, 3))
    R[..., 0, 0] = 1.0
    R[..., 1, 1], R[..., 1, 2] = c, -s
    R[..., 2, 1], R[..., 2, 2] = s, c
    return R


def _ry(b: np.ndarray) -> np.ndarray:
    c, s = np.cos(b), np.sin(b)
    R = np.zeros(b.shape + (3, 3))
    R[..., 1, 1] = 1.0
    R[..., 0, 0], R[..., 0, 2] = c, s
    R[..., 2, 0], R[..., 2, 2] = -s, c
    return R


def _mm(A: np.ndarray, B: np.ndarray) -> np.ndarray:
    """Batched 3 × 3 products without BLAS (a fixed summation order per instance)."""
    return (A[..., :, :, None] * B[..., None, :, :]).sum(axis=-2)


def _mv(A: np.ndarray, v: np.ndarray) -> np.ndarray:
    return (A * v[..., None, :]).sum(axis=-1)


def _compose(F, m):
    """Frame F = (R, o) moved by m = (Q, d) expressed in F: (R Q, o + R d)."""
    return _mm(F[0], m[0]), F[1] + _mv(F[0], m[1])


def _translate(I: int, z) -> tuple[np.ndarray, np.ndarray]:
    R = np.broadcast_to(np.eye(3), (I, 3, 3)).copy()
    o = np.zeros((I, 3))
    o[:, 2] = z
    return R, o


def _move(dx, dy, tx_deg, ty_deg):
    """(Q, d) of 'decenter, then tilt about x, then about the new y' (I instances)."""
    Q = _mm(_rx(np.radians(tx_deg)), _ry(np.radians(ty_deg)))
    d = np.stack([dx, dy, np.zeros_like(dx)], axis=-1)
    return Q, d


def _sphere_sag(c: np.ndarray, h: float) -> np.ndarray:
    return c * h * h / (1.0 + np.sqrt(1.0 - c * c * h * h))


# ------------------------------------------------------------------------------ the model
@dataclass(frozen=True, eq=False)
class _Applied:
    c: np.ndarray  # (I, n)
    k: np.ndarray
    asph: np.ndarray  # (I, n, m)
    t: np.ndarray  # (I, n)
    zv: np.ndarray  # (I, n)
    R: np.ndarray  # (I, n, 3, 3) surface frames
    o: np.ndarray  # (I, n, 3)
    moved: np.ndarray  # (n,) bool: any instance moves surface j
    dn: np.ndarray  # (I, n) Δnd of the medium after surface j
    dv: np.ndarray  # (I, n) ΔVd
    irr: np.ndarray  # (I, n, 2) Zs, Za (mm)


def _elements(spec: ToleranceSpec):
    """Element groups: {(first, last): pivot} in nesting order (outer first), checked."""
    groups: dict[tuple[int, int], float | None] = {}
    for it in spec.items:
        if it.type not in _ELEMENT:
            continue
        key = (it.surface, it.last)
        piv = it.pivot if it.type in ("TETX", "TETY") else None
        old = groups.get(key)
        if key in groups and piv is not None and old is not None and old != piv:
            raise ToleranceSpecError(
                f"{it.where or it.name}: element {key[0]}-{key[1]} has tilts about two pivots "
                f"({old:g} and {piv:g} mm); give both tilts the same pivot"
            )
        groups[key] = piv if piv is not None else old
    keys = sorted(groups, key=lambda r: (-(r[1] - r[0]), r[0]))
    for i, a in enumerate(keys):
        for b in keys[i + 1 :]:
            inter = not (a[1] < b[0] or b[1] < a[0])
            nested = a[0] <= b[0] and b[1] <= a[1]
            if inter and not nested:
                raise ToleranceSpecError(
                    f"elements {a[0]}-{a[1]} and {b[0]}-{b[1]} overlap without one containing "
                    "the other; make them disjoint or nested"
                )
    return [(k, groups[k] or 0.0) for k in keys]


def _apply(lens: Lens, spec: ToleranceSpec, values: np.ndarray, base) -> _Applied:
    """Apply ``values`` (I, n_items) to the nominal arrays ``base`` (a PackedLens)."""
    values = np.asarray(values, dtype=float)
    if values.ndim != 2 or values.shape[1] != spec.n_items:
        raise ValueError(f"values must be (instances, {spec.n_items}), got {values.shape}")
    I = values.shape[0]
    n = lens.n_surfaces
    c = np.repeat(base.c[None, :n], I, axis=0)
    k = np.repeat(base.k[None, :n], I, axis=0)
    m = base.asph.shape[1]
    need = max([m] + [(it.term - 4) // 2 + 1 for it in spec.items if it.type == "TASP"])
    asph = np.zeros((I, n, need))
    asph[:, :, :m] = base.asph[None, :n, :]
    t = np.repeat(np.array([s.thickness for s in lens.surfaces])[None, :], I, axis=0)
    sd = np.array([s.semi_diameter for s in lens.surfaces])
    lam_t = spec.test_wavelength * 1e-6  # mm
    own = {}  # surface -> [dx, dy, tx, ty]
    elem = {}  # (a, b) -> [dx, dy, tx, ty]
    dn = np.zeros((I, n))
    dv = np.zeros((I, n))
    irr = np.zeros((I, n, 2))
    zero = np.zeros(I)
    for col, it in enumerate(spec.items):
        v = values[:, col]
        j = it.surface - 1
        ty = it.type
        if ty == "TRAD":
            c[:, j] = 1.0 / (1.0 / c[:, j] + v)
        elif ty == "TCUR":
            c[:, j] = c[:, j] + v
        elif ty == "TFRN":
            h = sd[j]
            z = _sphere_sag(c[:, j], h) + v * lam_t / 2.0
            c[:, j] = 2.0 * z / (z * z + h * h)
        elif ty == "TTHI":
            t[:, j] = t[:, j] + v
            if it.adjust:
                t[:, it.adjust - 1] = t[:, it.adjust - 1] - v
        elif ty == "TCON":
            k[:, j] = k[:, j] + v
        elif ty == "TASP":
            asph[:, j, (it.term - 4) // 2] += v
        elif ty in _SURFACE_MOVE:
            mv = own.setdefault(j, [zero.copy() for _ in range(4)])
            if ty == "TSDX":
                mv[0] = mv[0] + v
            elif ty == "TSDY":
                mv[1] = mv[1] + v
            elif ty == "TSTX":
                mv[2] = mv[2] + v
            elif ty == "TSTY":
                mv[3] = mv[3] + v
            elif ty == "TIRX":
                mv[3] = mv[3] + np.degrees(np.arctan(v / (2.0 * sd[j])))
            else:  # TIRY
                mv[2] = mv[2] + np.degrees(np.arctan(v / (2.0 * sd[j])))
        elif ty in _ELEMENT:
            mv = elem.setdefault((it.surface, it.last), [zero.copy() for _ in range(4)])
            mv[_ELEMENT.index(ty)] = mv[_ELEMENT.index(ty)] + v
        elif ty == "TIND":
            dn[:, j] += v
        elif ty == "TABB":
            dv[:, j] += v
        elif ty == "TIRR":
            irr[:, j, 0] += v * lam_t / 4.0
            irr[:, j, 1] += v * lam_t / 4.0
        else:  # pragma: no cover - spec.ITEM_TYPES is exhaustive
            raise ToleranceSpecError(f"{it.where}: unknown type {ty}")
    zv = np.concatenate([np.zeros((I, 1)), np.cumsum(t[:, :-1], axis=1)], axis=1)
    R = np.broadcast_to(np.eye(3), (I, n, 3, 3)).copy()
    o = np.zeros((I, n, 3))
    o[:, :, 2] = zv
    moved = np.zeros(n, dtype=bool)
    groups = _elements(spec)
    for j in range(n):
        G = None  # the composed element moves of surface j (None: not in a moved element)
        for (a, b), pivot in groups:
            if a - 1 <= j <= b - 1:
                dx, dy, tx, ty_ = elem[(a, b)]
                zp = zv[:, a - 1] + pivot
                E = _compose(_compose(_translate(I, zp), _move(dx, dy, tx, ty_)),
                             _translate(I, -zp))  # fmt: skip
                # E moves the global frame (nominal coordinates); nested elements compose outer
                # first: the inner move is expressed in the outer element's moved frame
                G = E if G is None else _compose(G, E)
        touched = G is not None
        F = _translate(I, zv[:, j]) if G is None else _compose(G, _translate(I, zv[:, j]))
        if j in own:
            F = _compose(F, _move(*own[j]))
            touched = True
        R[:, j], o[:, j] = F
        moved[j] = touched
    return _Applied(c, k, asph, t, zv, R, o, moved, dn, dv, irr)


def perturbed_indices(lens: Lens, wavelength: float, dn: np.ndarray, dv: np.ndarray) -> np.ndarray:
    """Indices after each surface at ``wavelength`` (nm) with the glass changes ``dn`` (Δnd)
    and ``dv`` (ΔVd), arrays (I, n) (module docstring): (I, n + 1), column 0 the object space.
    The one place the TIND / TABB rule is applied."""
    idx = lens.indices((float(wavelength), LAMBDA_D, LAMBDA_F, LAMBDA_C))  # (4, n+1)
    n_l, n_d, n_f, n_c = idx[0], idx[1], idx[2], idx[3]
    out = np.repeat(n_l[None, :], dn.shape[0], axis=0)
    glass = (dn != 0.0) | (dv != 0.0)
    for j in np.nonzero(np.any(glass, axis=0))[0]:
        col = j + 1
        disp = n_f[col] - n_c[col]
        if disp != 0.0:
            vd = (n_d[col] - 1.0) / disp
            scale = vd / (vd + dv[:, j]) - 1.0
        else:
            scale = np.zeros(dn.shape[0])
        out[:, col] = n_l[col] + dn[:, j] + (n_l[col] - n_d[col]) * scale
    return out


def pack_instances(
    lens: Lens, spec: ToleranceSpec, values: np.ndarray, wavelength: float | None = None
) -> InstanceArrays:
    """The instances ``values`` (I, n_items) of ``lens`` as arrays for the instance kernels
    (module docstring), at ``wavelength`` nm (default the lens's reference wavelength)."""
    check_against_lens(spec, lens)
    wl = float(lens.wavelength if wavelength is None else wavelength)
    base = pack(lens, wl)
    ap = _apply(lens, spec, values, base)
    I, n = ap.c.shape
    n1 = n + 1
    idx = perturbed_indices(lens, wl, ap.dn, ap.dv)
    n_in = np.empty((I, n1))
    n_out = np.empty((I, n1))
    n_in[:, :n] = idx[:, :-1]
    n_out[:, :n] = idx[:, 1:]
    n_in[:, n] = idx[:, -1]
    n_out[:, n] = idx[:, -1]
    m = ap.asph.shape[2]
    asph = np.zeros((I, n1, m))
    asph[:, :n] = ap.asph
    kind = np.empty((I, n1), dtype=np.int64)
    has_asph = np.any(ap.asph != 0.0, axis=2)
    kind[:, :n] = np.where(has_asph, KIND_ASPHERE, np.where(ap.c == 0.0, KIND_PLANE, KIND_QUADRIC))
    irregular = np.any(ap.irr != 0.0, axis=2)
    kind[:, :n] = np.where(irregular, KIND_IRREGULAR, kind[:, :n])
    kind[:, n] = KIND_PLANE
    c = np.zeros((I, n1))
    c[:, :n] = ap.c
    k = np.zeros((I, n1))
    k[:, :n] = ap.k
    sd = np.empty((I, n1))
    sd[:, :n] = np.array([s.semi_diameter for s in lens.surfaces])[None, :]
    sd[:, n] = np.inf
    irr = np.zeros((I, n1, 3))
    irr[:, :n, :2] = ap.irr
    irr[:, :n, 2] = sd[:, :n]
    geo = np.zeros((I, n1, NGEO))
    eye = np.eye(3).ravel()
    geo[:, :, G_REL : G_REL + 9] = eye
    geo[:, :, G_ABS : G_ABS + 9] = eye
    geo[:, :n, G_ZV] = ap.zv
    geo[:, n, G_ZV] = ap.zv[:, -1] + ap.t[:, -1]
    # axis frames: the surface frame moved back along its own z by zv
    zhat = np.zeros((I, 3))
    prevR = np.broadcast_to(np.eye(3), (I, 3, 3))
    prevo = np.zeros((I, 3))
    prev_moved = False
    for j in range(n1):
        if j < n and ap.moved[j]:
            Rj = ap.R[:, j]
            zhat[:, 2] = ap.zv[:, j]
            oj = ap.o[:, j] - _mv(Rj, zhat)
            cur_moved = True
        else:
            Rj = np.broadcast_to(np.eye(3), (I, 3, 3))
            oj = np.zeros((I, 3))
            cur_moved = False
        flags = 0
        if prev_moved or cur_moved:
            M = (Rj[..., :, :, None] * prevR[..., :, None, :]).sum(axis=-3)  # Rj^T prevR
            tt = _mv(np.swapaxes(Rj, -1, -2), prevo - oj)
            geo[:, j, G_REL : G_REL + 9] = M.reshape(I, 9)
            geo[:, j, G_RELT : G_RELT + 3] = tt
            geo[:, j, G_ABS : G_ABS + 9] = Rj.reshape(I, 9)
            geo[:, j, G_ABST : G_ABST + 3] = oj
            flags |= F_FRAME
        if j == n:
            flags |= F_SKIP
        geo[:, j, G_FLAGS] = float(flags)
        prevR, prevo, prev_moved = Rj, oj, cur_moved
    return InstanceArrays(
        kind=np.ascontiguousarray(kind),
        c=np.ascontiguousarray(c),
        k=np.ascontiguousarray(k),
        asph=np.ascontiguousarray(asph),
        geo=np.ascontiguousarray(geo),
        n_in=np.ascontiguousarray(n_in),
        n_out=np.ascontiguousarray(n_out),
        sd=np.ascontiguousarray(sd),
        irr=np.ascontiguousarray(irr),
        thickness=ap.t,
        vertex_z=ap.zv,
        stop=lens.stop_index,
        wavelength=wl,
    )


def _euler_xyz(R: np.ndarray) -> tuple[float, float, float]:
    """(a, b, c) degrees with R = Rx(a) Ry(b) Rz(c) (:func:`raytrace.frames.move`'s
    "decenter-tilt" order)."""
    b = math.asin(max(-1.0, min(1.0, float(R[0, 2]))))
    a = math.atan2(-float(R[1, 2]), float(R[2, 2]))
    c = math.atan2(-float(R[0, 1]), float(R[0, 0]))
    return math.degrees(a), math.degrees(b), math.degrees(c)


def perturbed_lens(
    lens: Lens, spec: ToleranceSpec, values, wavelength: float | None = None
) -> Lens:
    """One instance (``values``: one value per item) as a :class:`Lens`: every moved surface
    gets its placement relative to its own vertex on the axis, with ``after="return"``
    (:mod:`raytrace.frames`); perturbed glasses become fixed indices at ``wavelength`` (nm,
    default the lens's reference wavelength) and the lens is then monochromatic there.

    Irregularity (TIRR) has no form in :class:`Lens` (an astigmatic sag term): a spec with a
    TIRR item raises :class:`ToleranceSpecError`; the instance kernel models it."""
    check_against_lens(spec, lens)
    if any(it.type == "TIRR" for it in spec.items):
        raise ToleranceSpecError(
            "TIRR (irregularity) cannot be written as a Lens (no astigmatic surface type); the "
            "Monte Carlo kernel models it — drop TIRR to get a perturbed Lens"
        )
    v = np.asarray(values, dtype=float).reshape(1, -1)
    wl = float(lens.wavelength if wavelength is None else wavelength)
    base = pack(lens, wl)
    ap = _apply(lens, spec, v, base)
    idx = perturbed_indices(lens, wl, ap.dn, ap.dv)[0]
    surfaces = []
    glass = bool(np.any(ap.dn != 0.0) or np.any(ap.dv != 0.0))
    for j, s in enumerate(lens.surfaces):
        kw = dict(
            curvature=float(ap.c[0, j]),
            thickness=float(ap.t[0, j]),
            conic=float(ap.k[0, j]),
            aspheric=tuple(float(a) for a in ap.asph[0, j]) if np.any(ap.asph[0, j]) else (),
        )
        if ap.dn[0, j] != 0.0 or ap.dv[0, j] != 0.0:
            kw["material"] = fixed_index(float(idx[j + 1]))
        if ap.moved[j]:
            R, o = ap.R[0, j], ap.o[0, j]
            d = (float(o[0]), float(o[1]), float(o[2] - ap.zv[0, j]))
            kw["placement"] = Placement(d, _euler_xyz(R), "decenter-tilt")
            kw["after"] = "return"
        surfaces.append(replace(s, **kw))
    out = replace(lens, surfaces=tuple(surfaces), image_solve=None)
    if glass:
        out = out.with_wavelengths([wl])
    return out


# ------------------------------------------------------------------------------ paraxial
@dataclass(frozen=True, eq=False)
class ParaxialBatch:
    """First-order data of the centred part of many instances (arrays (I,), mm, absolute z from
    the first vertex): ``efl``; ``z_image`` the paraxial image of the object (the Gaussian plane;
    for an object at infinity the back focal point); ``z_last`` the last vertex; ``chief_h`` and
    ``chief_slope`` the paraxial chief ray (through the centre of the stop) per unit field
    abscissa t (t = tan α for an object at infinity; for a finite object the object point is
    ``object_per_t · t``): its height at the last vertex (mm) and its image-space slope u'
    (height per mm of z), so that Pestrecov's constant of orthoscopy of a plane z is
    ``K0(z) = chief_h + (z − z_last) · chief_slope`` (Eq. 8 as the paraxial chief ray's height in
    the plane: F0 in mm for an object at infinity, M0·object_per_t for a finite one)."""

    efl: np.ndarray
    z_image: np.ndarray
    z_last: np.ndarray
    chief_h: np.ndarray
    chief_slope: np.ndarray

    def k0_at(self, z) -> np.ndarray:
        """Pestrecov's K0 (mm per unit t) of each instance in the planes ``z`` ((I,) or scalar)."""
        return self.chief_h + (np.asarray(z, dtype=float) - self.z_last) * self.chief_slope


def paraxial_batch(
    arrays: InstanceArrays, object_distance: float, object_per_t: float | None = None
) -> ParaxialBatch:
    """Paraxial marginal, system and chief rays of every instance's centred part (its decenters
    and tilts left out, as :meth:`Lens.nominal` does): the y-nu trace of
    :func:`raytrace.paraxial.paraxial` (:func:`raytrace.paraxial.ynu_matrix`) over instances at
    once (tested equal to :func:`raytrace.paraxial.paraxial` on the instances' lenses).
    ``object_per_t``: for a finite object, the object height (mm) per unit field abscissa t
    (Pestrecov's nominal ``p0 = z_object − z_E0`` of the nominal lens); unused for an object at
    infinity."""
    n = arrays.n_surfaces
    # surface first, as ynu_matrix reads them: row j holds surface j of every instance
    c, t = arrays.c[:, :n].T, arrays.thickness.T
    n_in, n_out = arrays.n_in[:, :n].T, arrays.n_out[:, :n].T
    # the rays (y, nu) = (1, 0) and (0, 1) at the first vertex: their heights sA, sB on the stop,
    # then on to the last surface (A, B) and their slopes there (C, D): the system matrix
    after_stop = arrays.stop + 1
    (sA, sB), (sC, sD) = ynu_matrix(c, t, n_in, n_out, after_stop)
    A, C = ynu_trace(c, t, n_in, n_out, sA, sC, n, start=after_stop)
    B, D = ynu_trace(c, t, n_in, n_out, sB, sD, n, start=after_stop)
    z_last = arrays.vertex_z[:, -1]
    nk = n_out[-1]
    n0 = n_in[0]
    efl = -1.0 / C
    if math.isinf(object_distance):
        z_img = z_last - A * nk / C
        # chief ray: slope 1 in object space (nu = n0), height y1 with zero height at the stop
        y1 = -n0 * sB / sA
        nu1 = n0
    else:
        u = 1.0 / object_distance  # slope of a ray from the axial object point
        y1m = u * object_distance
        ym = A * y1m + B * (n0 * u)
        num = C * y1m + D * (n0 * u)
        z_img = z_last - ym / (num / nk)
        if object_per_t is None:
            raise ValueError("a finite object needs object_per_t (the object height per unit t)")
        # chief ray from the object point Y = object_per_t at z = -object_distance through the
        # stop centre: y1 = Y + d u, nu1 = n0 u with sA y1 + sB nu1 = 0
        Y = float(object_per_t)
        d = float(object_distance)
        uc = -sA * Y / (sA * d + sB * n0)
        y1 = Y + d * uc
        nu1 = n0 * uc
    ch = A * y1 + B * nu1
    cnu = C * y1 + D * nu1
    return ParaxialBatch(efl, z_img, z_last, ch, cnu / nk)
