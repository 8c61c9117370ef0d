"""Monte Carlo of manufactured lenses: N seeded instances, compensated, their distortion outputs
(:mod:`.outputs`), in chunks of consecutive instances — on this machine (numba threads) or on a
Dask cluster — written incrementally with a manifest, resumable, and bit-identical.

Determinism. Instance i's perturbations come from its own stream
(:data:`raytrace.tolerance.GENERATOR`: ``SeedSequence(seed, spawn_key=(i,))``); its outputs are
computed by kernels and array code whose arithmetic for one instance does not depend on the other
instances of the call (no BLAS, reductions only along fixed-length per-instance axes). So an
instance is the same lens with the same numbers whatever the chunk size, the worker or a resume,
and the summary (computed from the arrays in instance order) is bit-identical — on one host and
build: another CPU, numpy or numba build may differ in the last bit (vectorised transcendental
functions and fused multiply-adds are the compiler's and the library's choice).

Files (``out_dir``): ``manifest.json`` (format, lens / spec / settings hashes, seed, n,
chunk_size, generator, done chunk numbers), ``chunk-NNNNN.npz`` (the perturbations ``values`` and
every :class:`ToleranceOutputs` array of instances [k·chunk, (k+1)·chunk)), ``summary.json`` at the
end. Each file is written atomically (:func:`raytrace.files.output.write_atomic`), the manifest
after each chunk: an interrupted run (Ctrl-C, a killed worker) keeps its finished chunks and a
rerun with the same inputs computes only the missing ones. Nothing is written to ``out_dir``
before every check has passed and the executor is connected (Dask installed, the scheduler
reached): a refused run leaves the folder as it was, and a run that fails before its first chunk
is on disk removes the manifest (and the folder) it made.
"""

from __future__ import annotations

import hashlib
import io
import json
import math
import time
import warnings
import zipfile
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from raytrace.errors import OutputError
from raytrace.executors import dask_client
from raytrace.files.output import write_atomic
from raytrace.lens import Lens
from raytrace.limits import MAX_INSTANCES as _MAX_INSTANCES
from raytrace.tolerance import (
    GENERATOR,
    ToleranceSpec,
    ToleranceSpecError,
    draw_instances,
    pack_instances,
)

from .checks import ToleranceInputError as ToleranceInputError
from .checks import (
    check_percentiles,
    check_yield_limit,
    split_where,
    warn_units,
    where_of,
    whole,
)
from .outputs import (
    CURVES,
    DEFAULT_AZIMUTHS,
    DEFAULT_RINGS,
    SCALARS,
    ToleranceOutputs,
    ToleranceSetup,
    evaluate,
    prepare,
)
from .summary import (
    PERCENTILE_METHOD,
    SUMMARY_BINS,
    SUMMARY_BLOCK,
    StreamedSummary,
    StreamingSummary,
    interpolation_weights,
    yield_counts,
)

FORMAT = "orthoscope-tolerance-mc-1"
DEFAULT_PERCENTILES = (0.5, 2.5, 16.0, 50.0, 84.0, 97.5, 99.5)
DEFAULT_CHUNK = 256
#: ``summary="auto"`` gathers the instances (exact summary) up to this many, streams above
EXACT_MAX_INSTANCES = 100_000
SUMMARY_METHODS = ("auto", "exact", "streaming")
#: instances of one run without ``allow_large=True``: :data:`raytrace.limits.MAX_INSTANCES`,
#: the command line's limit (lifted there by --allow-large)
MAX_INSTANCES = _MAX_INSTANCES
#: bytes per instance of an exact summary's gathered outputs (F = 50 fields; docs/tolerance.md)
BYTES_PER_INSTANCE = 1200
#: a run where more than this fraction of the instances cannot be traced warns
FAIL_WARN_FRACTION = 0.10
#: the manifest keys, in words (a folder that holds another run says which differ)
_MANIFEST_WORDS = {
    "format": "file format",
    "lens": "lens name",
    "lens_hash": "lens (surfaces, glasses or wavelength)",
    "spec_hash": "tolerance spec (its items, compensator or test wavelength)",
    "settings_hash": "settings (fields, object distance, wavelength, fit grid or g)",
    "seed": "seed",
    "n": "number of instances",
    "chunk_size": "chunk size",
    "generator": "random generator",
    "compensator": "compensator",
}


# ------------------------------------------------------------------------------ one chunk
def run_chunk(setup: ToleranceSetup, seed: int, start: int, stop: int, parallel: bool = False):
    """Instances ``start .. stop − 1`` of the run with ``seed``: dict of arrays (``values`` (I,
    n_items) and every :meth:`ToleranceOutputs.arrays` entry). The unit of work sent to a Dask
    worker (``parallel=False`` there: one thread per worker)."""
    values = draw_instances(setup.spec, seed, range(start, stop))
    out = evaluate(setup, values, parallel=parallel)
    d = out.arrays()
    d["values"] = values
    return d


