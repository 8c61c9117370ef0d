"""In-process A/B of the bulk ray-trace kernel: this checkout against earlier revisions.

    python benchmarks/kernel_ab.py                         # against f4081fc (the first wave)
    python benchmarks/kernel_ab.py --also 43d74ce --rounds 61
    python benchmarks/kernel_ab.py --threads 2             # the prange kernel, wall time

``benchmarks/ab.py`` runs each revision end to end in fresh processes; on a 2-core VM its bulk
row moves by 10-40 % between processes of the *same* code, because a fresh process pays the
first-touch page faults of its 8 MB output arrays (the count of transparent huge pages it gets
varies from process to process). That hides differences of a few per cent. This script takes
the kernel module of each revision (``git show``, into a temporary package), loads all of them
into **one** process and calls them on the same 1e6 Cooke-triplet rays into preallocated output
arrays (the memory is touched once, before the rounds), A B ... per round, the order reversed
every other round. Per kernel it reports the median and the 10th percentile of the CPU time
per call (``time.process_time``; wall time for ``--threads 2``), and the ratios of this
checkout's time to each revision's, per round (median, IQR) and of the 10th percentiles (the
least disturbed calls; on a shared machine the steadiest estimate).

Revisions before the kernels became a package (``raytrace/kernels.py``: f4081fc) took the vertex
z array instead of the placement table; they get ``geo[:, G_ZV]``. Each revision's kernel is
compiled once into the temporary package's cache (about 30-60 s each; stated, not timed).
Whether each revision's outputs are bit-identical to this checkout's is printed (revisions
before the backward-travel test of issue 13 differ on the rays that test fails). Writes
``benchmarks/results/kernel_ab.json``.
"""

from __future__ import annotations

import argparse
import importlib
import inspect
import json
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(ROOT))


def _git_show(ref: str, path: str) -> str | None:
    r = subprocess.run(
        ["git", "-C", str(ROOT), "show", f"{ref}:{path}"], capture_output=True, text=True
    )
    return r.stdout if r.returncode == 0 else None


def _extract(ref: str, dest: Path) -> Path:
    """The bulk kernel of ``ref`` as the package ``kab_<ref>`` in ``dest``; returns its folder."""
    pkg = dest / f"kab_{ref.replace('~', '_').replace('/', '_').replace('^', '_')}"
    pkg.mkdir()
    single = _git_show(ref, "raytrace/kernels.py")
    if single is not None:  # the first wave: one module
        (pkg / "__init__.py").write_text("")
        (pkg / "bulk.py").write_text(single)
        return pkg
    listing = subprocess.run(
        ["git", "-C", str(ROOT), "ls-tree", "--name-only", f"{ref}:raytrace/kernels"],
        capture_output=True,
        text=True,
        check=True,
    ).stdout.split()
    for name in listing:
        if name.endswith(".py"):
            (pkg / name).write_text(_git_show(ref, f"raytrace/kernels/{name}"))
    return pkg


