"""Bulk real-ray traces: any rays through a lens, one kernel call (docs/design.md, "Performance").

Units: millimetres; light travels toward +z with the first vertex at z = 0. A ray is a point and
a direction (normalised here); it may start anywhere before the first surface (it is a line: it
is carried to each vertex plane). Rays start in global (object-space) coordinates; final
segments are in the lens's image frame (:mod:`raytrace.frames`: the global frame for a centred
lens; for a folded or tilted one the frame whose z axis is the image-space axis, so that image
planes are z = const). Every ray gets a status code (:mod:`raytrace.kernels.codes`);
a failed ray has NaN coordinates and the 1-based number of the surface where it failed.

A start that is not a valid ray — a non-finite origin, a zero or non-finite direction — is
refused with a :class:`~raytrace.errors.TraceError` (how many, the first index), never traced to
a status: ``missed`` would read as a fact about the lens. A valid direction that does not point
toward +z is traced and gets a status (see :func:`trace_rays`): one such ray must not fail a
batch.
"""

from __future__ import annotations

import threading
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from ..errors import TraceError
from ..kernels.codes import STATUS_MISSED, STATUS_NAMES
from ..lens import Lens
from ..packing import PackedLens, pack
from ..paraxial.conjugates import checked_wavelength
from .results import RayStatus

#: Batches of at least this many rays use the prange kernel (when more than one thread is
#: allowed). Measured on the 2-core development machine (benchmarks/bench_core.py crossover,
#: vectorised kernel: serial 1 µs per 20 rays): 2 threads win from ~4k rays when a second core is
#: free, but when it is busy (other processes) a parallel call waits one scheduler slice (~4 ms).
#: At 32768 rays the serial kernel takes ~1.6 ms, which bounds that penalty to ~2.5x and costs at
#: most ~0.8 ms on a quiet machine.
PARALLEL_THRESHOLD = 32768

#: Rays per kernel call: a larger batch is traced in chunks of this size (contiguous views, no
#: copies), so that Ctrl-C stops a long trace within a fraction of a second.
CHUNK_RAYS = 1 << 18

#: numba's parallel layer is not re-entrant from several Python threads (workqueue layer): every
#: parallel kernel launch and thread-count change holds this lock.
PARALLEL_LOCK = threading.RLock()


@dataclass(frozen=True, eq=False)
class RayBatch(RayStatus):
    """Result of :func:`trace_rays`: the final segment of each ray.

    x, y, z: point on the last surface (mm); L, M, N: direction cosines after it; in the image
    frame (module docstring).
    status:  int8 status code per ray (:mod:`raytrace.kernels.codes`); surface: int32 1-based
    surface where the ray failed (0 when OK). Failed rays have NaN coordinates.
    """

    x: np.ndarray
    y: np.ndarray
    z: np.ndarray
    L: np.ndarray
    M: np.ndarray
    N: np.ndarray
    status: np.ndarray
    surface: np.ndarray

    @property
    def positions(self) -> np.ndarray:
        """(n, 3) points on the last surface (mm)."""
        return np.column_stack((self.x, self.y, self.z))

    @property
    def directions(self) -> np.ndarray:
        """(n, 3) unit directions after the last surface."""
        return np.column_stack((self.L, self.M, self.N))

    def at_plane(self, z_plane: float) -> tuple[np.ndarray, np.ndarray]:
        """(x, y) in mm where each final segment meets the plane z = ``z_plane`` (mm from the first
        vertex), by analytic transfer; NaN for failed rays."""
        from ..kernels.bulk import transfer_to_plane

        arrs = (self.x, self.y, self.z, self.L, self.M, self.N)
        if all(a.ndim == 1 and a.dtype == np.float64 and a.flags.c_contiguous for a in arrs) and (
            len({a.shape for a in arrs}) == 1
        ):
            return transfer_to_plane(*arrs, float(z_plane))  # one pass, no temporaries
        t = (float(z_plane) - self.z) / self.N
        return self.x + t * self.L, self.y + t * self.M

    def __len__(self) -> int:
        return int(self.x.shape[0])

    def __repr__(self) -> str:
        counts = np.bincount(self.status.astype(np.int64), minlength=len(STATUS_NAMES))
        parts = [f"{STATUS_NAMES[i]} {int(c)}" for i, c in enumerate(counts) if c]
        return f"RayBatch({len(self)} rays: {', '.join(parts) or 'none'})"


