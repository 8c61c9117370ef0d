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
rerun with the same inputs computes only the missing ones.
"""

from __future__ import annotations

import hashlib
import io
import json
import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from raytrace.errors import OrthoscopeError, OutputError
from raytrace.files.output import write_atomic
from raytrace.lens import Lens
from raytrace.tolerance import (
    GENERATOR,
    ToleranceSpec,
    ToleranceSpecError,
    draw_instances,
    pack_instances,
)

from .outputs import (
    DEFAULT_AZIMUTHS,
    DEFAULT_RINGS,
    SCALARS,
    ToleranceOutputs,
    ToleranceSetup,
    evaluate,
    prepare,
)

FORMAT = "orthoscope-tolerance-mc-1"
DEFAULT_PERCENTILES = (0.5, 2.5, 16.0, 50.0, 84.0, 97.5, 99.5)
DEFAULT_CHUNK = 256


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
    """Hash of what a spec changes (items in order, compensator, test wavelength)."""
    return _hash(spec.items, spec.compensator, spec.test_wavelength)


def _settings_hash(setup: ToleranceSetup) -> str:
    return _hash(setup.points_deg, setup.object_distance, setup.wavelength, setup.radial_terms,
                 setup.grid_rings, setup.grid_azimuths)  # fmt: skip


# ------------------------------------------------------------------------------ the store
class _Store:
    """Chunk files and the manifest in ``out_dir`` (module docstring)."""

    def __init__(self, out_dir, manifest: dict, resume: bool, overwrite: bool):
        self.dir = Path(out_dir)
        if self.dir.exists() and not self.dir.is_dir():
            raise OutputError(f"{self.dir}: exists and is not a folder; choose another -o")
        self.dir.mkdir(parents=True, exist_ok=True)
        self.mpath = self.dir / "manifest.json"
        self.manifest = manifest
        self.done: set[int] = set()
        if self.mpath.exists():
            try:
                old = json.loads(self.mpath.read_text())
            except (OSError, ValueError) as e:
                raise OutputError(f"{self.mpath}: unreadable manifest ({e}); use a new folder "
                                  "or overwrite=True (--force)") from None  # fmt: skip
            same = all(old.get(k) == manifest[k] for k in manifest if k != "done")
            if not same and not overwrite:
                diff = [k for k in manifest if k != "done" and old.get(k) != manifest[k]]
                raise OutputError(
                    f"{self.dir}: holds another run (different {', '.join(diff)}); use a new "
                    "folder or overwrite=True (--force) to replace it"
                )
            if same and resume:
                self.done = {int(k) for k in old.get("done", []) if self.path(int(k)).exists()}
            elif not same or not resume:
                if not overwrite and old.get("done"):
                    raise OutputError(
                        f"{self.dir}: holds a run; pass resume=True to continue it or "
                        "overwrite=True (--force) to start again"
                    )
                for f in self.dir.glob("chunk-*.npz"):
                    f.unlink()
        self._write_manifest()

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

    def load(self, k: int) -> dict:
        with np.load(self.path(k)) as z:
            return {key: z[key] for key in z.files}


# ------------------------------------------------------------------------------ executors
def _dask_client(executor):
    """(client, close) for an executor spec: a distributed.Client, "local[:N]", "tcp://..."."""
    try:
        import distributed
    except ImportError:
        raise OrthoscopeError(
            "Dask is not installed; install the extra: pip install 'orthoscope[dask]'"
        ) from None
    if isinstance(executor, distributed.Client):
        return executor, None
    if isinstance(executor, str) and executor.startswith("local"):
        n = None
        if ":" in executor:
            try:
                n = int(executor.split(":", 1)[1])
            except ValueError:
                raise OrthoscopeError(
                    f"--dask {executor!r}: write local or local:N (N workers)"
                ) from None
        cluster = distributed.LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                                           dashboard_address=None)  # fmt: skip
        client = distributed.Client(cluster)

        def close():
            client.close()
            cluster.close()

        return client, close
    if isinstance(executor, str) and "://" in executor:
        try:
            client = distributed.Client(executor, timeout="20s")
        except OSError as e:
            raise OrthoscopeError(f"cannot reach the Dask scheduler {executor}: {e}") from None
        return client, client.close
    raise OrthoscopeError(
        f"executor {executor!r} is not known; use None/'local' (this machine), 'local[:N]' "
        "(a Dask LocalCluster), 'tcp://HOST:PORT' or a distributed.Client"
    )


# ------------------------------------------------------------------------------ the result
@dataclass(frozen=True, eq=False)
class MonteCarloResult:
    """A Monte Carlo run (module docstring).

    Attributes
    ----------
    outputs : ToleranceOutputs
        Every instance, in instance order.
    values : (n, n_items) the perturbations (items' units).
    nominal : ToleranceOutputs (1 instance).
    names : list of str, item labels.
    seed, n, chunk_size : int
    generator : str
    compensator : str
    fields_deg : (F,) degrees
    percentiles : (P,) the envelope levels, %.
    envelope_um, envelope_cal_um : (P, F) percentiles over ok instances of D_um and D_cal_um.
    stats : dict name -> dict(mean, std, min, max, p2.5, p97.5) of the scalar outputs (units of
        :class:`ToleranceOutputs`) over ok instances.
    elapsed_s : float, wall time of this call.
    resumed_chunks : int, chunks read back from ``out_dir`` instead of computed.
    out_dir : str or None
    lens_hash, spec_hash : str
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

    @property
    def n_ok(self) -> int:
        return int(np.count_nonzero(self.outputs.ok))

    def yield_fraction(self, limit_um: float, field_deg: float, calibrated: bool = False) -> float:
        """Fraction of all instances with |D| < ``limit_um`` at ``field_deg`` (each instance's
        curve interpolated linearly; failed instances count as out of limit). ``calibrated``:
        D_cal_um instead of the raw D_um."""
        D = self.outputs.D_cal_um if calibrated else self.outputs.D_um
        fd = self.fields_deg
        if not (fd.min() <= field_deg <= fd.max()):
            raise ValueError(
                f"field {field_deg:g} deg is outside the traced {fd.min():g}..{fd.max():g}"
            )
        j = int(np.clip(np.searchsorted(fd, field_deg), 1, fd.size - 1))
        w = (field_deg - fd[j - 1]) / (fd[j] - fd[j - 1])
        d = D[:, j - 1] * (1.0 - w) + D[:, j] * w
        good = self.outputs.ok & np.isfinite(d)
        return float(np.count_nonzero(good & (np.abs(d) < limit_um)) / max(self.n, 1))

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
            },  # fmt: skip
        }

    def __repr__(self) -> str:
        return (
            f"MonteCarloResult({self.n} instances ({self.n_ok} ok), seed {self.seed}, "
            f"compensator {self.compensator}, {self.elapsed_s:.3g} s)"
        )


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
    setup: ToleranceSetup | None = None,
) -> MonteCarloResult:
    """Monte Carlo of ``n`` instances of ``lens`` under ``spec`` (module docstring).

    Parameters
    ----------
    n, seed, chunk_size : int
        Default: the spec's ``[monte_carlo]`` samples / seed / chunk, else 1000 / 0 / 256.
    fields_deg : array, degrees
        Curve fields along +y (default 50 from 0 to the lens's max field).
    object_distance : float, mm (positive magnitude; inf), default the lens's.
    wavelength : float, nm, default the lens's reference wavelength.
    out_dir : path or None
        Folder for chunks, manifest and summary.json; None keeps everything in memory.
    resume, overwrite : bool
        Continue a matching run found in ``out_dir``; replace any other run there.
    executor : None | "local" | "local[:N]" | "tcp://HOST:PORT" | distributed.Client
        None / "local": this process, numba threads over instances; otherwise Dask (imported only
        then): chunks (instance ranges) are submitted with the shared setup scattered once.
    progress : callable(done, total) or None
        Called after every finished chunk with instance counts.
    grid_rings, grid_azimuths, radial_terms
        The 2-D fit points (fractions of the largest curve field × azimuths) and its radial order.
    percentiles : the envelope levels, %.
    setup : a :class:`ToleranceSetup` to reuse (then the field / object / fit arguments are its).

    A ``KeyboardInterrupt`` propagates after the finished chunks are on disk.
    """
    t_start = time.perf_counter()
    mc = spec.monte_carlo
    n = int(mc.get("samples", 1000) if n is None else n)
    seed = int(mc.get("seed", 0) if seed is None else seed)
    cs = int(mc.get("chunk", DEFAULT_CHUNK) if chunk_size is None else chunk_size)
    if n < 1 or cs < 1 or seed < 0:
        raise ToleranceSpecError(
            f"samples {n}, chunk {cs}, seed {seed}: give samples and chunk ≥ 1 and a seed ≥ 0"
        )
    st = setup or prepare(lens, spec, fields_deg=fields_deg, object_distance=object_distance,
                          wavelength=wavelength, grid_rings=grid_rings,
                          grid_azimuths=grid_azimuths, radial_terms=radial_terms)  # fmt: skip
    lh = lens_hash(lens, spec, st.wavelength)
    sh = spec_hash(spec)
    chunks = [(k, k * cs, min(n, (k + 1) * cs)) for k in range(math.ceil(n / cs))]
    results: dict[int, dict] = {}
    store = None
    if out_dir is not None:
        manifest = {"format": FORMAT, "lens": lens.name, "lens_hash": lh, "spec_hash": sh,
                    "settings_hash": _settings_hash(st), "seed": seed, "n": n,
                    "chunk_size": cs, "generator": GENERATOR,
                    "compensator": spec.compensator.type}  # fmt: skip
        store = _Store(out_dir, manifest, resume, overwrite)
        for k in sorted(store.done):
            results[k] = store.load(k)
    resumed = len(results)
    todo = [c for c in chunks if c[0] not in results]
    done_count = sum(b - a for k, a, b in chunks if k in results)
    if progress is not None and done_count:
        progress(done_count, n)

    def finish(k: int, a: int, b: int, d: dict) -> None:
        nonlocal done_count
        results[k] = d
        if store is not None:
            store.save(k, d)
        done_count += b - a
        if progress is not None:
            progress(done_count, n)

    if executor in (None, "local"):
        for k, a, b in todo:
            finish(k, a, b, run_chunk(st, seed, a, b, parallel=True))
    elif todo:
        client, close = _dask_client(executor)
        try:
            from distributed import as_completed

            shared = client.scatter(st, broadcast=True)
            futs = {client.submit(run_chunk, shared, seed, a, b, False, pure=False): (k, a, b)
                    for k, a, b in todo}  # fmt: skip
            try:
                for fut in as_completed(futs):
                    k, a, b = futs[fut]
                    finish(k, a, b, fut.result())
            except BaseException:
                for fut in futs:
                    fut.cancel()
                raise
        finally:
            if close is not None:
                close()
    parts = [results[k] for k, _, _ in chunks]
    allv = {key: np.concatenate([p[key] for p in parts], axis=0) for key in parts[0]}
    values = allv.pop("values")
    outs = ToleranceOutputs.from_arrays(st.fields_deg, allv)
    nom = evaluate(st, np.zeros((1, spec.n_items)), parallel=False)
    q = np.asarray(percentiles, dtype=float)
    ok = outs.ok.astype(bool)
    stats = {k: _stats(getattr(outs, k)[ok]) for k in SCALARS}
    for i in range(outs.K.shape[1]):
        stats[f"K{i + 1}"] = _stats(outs.K[ok, i])
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
        envelope_um=_envelope(outs.D_um, ok, q),
        envelope_cal_um=_envelope(outs.D_cal_um, ok, q),
        stats=stats,
        elapsed_s=time.perf_counter() - t_start,
        resumed_chunks=resumed,
        out_dir=None if out_dir is None else str(out_dir),
        lens_hash=lh,
        spec_hash=sh,
    )
    if store is not None:
        write_atomic(store.dir / "summary.json", json.dumps(res.summary(), indent=1) + "\n",
                     overwrite=True)  # fmt: skip
    return res