def _hash(*parts) -> str:
    h = hashlib.sha256()
    for p in parts:
        if isinstance(p, np.ndarray):
            h.update(str(p.dtype).encode())
            h.update(str(p.shape).encode())
            h.update(np.ascontiguousarray(p).tobytes())
        else:
            h.update(repr(p).encode())
        h.update(b"|")
    return h.hexdigest()[:16]


def lens_hash(lens: Lens, spec: ToleranceSpec, wavelength: float) -> str:
    """Hash of the nominal lens as the kernels see it (surfaces, placements, indices)."""
    arr = pack_instances(lens, spec, np.zeros((1, spec.n_items)), wavelength)
    return _hash(*arr.lens_tuple, arr.thickness, arr.stop, arr.wavelength)


def spec_hash(spec: ToleranceSpec) -> str:
    """Hash of what a spec changes (items in order, compensator, test wavelength): its content,
    not where it was read from (a copy of the spec at another path has the same hash)."""
    items = tuple(replace(it, where="") for it in spec.items)
    return _hash(items, spec.compensator, spec.test_wavelength)


def legacy_spec_hash(spec: ToleranceSpec) -> str:
    """The spec hash of runs written before :func:`spec_hash` left out the items' ``where``
    (the spec file's path): such a run resumes when the spec is read from the same path."""
    return _hash(spec.items, spec.compensator, spec.test_wavelength)


def _settings_hash(setup: ToleranceSetup) -> str:
    parts = [setup.points_deg, setup.object_distance, setup.wavelength, setup.radial_terms,
             setup.grid_rings, setup.grid_azimuths]  # fmt: skip
    if setup.g is not None:  # (runs without g keep the hash they had before g existed)
        gs = setup.g
        parts += ["g", gs.object_distance, gs.n_r, gs.threshold_um, gs.method]
    return _hash(*parts)