def _columns(a, what: str) -> list[np.ndarray]:
    """An (n, 3) array (or nested lists of n rows, n ≠ 3) or a sequence of three array-likes
    → three float64 arrays."""
    if not isinstance(a, np.ndarray) and not (isinstance(a, Sequence) and len(a) == 3):
        try:
            rows = np.asarray(a, dtype=np.float64)
        except (TypeError, ValueError):
            rows = None
        if rows is not None and rows.ndim == 2:
            a = rows
    if isinstance(a, np.ndarray) and a.ndim == 2:
        if a.shape[1] != 3:
            raise TraceError(f"{what} must have shape (n, 3), got {a.shape}")
        a = a.astype(np.float64, copy=False)
        return [a[:, 0], a[:, 1], a[:, 2]]
    if isinstance(a, np.ndarray) and a.ndim == 1 and a.shape[0] == 3 and a.dtype != object:
        return [np.asarray(v, dtype=np.float64) for v in a]
    if isinstance(a, Sequence) and len(a) == 3:
        if all(isinstance(v, Sequence) and len(v) == 3 for v in a):
            raise TraceError(
                f"{what}: three lists of three numbers are ambiguous (three rays, or the x, y, z "
                "of three rays?): give np.array(rows) of shape (3, 3) for rays, or three 1-D "
                "arrays for x, y, z"
            )
        return [np.asarray(v, dtype=np.float64) for v in a]
    raise TraceError(f"{what}: expected an (n, 3) array or three arrays/values (x, y, z)")


def _f64(a: np.ndarray, n: int) -> np.ndarray:
    """A contiguous, writeable float64 1-D array of length n (one kernel specialisation only: a
    read-only array is another type to numba, and would compile the kernel again); such an input
    is used without a copy (the structure-of-arrays form of :func:`trace_rays`)."""
    if a.shape == (n,) and a.dtype == np.float64 and a.flags.c_contiguous and a.flags.writeable:
        return a
    return np.array(np.broadcast_to(a, (n,)), dtype=np.float64, order="C")


def _ray_columns(origins, directions) -> list[np.ndarray]:
    """x, y, z, L, M, N as contiguous float64 columns of one length (the inputs broadcast; a
    single ray is a batch of one), or TraceError."""
    arrs = _columns(origins, "origins") + _columns(directions, "directions")
    try:
        shape = np.broadcast_shapes(*(a.shape for a in arrs))
    except ValueError as e:
        raise TraceError(f"ray arrays do not broadcast to a common shape: {e}") from None
    if len(shape) > 1:
        raise TraceError(f"ray arrays must be 1-D (got shape {shape})")
    n = int(shape[0]) if shape else 1
    return [_f64(a, n) for a in arrs]


#: what a valid ray start is, for the refusal (:func:`_refuse`)
RAY_RULE = (
    "origins must be finite and directions must be nonzero, finite vectors pointing toward +z"
)


def _bad_starts(xs: list[np.ndarray], idx=slice(None)) -> np.ndarray:
    """Mask of the rays (of ``idx``) that are not valid rays: the kernels' own test (:mod:`.bulk`,
    ``_trace_block``; :mod:`.paths`) — |d|² = L² + M² + N² not positive and finite, or x + y + z
    not finite; the kernels trace such a ray to MISSED at surface 1."""
    x, y, z, L, M, N = (a[idx] for a in xs)
    s = L * L + M * M + N * N
    return ~((s > 0.0) & np.isfinite(s) & np.isfinite(x + y + z))


#: rays per block of the contiguous test in :func:`_any_bad_traced` (temporaries stay in cache)
CHECK_BLOCK = 16384


