"""A :class:`~raytrace.lens.Lens` packed into contiguous float64 / int64 arrays for the numba
kernels, at one or several wavelengths (docs/design.md, "Performance": pack once, structure of
arrays).

The geometry arrays are shared by every wavelength; the indices are rows of 2-D arrays
``n_in_w`` / ``n_out_w`` of shape (n_wavelengths, n_surfaces). Kernels take the lens as ONE
tuple (:attr:`PackedLens.lens_arrays`) that they unpack, so that more per-surface data can be
added without changing any kernel's argument list.

Surface placement (decenters, tilts, coordinate breaks, mirrors; :mod:`raytrace.frames`) travels
in the 2-D table ``geo`` that takes the place of the vertex positions in the tuples: column
``G_ZV`` is the vertex z, the other columns (:mod:`raytrace.kernels.codes`) hold the flags, the
transform into each surface's axis frame and the clear aperture. For a centred lens every row
is the identity with flags 0, and the kernels run the coaxial code unchanged. When the final
segments must be turned into an image frame other than the last surface's axis frame (a fold or
tilt after the last surface, a tilted image surface), one pseudo-surface is appended (flags
``F_SKIP | F_FRAME``): ``n_surfaces`` is then one more than the lens's
(:attr:`PackedLens.n_lens_surfaces`).

Q-type aspheres (:mod:`raytrace.qtype`; kinds ``KIND_QBFS``, ``KIND_QCON``) keep their row of
``asph`` as :meth:`raytrace.qtype.QType.packed_row` (1/ρ_max², then the coefficients of the
sum in the basis P_m) and are flagged ``F_SCALAR`` in the placement table: the bulk trace sends
flagged surfaces through the scalar surface step, which holds their sag (the vectorised passes
do not), and such a lens is not marked ``L_COAXIAL``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .frames import relative, surface_frames
from .kernels.codes import (
    F_APERTURE,
    F_FRAME,
    F_GENERAL,
    F_MIRROR,
    F_SCALAR,
    F_SKIP,
    G_ABS,
    G_ABST,
    G_AP,
    G_FLAGS,
    G_LENS,
    G_REL,
    G_RELT,
    G_ZV,
    KIND_PLANE,
    KIND_QBFS,
    KIND_QCON,
    L_COAXIAL,
    L_SYMMETRIC,
    NGEO,
)
from .lens import Lens

#: kinds the vectorised bulk passes do not hold (flagged ``F_SCALAR``)
SCALAR_KINDS = (KIND_QBFS, KIND_QCON)


def coaxial_geo(zv: np.ndarray, symmetric: bool = True) -> np.ndarray:
    """The placement table of a centred lens: identity frames, no flags, column G_ZV = ``zv``."""
    n = zv.shape[0]
    geo = np.zeros((n, NGEO))
    geo[:, G_ZV] = zv
    eye = np.eye(3).ravel()
    geo[:, G_REL : G_REL + 9] = eye
    geo[:, G_ABS : G_ABS + 9] = eye
    if n:
        geo[0, G_LENS] = float(L_COAXIAL | (L_SYMMETRIC if symmetric else 0))
    return geo


@dataclass(frozen=True, eq=False)
class PackedLens:
    """Contiguous float64/int64 arrays the numba kernels read (one entry per surface).

    kind:   int64 surface kind (KIND_PLANE, KIND_QUADRIC, KIND_ASPHERE, KIND_QBFS, KIND_QCON)
    c, k:   curvature (1/mm) and conic constant (of the base conic for a Q-type surface)
    asph:   (n, m) even-asphere coefficients of r⁴, r⁶, ... (m >= 1, zero padded); for a
            Q-type surface its packed row (module docstring)
    zv:     vertex z (mm), first vertex at 0
    n_in:   index before each surface; n_out: index after it (at ``wavelength``, the first of
            ``wavelengths``)
    sd:     semi-diameters (mm; inf = unlimited)
    stop:   0-based stop index;  z_image: image-plane z the file defines
    wavelengths: the packed wavelengths (nm); n_in_w, n_out_w: (n_wavelengths, n) indices, row i
            at ``wavelengths[i]`` (row 0 is ``n_in`` / ``n_out``)
    geo:    (n, NGEO) placement table (module docstring; column G_ZV = ``zv``)
    n_lens_surfaces: the lens's surfaces (``n_surfaces`` minus the image pseudo-surface)
    """

    kind: np.ndarray
    c: np.ndarray
    k: np.ndarray
    asph: np.ndarray
    zv: np.ndarray
    n_in: np.ndarray
    n_out: np.ndarray
    sd: np.ndarray
    stop: int
    z_image: float
    wavelength: float
    wavelengths: tuple[float, ...] = ()
    n_in_w: np.ndarray | None = None
    n_out_w: np.ndarray | None = None
    geo: np.ndarray | None = None
    n_lens_surfaces: int | None = None

    def __post_init__(self) -> None:
        # numba compiles a kernel once per array type, and a read-only array is another type:
        # every array here is writeable, so that each kernel is compiled once (a cached pack is
        # not to be written to all the same)
        for name in ("kind", "c", "k", "asph", "zv", "n_in", "n_out", "sd", "n_in_w", "n_out_w"):
            a = getattr(self, name)
            if isinstance(a, np.ndarray) and not a.flags.writeable:
                object.__setattr__(self, name, a.copy())
        n = int(self.c.shape[0])
        geo = self.geo
        if geo is None or geo.shape[0] != n:
            if geo is not None and np.any(geo[:, G_FLAGS] != 0.0):
                raise ValueError(
                    "the placement table (geo) does not match the surfaces; pack the lens again"
                )
            geo = coaxial_geo(np.asarray(self.zv, dtype=np.float64))
        else:
            geo = np.array(geo, dtype=np.float64)
            geo[:, G_ZV] = self.zv
        object.__setattr__(self, "geo", np.ascontiguousarray(geo))
        if self.n_lens_surfaces is None or self.n_lens_surfaces > n:
            object.__setattr__(self, "n_lens_surfaces", n)
        # a PackedLens built by hand (tests, benchmarks) at one wavelength
        if not self.wavelengths:
            object.__setattr__(self, "wavelengths", (float(self.wavelength),))
        if self.n_in_w is None:
            object.__setattr__(self, "n_in_w", np.ascontiguousarray(self.n_in[None, :]))
        if self.n_out_w is None:
            object.__setattr__(self, "n_out_w", np.ascontiguousarray(self.n_out[None, :]))

    @property
    def n_surfaces(self) -> int:
        return int(self.c.shape[0])

    @property
    def n_wavelengths(self) -> int:
        return len(self.wavelengths)

    @property
    def arrays(self) -> tuple:
        """The lens arrays at ``wavelength`` in the order the bulk and path kernels take them:
        kind, c, k, asph, geo (the placement table; its column G_ZV is the vertex z), n_in,
        n_out, sd."""
        return (self.kind, self.c, self.k, self.asph, self.geo, self.n_in, self.n_out, self.sd)

    @property
    def lens_arrays(self) -> tuple:
        """The lens as the one tuple the aiming kernels take (all wavelengths): kind, c, k, asph,
        geo (placement table, module docstring), n_in_w, n_out_w (2-D, wavelength × surface),
        sd."""
        return (self.kind, self.c, self.k, self.asph, self.geo, self.n_in_w, self.n_out_w, self.sd)

    @property
    def is_coaxial(self) -> bool:
        """True when no surface needs anything but the coaxial kernel code (all flags 0)."""
        return not np.any(self.geo[:, G_FLAGS] != 0.0)


def _asph_row(s) -> tuple[float, ...]:
    """The row of ``asph`` for surface ``s`` (module docstring)."""
    if s.qtype is None or s.qtype.is_zero:
        return s.aspheric
    return s.qtype.packed_row()


def pack(lens: Lens, wavelength: float | None = None, *, wavelengths=None) -> PackedLens:
    """Pack ``lens`` into contiguous arrays at ``wavelength`` nm (default: the lens's reference
    wavelength), or at several ``wavelengths`` (nm; the 1-D ``n_in`` / ``n_out`` are then at the
    first of them). Indices come from :meth:`raytrace.lens.Lens.indices`."""
    if wavelength is not None and wavelengths is not None:
        raise ValueError("give wavelength or wavelengths, not both")
    if wavelengths is None:
        wl = (lens.wavelength if wavelength is None else float(wavelength),)
    else:
        wl = tuple(float(w) for w in np.atleast_1d(np.asarray(wavelengths, dtype=float)))
        if not wl:
            raise ValueError("wavelengths: give at least one")
    ss = lens.surfaces
    n = len(ss)
    rows = [_asph_row(s) for s in ss]
    m = max([1] + [len(r) for r in rows])
    asph = np.zeros((n, m))
    for i, r in enumerate(rows):
        asph[i, : len(r)] = r
    idx = lens.indices(wl)  # (w, n + 1): object space, then after each surface
    n_in_w = np.array(idx[:, :-1], order="C")  # copies: the cached indices are read-only
    n_out_w = np.array(idx[:, 1:], order="C")
    kind = np.array([s.kind for s in ss], dtype=np.int64)
    c = np.array([s.curvature for s in ss], dtype=np.float64)
    k = np.array([s.conic for s in ss], dtype=np.float64)
    zv = np.ascontiguousarray(lens.vertex_z, dtype=np.float64)
    sd = np.array([s.semi_diameter for s in ss], dtype=np.float64)
    geo, extra = placement_table(lens)
    if extra:  # the image-frame pseudo-surface: a plane in the image medium, not traced
        kind = np.append(kind, KIND_PLANE)
        c = np.append(c, 0.0)
        k = np.append(k, 0.0)
        asph = np.vstack([asph, np.zeros((1, m))])
        zv = np.append(zv, float(lens.image_z))
        sd = np.append(sd, np.inf)
        n_in_w = np.ascontiguousarray(np.hstack([n_in_w, n_out_w[:, -1:]]))
        n_out_w = np.ascontiguousarray(np.hstack([n_out_w, n_out_w[:, -1:]]))
    return PackedLens(
        kind=kind,
        c=c,
        k=k,
        asph=np.ascontiguousarray(asph),
        zv=zv,
        n_in=np.ascontiguousarray(n_in_w[0]),
        n_out=np.ascontiguousarray(n_out_w[0]),
        sd=sd,
        stop=lens.stop_index,
        z_image=float(lens.image_z),
        wavelength=wl[0],
        wavelengths=wl,
        n_in_w=n_in_w,
        n_out_w=n_out_w,
        geo=geo,
        n_lens_surfaces=n,
    )


def placement_table(lens: Lens) -> tuple[np.ndarray, bool]:
    """(geo, extra): the placement table of ``lens`` (module docstring) and whether it holds the
    image-frame pseudo-surface as its last row."""
    ss = lens.surfaces
    zv = np.asarray(lens.vertex_z, dtype=np.float64)
    scalar = [s.kind in SCALAR_KINDS for s in ss]
    if (
        lens.is_centred
        and not lens.has_mirrors
        and all(s.aperture is None for s in ss)
        and not any(s.coordinate_break for s in ss)
        and not any(scalar)
    ):
        return coaxial_geo(zv), False
    fr = surface_frames(lens)
    general = lens.has_mirrors or not lens.is_centred
    rows = []
    prev = (np.eye(3), np.zeros(3))
    for j, s in enumerate(ss):
        row = np.zeros(NGEO)
        row[G_ZV] = zv[j]
        cur = (np.asarray(fr.axis_rotation[j]), np.asarray(fr.axis_origin[j]))
        row[G_ABS : G_ABS + 9] = cur[0].ravel()
        row[G_ABST : G_ABST + 3] = cur[1]
        row[G_REL : G_REL + 9] = np.eye(3).ravel()
        flags = 0
        if s.coordinate_break:
            flags |= F_SKIP
        else:
            if not (np.array_equal(prev[0], cur[0]) and np.array_equal(prev[1], cur[1])):
                M, t = relative(prev, cur)
                row[G_REL : G_REL + 9] = M.ravel()
                row[G_RELT : G_RELT + 3] = t
                flags |= F_FRAME
            prev = cur
            if s.mirror:
                flags |= F_MIRROR
            if general:
                flags |= F_GENERAL
            if scalar[j]:
                flags |= F_SCALAR
            if s.aperture is not None:
                a = s.aperture
                row[G_AP : G_AP + 5] = (a.code, a.half_x, a.half_y, a.x0, a.y0)
                flags |= F_APERTURE
        row[G_FLAGS] = float(flags)
        rows.append(row)
    img = (np.asarray(fr.image_rotation), np.asarray(fr.image_origin))
    extra = not (np.array_equal(prev[0], img[0]) and np.array_equal(prev[1], img[1]))
    if extra:
        row = np.zeros(NGEO)
        row[G_ZV] = float(lens.image_z)
        M, t = relative(prev, img)
        row[G_REL : G_REL + 9] = M.ravel()
        row[G_RELT : G_RELT + 3] = t
        row[G_ABS : G_ABS + 9] = img[0].ravel()
        row[G_ABST : G_ABST + 3] = img[1]
        row[G_FLAGS] = float(F_SKIP | F_FRAME)
        rows.append(row)
    geo = np.ascontiguousarray(np.array(rows))
    lens_flags = L_SYMMETRIC if lens.is_centred else 0
    if not np.any(geo[:, G_FLAGS] != 0.0):
        lens_flags |= L_COAXIAL
    geo[0, G_LENS] = float(lens_flags)
    return geo, extra