# ------------------------------------------------------------------------------ the store
class _Store:
    """Chunk files and the manifest in ``out_dir`` (module docstring).

    Made in two steps, so that a run refused by a later check (Dask not installed, a scheduler
    that cannot be reached) leaves ``out_dir`` as it was: the constructor reads and checks what
    the folder holds and writes nothing; :meth:`open` then creates the folder, removes the
    chunks of a run being replaced and writes the manifest, once the run can start."""

    def __init__(self, out_dir, manifest: dict, resume: bool, overwrite: bool,
                 legacy_spec_hash: str | None = None):  # fmt: skip
        self.dir = Path(out_dir)
        if self.dir.exists() and not self.dir.is_dir():
            raise OutputError(f"{self.dir}: exists and is not a folder; give another out_dir")
        self.mpath = self.dir / "manifest.json"
        self.manifest = manifest
        self.done: set[int] = set()
        #: what :meth:`open` does: remove the chunk files there (a run replaced or none)
        self._clear = False
        #: :meth:`open` created the folder / wrote the first manifest there (:meth:`undo`)
        self._made_dir = False
        self._fresh = not self.mpath.exists()
        if self.mpath.exists():
            try:
                old = json.loads(self.mpath.read_text())
                if not isinstance(old, dict):
                    raise ValueError("not a JSON object")
                done = [int(k) for k in old.get("done", [])]
                if any(not 0 <= k < 2**31 for k in done):
                    raise ValueError("a chunk number out of range")
            except (OSError, ValueError, TypeError, OverflowError, RecursionError) as e:
                if not overwrite:
                    raise OutputError(
                        f"{self.mpath}: unreadable run manifest ({e}); give a new out_dir, or "
                        "overwrite=True to replace the run there"
                    ) from None
                old, done = {}, []
            if legacy_spec_hash is not None and old.get("spec_hash") == legacy_spec_hash:
                old["spec_hash"] = manifest["spec_hash"]  # same spec, hashed with its path
            diff = [k for k in manifest if k != "done" and old.get(k) != manifest[k]]
            if diff and not overwrite:
                what = _differences(diff, old, manifest)
                raise OutputError(
                    f"{self.dir}: holds another run (it differs in {what}); give a new out_dir, "
                    "or overwrite=True to replace it"
                )
            if not diff and resume:
                self.done = {k for k in done if self.path(k).exists()}
            else:
                if not overwrite and done:
                    raise OutputError(
                        f"{self.dir}: holds this run already; pass resume=True to continue it or "
                        "overwrite=True to start again"
                    )
                self._clear = True
        else:
            others = sorted(p.name for p in self.dir.iterdir()) if self.dir.is_dir() else []
            if others and not overwrite:
                shown = ", ".join(others[:3]) + (", ..." if len(others) > 3 else "")
                raise OutputError(
                    f"{self.dir}: is not empty ({shown}) and holds no run (no manifest.json); "
                    "give a new or empty out_dir, or overwrite=True to use it anyway (its chunk "
                    "files are replaced)"
                )
            self._clear = True

    def open(self) -> None:
        """Make the folder ready for the run the constructor checked: create it, remove the
        chunk files of a run it replaces, write the manifest."""
        self._made_dir = not self.dir.exists()
        self.dir.mkdir(parents=True, exist_ok=True)
        if self._clear:
            self._remove_chunks()
        self._write_manifest()

    def undo(self) -> None:
        """After a run that failed before any chunk finished: remove the manifest :meth:`open`
        wrote where there was none, and the folder if it made it and it is empty again (a rerun
        with other settings is then not refused as "another run"). A folder that held a run
        keeps its manifest (the run resumes there)."""
        if not self._fresh or self.done:
            return
        try:
            self.mpath.unlink(missing_ok=True)
            if self._made_dir and not any(self.dir.iterdir()):
                self.dir.rmdir()
        except OSError:  # the run's own error is the one to report
            pass

    def _remove_chunks(self) -> None:
        for f in self.dir.glob("chunk-*.npz"):
            f.unlink()

    def path(self, k: int) -> Path:
        return self.dir / f"chunk-{k:05d}.npz"

    def _write_manifest(self) -> None:
        m = dict(self.manifest)
        m["done"] = sorted(self.done)
        write_atomic(self.mpath, json.dumps(m, indent=1) + "\n", overwrite=True)

    def save(self, k: int, arrays: dict) -> None:
        buf = io.BytesIO()
        np.savez(buf, **arrays)
        write_atomic(self.path(k), buf.getvalue(), overwrite=True)
        self.done.add(k)
        self._write_manifest()

    def load(self, k: int, count: int, n_fields: int) -> dict:
        """Chunk ``k``'s arrays, checked: ``count`` instances, ``n_fields`` curve fields; a file
        that cannot be read as that is damaged (OutputError, one line)."""
        p = self.path(k)
        fix = "delete it and run again: the run recomputes it"
        try:
            with np.load(p) as z:
                d = {key: z[key] for key in z.files}
        except (OSError, ValueError, EOFError, KeyError, zipfile.BadZipFile) as e:
            raise OutputError(f"{p}: damaged chunk file ({type(e).__name__}); {fix}") from None
        need = ("values", "ok", "efl", "D_um", "D_cal_um", "K")
        missing = [key for key in need if key not in d]
        if missing:
            raise OutputError(f"{p}: damaged chunk file (no {', '.join(missing)}); {fix}")
        for key, v in d.items():
            bad_curve = key in CURVES and (v.ndim != 2 or v.shape[1] != n_fields)
            if v.ndim == 0 or v.shape[0] != count or bad_curve:
                raise OutputError(
                    f"{p}: damaged chunk file ({key} has shape {v.shape}, this run's chunk "
                    f"holds {count} instances of {n_fields} fields); {fix}"
                )
        return d


def _differences(keys: list, old: dict, new: dict) -> str:
    """The manifest keys that differ, in words, with the values of the small ones."""
    out = []
    for k in keys:
        w = _MANIFEST_WORDS.get(k, k)
        if k in ("seed", "n", "chunk_size", "compensator", "lens") and k in old:
            w += f": {old[k]} there, {new[k]} here"
        out.append(w)
    return "; ".join(out)