def _any_bad_traced(xs: list[np.ndarray], st: np.ndarray, i0: int, i1: int) -> bool:
    """Whether rays i0..i1-1, just traced to the statuses ``st``, hold a start that is not a
    valid ray. The kernel traces such a start to MISSED (at surface 1), so only MISSED rays are
    tested: the compare over the int8 status costs ~0.1-0.2 ms per 1e6 rays, where testing every
    start costs ~9 ms, 7 % of a 1e6-ray trace of the Cooke triplet (2-core development machine).
    A few MISSED rays are gathered and tested (~85 ns each); when more than 1/32 of the rays
    missed, the blocks of :data:`CHECK_BLOCK` rays that hold one are tested in place (~8 ms per
    1e6 rays at worst, ~10 % of a trace in which every ray misses)."""
    hit = st[i0:i1] == STATUS_MISSED
    k = np.count_nonzero(hit)
    if k == 0:
        return False
    if 32 * k <= i1 - i0:
        return bool(_bad_starts(xs, np.flatnonzero(hit) + i0).any())
    for b0 in range(0, i1 - i0, CHECK_BLOCK):
        b1 = min(b0 + CHECK_BLOCK, i1 - i0)
        if hit[b0:b1].any() and _bad_starts(xs, slice(i0 + b0, i0 + b1)).any():
            return True
    return False


def _refuse(xs: list[np.ndarray], what: str) -> TraceError:
    """The one-line error for a batch that holds starts that are not valid rays."""
    bad = np.flatnonzero(_bad_starts(xs))
    i = int(bad[0])
    o = ", ".join(f"{float(a[i]):g}" for a in xs[:3])
    d = ", ".join(f"{float(a[i]):g}" for a in xs[3:])
    return TraceError(
        f"{what}: {bad.size} of {xs[0].shape[0]} rays are not valid rays (first: index {i}, origin "
        f"({o}), direction ({d})): {RAY_RULE}"
    )


def packed_lens(lens: Lens | PackedLens, wavelength: float | None = None) -> PackedLens:
    """``lens`` packed at ``wavelength`` (nm, or a string with a unit: the one check); a
    :class:`PackedLens` is used as it is."""
    if wavelength is not None:
        wavelength = checked_wavelength(wavelength)
    if isinstance(lens, PackedLens):
        if wavelength is not None and float(wavelength) != lens.wavelength:
            raise TraceError(
                f"the packed lens is at {lens.wavelength:g} nm; pack it again for {wavelength} nm"
            )
        return lens
    if not isinstance(lens, Lens):
        raise TypeError(
            f"lens must be a Lens (osc.load_lens) or a PackedLens, not {type(lens).__name__}"
        )
    return pack(lens, wavelength)


def trace_rays(
    lens: Lens | PackedLens,
    origins: npt.ArrayLike,
    directions: npt.ArrayLike,
    *,
    wavelength: float | None = None,
    clip: bool = True,
    threads: int | None = None,
) -> RayBatch:
    """Trace any rays through ``lens`` and keep their final segments.

    Parameters
    ----------
    lens : Lens or PackedLens
        The lens (packed at ``wavelength``), or an already packed lens.
    origins, directions : array_like
        Either (n, 3) arrays or sequences of three array-likes ``(x, y, z)`` / ``(L, M, N)``
        (structure of arrays, broadcast to one length; the fastest form for millions of rays).
        Points in mm (first vertex at z = 0), anywhere before the first surface; directions
        are normalised and must point toward +z. A non-finite origin coordinate or a direction
        that is zero or not finite (more exactly: L² + M² + N² not a positive finite number)
        raises :class:`TraceError` naming how many rays and the first index. A valid direction
        with N <= 0 is traced, not refused (one such ray must not fail a large batch): in a
        centred lens without mirrors it gets status MISSED at the first traced surface (surface
        1 unless that is a coordinate break), with NaN coordinates; in a lens with mirrors,
        tilts or decentres (every surface traced in the general form) one with N = 0 in the
        frame of that surface gets MISSED there, and one with N < 0 is traced along its line
        as if it met the surfaces, so that its status (BACKWARD, MISSED, even OK) describes no
        real ray: give N > 0.
    wavelength : float, optional
        nm; default the lens's wavelength.
    clip : bool
        Apply semi-diameters (status CLIPPED outside them).
    threads : int, optional
        numba threads for this call; 1 forces the serial kernel. Batches of
        ``PARALLEL_THRESHOLD`` rays or more use the parallel kernel.

    Returns
    -------
    RayBatch
        Final segments (point on the last surface, direction after it), status per ray.

    Raises
    ------
    TraceError
        Arrays of the wrong shape, ``threads`` < 1, a packed lens of another wavelength, or
        starts that are not valid rays (above).
    """
    from ..kernels import bulk

    packed = packed_lens(lens, wavelength)
    xs = _ray_columns(origins, directions)
    n = xs[0].shape[0]
    out = [np.empty(n) for _ in range(6)]
    st = np.empty(n, dtype=np.int8)
    sf = np.empty(n, dtype=np.int32)
    if threads is not None and not (1 <= int(threads)):
        raise TraceError(f"threads must be >= 1, got {threads}")
    for i0 in range(0, n, CHUNK_RAYS):
        i1 = min(n, i0 + CHUNK_RAYS)
        args = (
            *packed.arrays,
            bool(clip),
            *(a[i0:i1] for a in xs),
            *(a[i0:i1] for a in out),
            st[i0:i1],
            sf[i0:i1],
        )
        _launch(bulk, args, i1 - i0, threads)
        if _any_bad_traced(xs, st, i0, i1):
            raise _refuse(xs, "trace_rays")
    return RayBatch(*out, st, sf)


