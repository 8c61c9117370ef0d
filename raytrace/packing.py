"""A :class:`~raytrace.lens.Lens` packed into contiguous float64 / int64 arrays for the numba
kernels, at one or several wavelengths (docs/design.md, "Performance": pack once, structure of
arrays).

The geometry arrays are shared by every wavelength; the indices are rows of 2-D arrays
``n_in_w`` / ``n_out_w`` of shape (n_wavelengths, n_surfaces). Kernels take the lens as ONE
tuple (:attr:`PackedLens.lens_arrays`) that they unpack, so that more per-surface data (surface
frames) can be added to the tuple without changing any kernel's argument list.
"""

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
    n_in:   index before each surface; n_out: index after it (at ``wavelength``, the first of
            ``wavelengths``)
    sd:     semi-diameters (mm; inf = unlimited)
    stop:   0-based stop index;  z_image: image-plane z the file defines
    wavelengths: the packed wavelengths (nm); n_in_w, n_out_w: (n_wavelengths, n) indices, row i
            at ``wavelengths[i]`` (row 0 is ``n_in`` / ``n_out``)
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

    def __post_init__(self) -> None:
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
        kind, c, k, asph, zv, n_in, n_out, sd."""
        return (self.kind, self.c, self.k, self.asph, self.zv, self.n_in, self.n_out, self.sd)

    @property
    def lens_arrays(self) -> tuple:
        """The lens as the one tuple the aiming kernel takes (all wavelengths): kind, c, k, asph,
        zv, n_in_w, n_out_w (2-D, wavelength × surface), sd. Extensions (surface frames) append
        to this tuple."""
        return (self.kind, self.c, self.k, self.asph, self.zv, self.n_in_w, self.n_out_w, self.sd)


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
    m = max([1] + [len(s.aspheric) for s in ss])
    asph = np.zeros((n, m))
    for i, s in enumerate(ss):
        asph[i, : len(s.aspheric)] = s.aspheric
    idx = lens.indices(wl)  # (w, n + 1): object space, then after each surface
    n_in_w = np.array(idx[:, :-1], order="C")  # writeable copies (idx is a cached read-only
    n_out_w = np.array(idx[:, 1:], order="C")  # array): one kernel specialisation only
    return PackedLens(
        kind=np.array([s.kind for s in ss], dtype=np.int64),
        c=np.array([s.curvature for s in ss], dtype=np.float64),
        k=np.array([s.conic for s in ss], dtype=np.float64),
        asph=np.ascontiguousarray(asph),
        zv=np.ascontiguousarray(lens.vertex_z, dtype=np.float64),
        n_in=n_in_w[0].copy(),
        n_out=n_out_w[0].copy(),
        sd=np.array([s.semi_diameter for s in ss], dtype=np.float64),
        stop=lens.stop_index,
        z_image=float(lens.image_z),
        wavelength=wl[0],
        wavelengths=wl,
        n_in_w=n_in_w,
        n_out_w=n_out_w,
    )