# ------------------------------------------------------------------------------ the result
@dataclass(frozen=True, eq=False)
class MonteCarloResult:
    """A Monte Carlo run (module docstring).

    Attributes
    ----------
    outputs : ToleranceOutputs or None
        Every instance, in instance order (``summary="exact"``); None for a streamed summary,
        which never holds all instances.
    values : (n, n_items) the perturbations (items' units), or None (streamed).
    nominal : ToleranceOutputs (1 instance).
    names : list of str, item labels.
    seed, n, chunk_size : int
    generator : str
    compensator : str
    fields_deg : (F,) degrees
    percentiles : (P,) the envelope levels, %.
    envelope_um, envelope_cal_um : (P, F) percentiles over ok instances of D_um and D_cal_um.
    stats : dict name -> dict(mean, std, min, max, p2.5, p97.5) of the scalar outputs (units of
        :class:`ToleranceOutputs`) over ok instances (finite values; ``"g"`` only when g was
        computed, with ``"n"`` the number of instances whose g is determined).
    g_object_distance : float or None, the object plane s' of g (mm from the first vertex).
    elapsed_s : float, wall time of this call.
    resumed_chunks : int, chunks read back from ``out_dir`` instead of computed.
    out_dir : str or None
    lens_hash, spec_hash : str
    summary_method : ``"exact"`` (statistics over the gathered instances; exact percentiles) or
        ``"streaming"`` (computed chunk by chunk, :mod:`distortion.tolerance.summary`).
    streamed : the :class:`~distortion.tolerance.summary.StreamedSummary` (streaming), else None.
    limits : ((limit µm, field deg), ...) the yields counted during the run.
    """

    outputs: ToleranceOutputs
    values: np.ndarray
    nominal: ToleranceOutputs
    names: list
    seed: int
    n: int
    chunk_size: int
    generator: str
    compensator: str
    fields_deg: np.ndarray
    percentiles: np.ndarray
    envelope_um: np.ndarray
    envelope_cal_um: np.ndarray
    stats: dict
    elapsed_s: float
    resumed_chunks: int
    out_dir: str | None
    lens_hash: str
    spec_hash: str
    g_object_distance: float | None = None
    summary_method: str = "exact"
    streamed: StreamedSummary | None = None
    limits: tuple = ()

    @property
    def n_ok(self) -> int:
        if self.outputs is None:
            return int(self.streamed.n_ok)
        return int(np.count_nonzero(self.outputs.ok))

    def yield_fraction(self, limit_um: float, field_deg: float, calibrated: bool = False) -> float:
        """Fraction of all instances with |D| < ``limit_um`` at ``field_deg`` (each instance's
        curve interpolated linearly; failed instances count as out of limit). ``calibrated``:
        D_cal_um instead of the raw D_um. A streamed run answers the limits it counted
        (``limits=`` of :func:`monte_carlo`) and raises ValueError for any other. A limit ≤ 0 or a
        negative field raises :class:`ToleranceInputError` (a ValueError); a limit below 0.1 µm
        warns that it looks like millimetres (once, with ``limits=``, when the run starts)."""
        counted = (
            (float(limit_um), float(field_deg)) in self.limits
            if _is_real(limit_um, field_deg)
            else False
        )
        limit_um, field_deg = check_yield_limit(limit_um, field_deg, "yield_fraction limit",
                                                warn=not counted)  # fmt: skip
        j, w = interpolation_weights(self.fields_deg, field_deg)
        if self.outputs is None:
            key = (float(limit_um), float(field_deg))
            if key not in self.streamed.limits:
                raise ValueError(
                    f"this streamed run counted the yields {list(self.streamed.limits)} only; "
                    f"pass limits=[({limit_um:g}, {field_deg:g})] to monte_carlo"
                )
            k = self.streamed.limits.index(key)
            y = self.streamed.yields_cal if calibrated else self.streamed.yields_raw
            return float(int(y[k]) / max(self.n, 1))
        D = self.outputs.D_cal_um if calibrated else self.outputs.D_um
        return float(yield_counts(D, self.outputs.ok, j, w, limit_um) / max(self.n, 1))

    def percentile_values(self, name: str, levels) -> np.ndarray:
        """Percentiles (``levels`` in %) of a scalar output (or ``K1``..) over the ok instances
        with a finite value: exact (numpy) for an exact summary, from the histogram (within one
        bin width) for a streamed one."""
        if self.outputs is None:
            return self.streamed.percentiles(name, levels)
        v = self._values(name)
        lev = np.asarray(levels, dtype=float)
        return np.percentile(v, lev) if v.size else np.full(lev.shape, np.nan)

    def histogram(self, name: str, bins: int | None = None) -> tuple[np.ndarray, np.ndarray]:
        """(counts, edges) of a scalar output over the ok instances with a finite value, for
        plots: ``bins`` equal bins between its min and max (default ~√n, 10..60)."""
        if self.outputs is None:
            return self.streamed.histogram(name, bins or 50)
        v = self._values(name)
        if v.size == 0:
            return np.zeros(0, dtype=np.int64), np.zeros(1)
        nb = bins or min(60, max(10, int(np.sqrt(v.size))))
        return np.histogram(v, bins=nb)

    def _values(self, name: str) -> np.ndarray:
        o = self.outputs
        if name.startswith("K") and name[1:].isdigit():
            v = o.K[:, int(name[1:]) - 1]
        else:
            v = getattr(o, name)
        v = np.asarray(v, dtype=float)[np.asarray(o.ok, dtype=bool)]
        return v[np.isfinite(v)]

    def summary(self) -> dict:
        """JSON-ready summary (floats and lists; keys carry units): bit-identical for the same
        inputs whatever the chunking, the workers or a resume."""
        return {
            "format": FORMAT,
            "n": self.n,
            "n_ok": self.n_ok,
            "seed": self.seed,
            "generator": self.generator,
            "compensator": self.compensator,
            "lens_hash": self.lens_hash,
            "spec_hash": self.spec_hash,
            "items": list(self.names),
            "fields_deg": [float(v) for v in self.fields_deg],
            "percentiles": [float(v) for v in self.percentiles],
            "nominal_D_um": [float(v) for v in self.nominal.D_um[0]],
            "nominal_D_cal_um": [float(v) for v in self.nominal.D_cal_um[0]],
            "envelope_D_um": [[float(v) for v in row] for row in self.envelope_um],
            "envelope_D_cal_um": [[float(v) for v in row] for row in self.envelope_cal_um],
            "stats": {k: {s: float(x) for s, x in v.items()} for k, v in self.stats.items()},
            "summary_method": self.summary_method,
            **self._streaming_summary(),
            "units": {
                "D_um": "um",
                "efl": "mm",
                "image_z": "mm",
                "focus_shift": "mm",
                "k0": "mm",
                "c": "mm",
                "x0": "mm",
                "y0": "mm",
                "P1": "1/mm",
                "P2": "1/mm",
                "S1": "1/mm",
                "S2": "1/mm",
                "P1_raw": "1/mm",
                "P2_raw": "1/mm",
                "fit_rms_um": "um",
                "g": "1",
            },  # fmt: skip
            **self._g_summary(),
        }

    def _streaming_summary(self) -> dict:
        if self.streamed is None:
            return {}
        ss = self.streamed
        return {
            "percentile_method": PERCENTILE_METHOD.format(
                bins=ss.bins, last=min(ss.block, ss.n) - 1, widen=ss.widen
            ),
            "summary_block": ss.block,
            "summary_bins": ss.bins,
            "yield_counts": [
                {"limit_um": a, "field_deg": b, "raw": int(r), "calibrated": int(c)}
                for (a, b), r, c in zip(ss.limits, ss.yields_raw, ss.yields_cal, strict=True)
            ],
        }

    def _g_summary(self) -> dict:
        if self.g_object_distance is None:
            return {}
        from .gfactor import DEFINITION

        od = self.g_object_distance
        return {
            "g_object_distance_mm": od if math.isfinite(od) else "inf",
            "g_definition": DEFINITION,
        }

    def __repr__(self) -> str:
        return (
            f"MonteCarloResult({self.n} instances ({self.n_ok} ok), seed {self.seed}, "
            f"compensator {self.compensator}, {self.elapsed_s:.3g} s)"
        )


