"""A :class:`~raytrace.lens.Lens` packed into contiguous float64 / int64 arrays for the numba
kernels, at one wavelength (docs/design.md, "Performance": pack once, structure of arrays)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .lens import Lens


@dataclass(frozen=True, eq=False)
class PackedLens:
    """Contiguous float64/int64 arrays the numba kernels read (one entry per surface).

    kind:   int64 surface kind (KIND_PLANE, KIND_QUADRIC, KIND_ASPHERE)
    c, k:   curvature (1/mm) and conic constant
    asph:   (n, m) even-asphere coefficients of r⁴, r⁶, ... (m >= 1, zero padded)
    zv:     vertex z (mm), first vertex at 0
    n_in:   index before each surface; n_out: index after it (at ``wavelength``)
    sd:     semi-diameters (mm; inf = unlimited)
    stop:   0-based stop index;  z_image: image-plane z the file defines
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

    @property
    def n_surfaces(self) -> int:
        return int(self.c.shape[0])

    @property
    def arrays(self) -> tuple:
        """The lens arrays in the order every kernel takes them: kind, c, k, asph, zv, n_in,
        n_out, sd."""
        return (self.kind, self.c, self.k, self.asph, self.zv, self.n_in, self.n_out, self.sd)


def pack(lens: Lens, wavelength: float | None = None) -> PackedLens:
    """Pack ``lens`` into contiguous arrays at ``wavelength`` nm (default: the lens's)."""
    wl = lens.wavelength if wavelength is None else float(wavelength)
    ss = lens.surfaces
    n = len(ss)
    m = max([1] + [len(s.aspheric) for s in ss])
    asph = np.zeros((n, m))
    for i, s in enumerate(ss):
        asph[i, : len(s.aspheric)] = s.aspheric
    n_out = np.array([s.material.index(wl) for s in ss], dtype=np.float64)
    n_in = np.empty(n)
    n_in[0] = lens.object_material.index(wl)
    n_in[1:] = n_out[:-1]
    return PackedLens(
        kind=np.array([s.kind for s in ss], dtype=np.int64),
        c=np.array([s.curvature for s in ss], dtype=np.float64),
        k=np.array([s.conic for s in ss], dtype=np.float64),
        asph=np.ascontiguousarray(asph),
        zv=np.ascontiguousarray(lens.vertex_z, dtype=np.float64),
        n_in=np.ascontiguousarray(n_in),
        n_out=n_out,
        sd=np.array([s.semi_diameter for s in ss], dtype=np.float64),
        stop=lens.stop_index,
        z_image=float(lens.image_z),
        wavelength=wl,
    )