def _launch(bulk, args: tuple, n: int, threads: int | None) -> None:
    """One kernel call: serial for small batches or one thread, else the prange kernel (under
    :data:`PARALLEL_LOCK`)."""
    if n < PARALLEL_THRESHOLD or threads == 1:
        bulk.trace_batch_serial(*args)
        return
    import numba

    with PARALLEL_LOCK:
        top = numba.config.NUMBA_NUM_THREADS
        want = top if threads is None else min(int(threads), top)
        if want == 1:
            bulk.trace_batch_serial(*args)
            return
        old = numba.get_num_threads()
        try:
            if threads is not None:
                numba.set_num_threads(want)
            bulk.trace_batch_parallel(*args)
        finally:
            if threads is not None:
                numba.set_num_threads(old)


@dataclass(frozen=True, eq=False)
class RayPaths:
    """Intersection points of each ray with every surface: x, y, z of shape (n_rays, n_surfaces)
    in mm, global coordinates (NaN after a failure and on coordinate breaks), with status and
    failed surface per ray as in :class:`RayBatch`."""

    x: np.ndarray
    y: np.ndarray
    z: np.ndarray
    status: np.ndarray
    surface: np.ndarray


def ray_paths(
    lens: Lens | PackedLens,
    origins: npt.ArrayLike,
    directions: npt.ArrayLike,
    *,
    wavelength: float | None = None,
    clip: bool = False,
) -> RayPaths:
    """Trace a few rays (same inputs as :func:`trace_rays`) and keep every surface intersection —
    for layout drawings and checks. Serial: tens of rays, not millions.

    Starts that are not valid rays (a non-finite origin, a zero or non-finite direction) raise
    :class:`TraceError` as in :func:`trace_rays`. A valid direction with N <= 0 is traced: in a
    centred lens without mirrors it gets MISSED at the first traced surface, as in
    :func:`trace_rays`; in a lens with mirrors, tilts or decentres its status describes no real
    ray (and may differ from the one :func:`trace_rays` gives it)."""
    from ..kernels.paths import trace_paths

    packed = packed_lens(lens, wavelength)
    xs = _ray_columns(origins, directions)
    n = xs[0].shape[0]
    if n and _bad_starts(xs).any():  # few rays: every start is tested
        raise _refuse(xs, "ray_paths")
    ns = packed.n_lens_surfaces
    px, py, pz = (np.empty((n, ns)) for _ in range(3))
    st = np.empty(n, dtype=np.int8)
    sf = np.empty(n, dtype=np.int32)
    trace_paths(*packed.arrays, bool(clip), *xs, px, py, pz, st, sf)
    return RayPaths(px, py, pz, st, sf)