def _is_real(*v) -> bool:
    try:
        return all(math.isfinite(float(x)) for x in v)
    except (TypeError, ValueError):
        return False


def _stats(v: np.ndarray) -> dict:
    v = v[np.isfinite(v)]
    if v.size == 0:
        return {k: math.nan for k in ("mean", "std", "min", "max", "p2.5", "p97.5")}
    return {
        "mean": float(np.mean(v)),
        "std": float(np.std(v, ddof=1)) if v.size > 1 else math.nan,
        "min": float(np.min(v)),
        "max": float(np.max(v)),
        "p2.5": float(np.percentile(v, 2.5)),
        "p97.5": float(np.percentile(v, 97.5)),
    }


def _envelope(D: np.ndarray, ok: np.ndarray, q: np.ndarray) -> np.ndarray:
    rows = D[ok]
    if rows.shape[0] == 0:
        return np.full((q.size, D.shape[1]), np.nan)
    return np.percentile(rows, q, axis=0)


# ------------------------------------------------------------------------------ the driver
def monte_carlo(
    lens: Lens,
    spec: ToleranceSpec,
    n: int | None = None,
    *,
    seed: int | None = None,
    fields_deg=None,
    object_distance: float | None = None,
    wavelength: float | None = None,
    chunk_size: int | None = None,
    out_dir=None,
    resume: bool = True,
    overwrite: bool = False,
    executor=None,
    progress: Callable[[int, int], None] | None = None,
    grid_rings=DEFAULT_RINGS,
    grid_azimuths: int = DEFAULT_AZIMUTHS,
    radial_terms: int = 3,
    percentiles=DEFAULT_PERCENTILES,
    g_object_distance=None,
    limits=(),
    summary: str = "auto",
    summary_block: int = SUMMARY_BLOCK,
    summary_bins: int = SUMMARY_BINS,
    setup: ToleranceSetup | None = None,
    allow_large: bool = False,
) -> MonteCarloResult:
    """Monte Carlo of ``n`` instances of ``lens`` under ``spec`` (module docstring).

    Parameters
    ----------
    n, seed, chunk_size : int
        Default: the spec's ``[monte_carlo]`` samples / seed / chunk, else 1000 / 0 / 256. Whole
        numbers (an int, not a float or a bool): n, chunk_size ≥ 1, seed ≥ 0.
    fields_deg : array, degrees
        Curve fields along +y (default 50 from 0 to the lens's max field).
    object_distance : float, mm (positive magnitude; inf), default the lens's.
    wavelength : float, nm, default the lens's reference wavelength.
    out_dir : path or None
        Folder for chunks, manifest and summary.json; None keeps nothing on disk. Written only
        once the run can start (module docstring).
    resume, overwrite : bool
        Continue a matching run found in ``out_dir``; replace any other run there.
    executor : None | "local" | "local:N" | "tcp://HOST:PORT" | distributed.Client
        None: this process, numba threads over instances; otherwise Dask (imported only then;
        :func:`raytrace.executors.dask_client`: "local" is a LocalCluster of one worker per
        CPU): chunks (instance ranges) are submitted with the shared setup scattered once, at
        most a few per worker at a time.
    progress : callable(done, total) or None
        Called after every finished chunk with instance counts.
    grid_rings, grid_azimuths, radial_terms
        The 2-D fit points (fractions of the largest curve field × azimuths) and its radial order.
    percentiles : the envelope levels, %.
    g_object_distance : mm, ``inf``, ``"2m"`` or ``"10x"``, or None
        The object plane s' of Fraser & Shortis's g_ss' (the lens focused at ``object_distance``
        by its compensator; :mod:`distortion.tolerance.gfactor`); None takes the spec's
        ``[outputs] g_object_distance``; without either, g is not computed (NaN).
    limits : ((limit µm, field deg), ...)
        Yields counted during the run (a streamed run can answer only these); a limit > 0 µm
        (below 1 µm it warns: it looks like millimetres), a field ≥ 0.
    summary : "auto" | "exact" | "streaming"
        ``"exact"`` gathers every instance (``outputs``) and takes exact statistics;
        ``"streaming"`` summarises chunk by chunk and never holds all instances
        (:mod:`distortion.tolerance.summary`: exact counts, min, max and yields, means and
        standard deviations by a pairwise merge, percentiles within one histogram bin);
        ``"auto"``: exact up to :data:`EXACT_MAX_INSTANCES` instances, streaming above. The
        choice depends on n only, never on the chunking.
    summary_block, summary_bins : the streamed summary's block of instances and histogram bins.
    setup : a :class:`ToleranceSetup` to reuse (then the field / object / fit arguments are its).
    allow_large : bool
        Run more than :data:`MAX_INSTANCES` instances (the command line's ``--allow-large``).

    Returns
    -------
    MonteCarloResult
        The perturbations and outputs of every instance (``summary_method = "exact"``) or the
        streamed summary, the statistics and envelopes, and the yields counted during the run.

    A ``KeyboardInterrupt`` propagates after the finished chunks are on disk. Warns
    (RuntimeWarning, one line) when more than :data:`FAIL_WARN_FRACTION` of the instances
    cannot be traced (they count as out of every yield limit), naming the items that lie
    furthest out in them; and (:class:`UnitWarning`) for item limits that look like another
    unit (:func:`distortion.tolerance.checks.unit_hint`).
    """
    t_start = time.perf_counter()
    mc = spec.monte_carlo
    n = whole(mc.get("samples", 1000) if n is None else n, "n (instances)", 1)
    seed = whole(mc.get("seed", 0) if seed is None else seed, "seed", 0)
    cs = whole(mc.get("chunk", DEFAULT_CHUNK) if chunk_size is None else chunk_size,
               "chunk_size", 1)  # fmt: skip
    if n > MAX_INSTANCES and not allow_large:
        raise ToleranceInputError(
            f"n {n}: more than {MAX_INSTANCES} instances (a long run, and about "
            f"{n * BYTES_PER_INSTANCE / 1e9:.3g} GB in memory unless the summary is streamed); "
            "pass allow_large=True to run it anyway"
        )
    if summary not in SUMMARY_METHODS:
        raise ToleranceSpecError(f"summary {summary!r}: use one of {', '.join(SUMMARY_METHODS)}")
    levels = check_percentiles(percentiles)
    streaming = summary == "streaming" or (summary == "auto" and n > EXACT_MAX_INSTANCES)
    st = setup or prepare(lens, spec, fields_deg=fields_deg, object_distance=object_distance,
                          wavelength=wavelength, grid_rings=grid_rings,
                          grid_azimuths=grid_azimuths, radial_terms=radial_terms,
                          g_object_distance=g_object_distance)  # fmt: skip
    lims = tuple(check_yield_limit(a, b, "limits") for a, b in limits)
    for _, deg in lims:
        interpolation_weights(st.fields_deg, deg)  # ValueError now, not after the run
    warn_units(spec)
    lh = lens_hash(lens, spec, st.wavelength)
    sh = spec_hash(spec)
    chunks = [(k, k * cs, min(n, (k + 1) * cs)) for k in range(math.ceil(n / cs))]
    results: dict[int, dict] = {}
    acc = None
    if streaming:
        acc = StreamingSummary(n, st.fields_deg, st.radial_terms, lims, block=summary_block,
                               bins=summary_bins)  # fmt: skip
    store = None
    on_disk: set[int] = set()
    if out_dir is not None:
        manifest = {"format": FORMAT, "lens": lens.name, "lens_hash": lh, "spec_hash": sh,
                    "settings_hash": _settings_hash(st), "seed": seed, "n": n,
                    "chunk_size": cs, "generator": GENERATOR,
                    "compensator": spec.compensator.type}  # fmt: skip
        # the folder is checked now and written only once the run can start (below)
        store = _Store(out_dir, manifest, resume, overwrite, legacy_spec_hash(spec))
        on_disk = set(store.done)
    # Dask not installed, a scheduler out of reach: refused here, before the folder is written
    client, close = (None, None)
    if executor is not None and any(k not in on_disk for k, _, _ in chunks):
        client, close = dask_client(executor)
    try:
        if store is not None:
            store.open()
        resumed = len(on_disk)
        done_count = sum(b - a for k, a, b in chunks if k in on_disk)
        if progress is not None and done_count:
            progress(done_count, n)

        half = np.array([max(abs(it.min), abs(it.max)) for it in spec.items])
        failed = {"n": 0, "bad": np.zeros(spec.n_items), "good": np.zeros(spec.n_items)}

        def feed(k: int, a: int, d: dict) -> None:
            """A chunk's arrays into the summary (streaming) or the gathered results (exact)."""
            bad = ~np.asarray(d["ok"], dtype=bool)
            if bad.any():  # how far out each item lies in the failed instances, and in the others
                r = np.abs(np.asarray(d["values"], dtype=float)) / half
                failed["n"] += int(np.count_nonzero(bad))
                failed["bad"] += r[bad].sum(axis=0)
                failed["good"] += r[~bad].sum(axis=0)
            if acc is not None:
                acc.add(a, d)
            else:
                results[k] = d

        def finish(k: int, a: int, b: int, d: dict) -> None:
            nonlocal done_count
            if store is not None:
                store.save(k, d)
            feed(k, a, d)
            done_count += b - a
            if progress is not None:
                progress(done_count, n)

        # the chunks that hold block 0 of a streamed summary come first (its range fixes the
        # histograms); then every chunk in order (local) or as workers finish them (Dask)
        block0 = summary_block if streaming else 0
        first = [c for c in chunks if c[1] < block0]
        rest = [c for c in chunks if c[1] >= block0]
        if executor is None:
            for k, a, b in first + rest:
                if k in on_disk:
                    feed(k, a, store.load(k, b - a, st.n_curve))
                else:
                    finish(k, a, b, run_chunk(st, seed, a, b, parallel=True))
        else:
            # hash=False: a key of its own for each run. The default content-hashed key is the
            # same for a second run with the same setup on the same client, and the first run's
            # release of that key then deleted the second run's data ("lost dependencies")
            shared = client.scatter(st, broadcast=True, hash=False) if client is not None else None
            for group in (first, rest):
                for k, a, b in group:
                    if k in on_disk:
                        feed(k, a, store.load(k, b - a, st.n_curve))
                todo = [c for c in group if c[0] not in on_disk]
                if todo:
                    _run_dask(client, shared, seed, todo, finish)
    except Exception:
        if store is not None:
            store.undo()  # failed before any chunk finished: the folder as it was
        raise
    finally:
        if close is not None:
            close()
    _warn_failed(spec, failed, n, half)
    nom = evaluate(st, np.zeros((1, spec.n_items)), parallel=False)
    q = np.asarray(levels, dtype=float)
    has_g = st.g is not None
    names = [k for k in SCALARS if k != "g" or has_g]
    if acc is not None:
        ss = acc.result()
        outs = values = None
        stats = {k: ss.stats(k) for k in names}
        for i in range(st.radial_terms):
            stats[f"K{i + 1}"] = ss.stats(f"K{i + 1}")
        if has_g:
            stats["g"]["n"] = float(ss.count[ss.index("g")])
        F = st.fields_deg.size
        env = np.stack([ss.percentiles(f"D_um[{j}]", q) for j in range(F)], axis=1)
        envc = np.stack([ss.percentiles(f"D_cal_um[{j}]", q) for j in range(F)], axis=1)
    else:
        ss = None
        parts = [results[k] for k, _, _ in chunks]
        allv = {key: np.concatenate([p[key] for p in parts], axis=0) for key in parts[0]}
        values = allv.pop("values")
        outs = ToleranceOutputs.from_arrays(st.fields_deg, allv)
        ok = outs.ok.astype(bool)
        stats = {k: _stats(getattr(outs, k)[ok]) for k in names}
        for i in range(outs.K.shape[1]):
            stats[f"K{i + 1}"] = _stats(outs.K[ok, i])
        if has_g:
            stats["g"]["n"] = float(np.count_nonzero(np.isfinite(outs.g[ok])))
        env = _envelope(outs.D_um, ok, q)
        envc = _envelope(outs.D_cal_um, ok, q)
    res = MonteCarloResult(
        outputs=outs,
        values=values,
        nominal=nom,
        names=spec.names(),
        seed=seed,
        n=n,
        chunk_size=cs,
        generator=GENERATOR,
        compensator=spec.compensator.type,
        fields_deg=st.fields_deg,
        percentiles=q,
        envelope_um=env,
        envelope_cal_um=envc,
        stats=stats,
        elapsed_s=time.perf_counter() - t_start,
        resumed_chunks=resumed,
        out_dir=None if out_dir is None else str(out_dir),
        lens_hash=lh,
        spec_hash=sh,
        g_object_distance=None if st.g is None else st.g.object_distance,
        summary_method="streaming" if streaming else "exact",
        streamed=ss,
        limits=lims,
    )
    if store is not None:
        write_atomic(store.dir / "summary.json", json.dumps(res.summary(), indent=1) + "\n",
                     overwrite=True)  # fmt: skip
    return res