def _rays(n: int) -> tuple[np.ndarray, ...]:
    """The rays of ``benchmarks/ab.py``: 1e6 random rays through the Cooke triplet's entrance."""
    rng = np.random.default_rng(0)
    r = 6.25 * 0.9 * np.sqrt(rng.uniform(0, 1, n))
    t = rng.uniform(0, 2 * np.pi, n)
    a, b = np.radians(rng.uniform(-20, 20, (2, n)))
    d = np.stack([np.tan(a), np.tan(b), np.ones(n)])
    d /= np.linalg.norm(d, axis=0)
    return (r * np.cos(t), r * np.sin(t), np.full(n, -1.0), d[0].copy(), d[1].copy(), d[2].copy())


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--ref", default="f4081fc", help="the A revision (default: f4081fc)")
    ap.add_argument("--also", action="append", default=[], metavar="REV")
    ap.add_argument("--rounds", type=int, default=41)
    ap.add_argument("--rays", type=int, default=1_000_000)
    ap.add_argument("--threads", type=int, default=1, help="1: serial kernel; more: prange")
    args = ap.parse_args()

    import numba

    from raytrace.files.library import load_lens
    from raytrace.files.output import write_atomic
    from raytrace.kernels import bulk as this
    from raytrace.kernels.codes import G_ZV
    from raytrace.packing import pack

    if args.threads > 1:
        numba.set_num_threads(min(args.threads, numba.config.NUMBA_NUM_THREADS))
    packed = pack(load_lens("cooke-triplet-f4"))
    lens_new = (*packed.arrays, True)
    geo = packed.arrays[4]
    lens_old = (*packed.arrays[:4], np.ascontiguousarray(geo[:, G_ZV]), *packed.arrays[5:], True)
    rays = _rays(args.rays)
    n = args.rays
    fn = "trace_batch_serial" if args.threads == 1 else "trace_batch_parallel"
    clock = time.process_time if args.threads == 1 else time.perf_counter
    with tempfile.TemporaryDirectory() as d:
        tmp = Path(d)
        sys.path.insert(0, str(tmp))
        refs = {"A": args.ref, **{f"A{i + 2}": r for i, r in enumerate(args.also)}}
        kernels = {}
        for key, ref in refs.items():
            mod = importlib.import_module(f"{_extract(ref, tmp).name}.bulk")
            k = getattr(mod, fn)
            old = "zv" in inspect.signature(k.py_func).parameters
            kernels[key] = (k, lens_old if old else lens_new)
        kernels["B"] = (getattr(this, fn), lens_new)
        outs = {
            key: ([np.zeros(n) for _ in range(6)], np.zeros(n, np.int8), np.zeros(n, np.int32))
            for key in kernels
        }

        def call(key: str) -> float:
            k, lens_args = kernels[key]
            o, st, sf = outs[key]
            c0 = clock()
            k(*lens_args, *rays, *o, st, sf)
            return clock() - c0

        t0 = time.perf_counter()
        for key in kernels:  # compile (or load from the temporary cache), first call
            call(key)
        compile_s = time.perf_counter() - t0
        same = {
            key: all(
                np.array_equal(a, b, equal_nan=True)
                for a, b in zip(o[0], outs["B"][0], strict=True)
            )
            and np.array_equal(o[1], outs["B"][1])
            and np.array_equal(o[2], outs["B"][2])
            for key, o in outs.items()
        }
        times: dict[str, list[float]] = {key: [] for key in kernels}
        order = list(kernels)
        for r in range(args.rounds):
            for key in order if r % 2 == 0 else order[::-1]:
                times[key].append(call(key))
    ns = packed.arrays[1].shape[0]
    clock_name = "CPU" if args.threads == 1 else "wall"
    print(f"{', '.join(f'{k} = {v}' for k, v in refs.items())}, B = this checkout; {fn}, "
          f"{n} rays x {ns} surfaces, {args.rounds} interleaved rounds, {clock_name} time per "
          f"call; compile and first calls {compile_s:.0f} s (not timed)")  # fmt: skip
    summary = {}
    for key, v in times.items():
        q = sorted(v)
        p10 = q[len(q) // 10]
        summary[key] = {"median_ms": statistics.median(v) * 1e3, "p10_ms": p10 * 1e3,
                        "mrs_p10": ns * n / p10 / 1e6, "bit_identical_to_B": same[key]}  # fmt: skip
        print(f"{key:>3}: median {summary[key]['median_ms']:6.1f} ms   p10 {p10 * 1e3:6.1f} ms "
              f"({summary[key]['mrs_p10']:.1f} M ray-surfaces/s)   outputs bit-identical to B: "
              f"{same[key]}")  # fmt: skip
    for key in refs:
        q = sorted(b / a for a, b in zip(times[key], times["B"], strict=True))
        m = len(q)
        summary[key]["B_over_time"] = {
            "median": statistics.median(q),
            "iqr": [q[m // 4], q[(3 * m) // 4]],
            "p10_ratio": summary["B"]["p10_ms"] / summary[key]["p10_ms"],
        }
        s = summary[key]["B_over_time"]
        print(f"time B/{key}: per round median {s['median']:.3f} (IQR {s['iqr'][0]:.3f}-"
              f"{s['iqr'][1]:.3f}); of the 10th percentiles {s['p10_ratio']:.3f}")  # fmt: skip
    out = HERE / "results"
    out.mkdir(exist_ok=True)
    record = {
        "refs": refs,
        "threads": args.threads,
        "rays": n,
        "summary": summary,
        "times_s": times,
    }
    write_atomic(out / "kernel_ab.json", json.dumps(record, indent=1), overwrite=True)
    print(f"wrote {out / 'kernel_ab.json'}")


if __name__ == "__main__":
    main()