def _warn_failed(spec: ToleranceSpec, failed: dict, n: int, half: np.ndarray) -> None:
    """One RuntimeWarning when more than :data:`FAIL_WARN_FRACTION` of the ``n`` instances could
    not be traced: how many, and the items whose draws lie furthest out (in units of their
    limit) in the failed instances compared with the others."""
    nf = failed["n"]
    if nf <= FAIL_WARN_FRACTION * n:
        return
    mb = failed["bad"] / nf
    mg = failed["good"] / max(n - nf, 1)
    excess = mb - mg if n > nf else mb
    order = [k for k in np.argsort(-excess, kind="stable") if excess[k] > 0.05][:3]
    f = split_where(where_of(spec, 0))[0]
    named = ", ".join(f"{spec.items[k].name} ({split_where(where_of(spec, k))[1]})"
                      for k in order)  # fmt: skip
    most = f"; the failed lenses lie furthest out in {named}" if named else ""
    warnings.warn(
        f"{nf} of {n} lenses ({100 * nf / n:.1f} %) cannot be traced (chief rays or image plane "
        f"fail); they count as out of every yield limit and are left out of the statistics"
        f"{most}; check {'those' if named else 'the'} limits{f' in {f}' if f else ''} (units: "
        "mm, degrees, fringes)",
        RuntimeWarning,
        stacklevel=3,
    )


#: chunks in flight per Dask worker (a sliding window: results are taken and released as they
#: finish, so neither the cluster nor the client holds the outputs of the whole run)
DASK_WINDOW_PER_WORKER = 4


def _run_dask(client, shared, seed: int, todo: list, finish) -> None:
    """Run the chunks ``todo`` [(k, start, stop), ...] on ``client`` with at most
    :data:`DASK_WINDOW_PER_WORKER` per worker in flight; ``finish(k, start, stop, arrays)`` for
    each as it completes (in any order)."""
    from distributed import as_completed

    workers = max(1, len(client.scheduler_info().get("workers", {})))
    window = DASK_WINDOW_PER_WORKER * workers
    pending = iter(todo)
    futs = {}

    def submit() -> bool:
        nxt = next(pending, None)
        if nxt is None:
            return False
        k, a, b = nxt
        f = client.submit(run_chunk, shared, seed, a, b, False, pure=False)
        futs[f] = nxt
        ac.add(f)
        return True

    ac = as_completed()
    try:
        for _ in range(window):
            if not submit():
                break
        for fut in ac:
            k, a, b = futs.pop(fut)
            d = fut.result()
            fut.release()
            finish(k, a, b, d)
            submit()
    except BaseException:
        for fut in futs:
            fut.cancel()
        raise
