"""Core tracer benchmark: bulk ray throughput and chief-ray curve latency.

Run:  python benchmarks/bench_core.py [--rays 1000000] [--repeat 5]

Lens: Cooke triplet 50 mm f/4 (lenses/cooke-triplet-f4.toml, the issue-2 prescription, stop on the
+19.3 surface). Bulk: random rays over the entrance aperture and ±20° of field, traced with status
codes through the 6 surfaces and transferred to the image plane — counted as 7 ray-surfaces per
ray — with 1 and 2 numba threads (best of --repeat). Latency: a 50-field chief-ray curve through
``chief_rays`` (public API, warm; median of many calls). Also the small-batch crossover between
the serial and parallel kernels (sets the PARALLEL_THRESHOLD of raytrace.trace).

Prints a table and writes JSON to benchmarks/results/bench_core.json.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import time
from pathlib import Path

import numba
import numpy as np

from raytrace.files.library import load_lens
from raytrace.files.output import write_atomic
from raytrace.kernels import bulk as K
from raytrace.packing import pack
from raytrace.trace import chief_rays, trace_rays

RESULTS = Path(__file__).resolve().parent / "results"


def _rays(n: int, seed: int = 0):
    rng = np.random.default_rng(seed)
    r = 6.25 * np.sqrt(rng.uniform(0, 1, n))
    t = rng.uniform(0, 2 * np.pi, n)
    # field angle uniform over the disk of the 20-degree field (any azimuth): inside the field
    w = np.radians(20.0 * np.sqrt(rng.uniform(0, 1, n)))
    phi = rng.uniform(0, 2 * np.pi, n)
    d = np.stack([np.tan(w) * np.cos(phi), np.tan(w) * np.sin(phi), np.ones(n)])
    d /= np.linalg.norm(d, axis=0)
    return r * np.cos(t), r * np.sin(t), np.full(n, -1.0), d[0].copy(), d[1].copy(), d[2].copy()


def _best(fn, repeat: int) -> float:
    best = np.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def bulk(n: int, repeat: int) -> list[dict]:
    lens = load_lens("cooke-triplet-f4")
    p = pack(lens)
    rays = _rays(n)
    rows = []
    for threads in (1, 2):
        if threads > numba.config.NUMBA_NUM_THREADS:
            continue

        def run(threads=threads):
            rb = trace_rays(p, rays[:3], rays[3:], threads=threads)
            rb.at_plane(p.z_image)
            return rb

        rb = run()  # warm (compile / load cache)
        t = _best(run, repeat)
        rows.append(
            {
                "threads": threads,
                "rays": n,
                "seconds": t,
                "mray_surfaces_per_s": 7 * n / t / 1e6,
                "ok_fraction": float(rb.ok.mean()),
            }
        )
    return rows


def crossover(repeat: int = 30) -> list[dict]:
    """Serial vs parallel kernel time for small batches (2 threads)."""
    p = pack(load_lens("cooke-triplet-f4"))
    la = p.arrays
    rows = []
    for n in (1000, 4000, 8000, 16000, 32000, 64000):
        rays = _rays(n, 1)
        out = [np.empty(n) for _ in range(6)]
        st = np.empty(n, np.int8)
        sf = np.empty(n, np.int32)
        args = (*la, True, *rays, *out, st, sf)
        K.trace_batch_serial(*args)
        K.trace_batch_parallel(*args)
        ts = _best(lambda a=args: K.trace_batch_serial(*a), repeat)
        tp = _best(lambda a=args: K.trace_batch_parallel(*a), repeat)
        rows.append({"rays": n, "serial_us": ts * 1e6, "parallel_us": tp * 1e6})
    return rows


def chief_latency(n_fields: int = 50, calls: int = 500) -> dict:
    out = {}
    for name, fmax in (("cooke-triplet-f4", 20.0), ("topogon-us2031792-fig1", 45.0)):
        lens = load_lens(name)
        f = np.linspace(0.0, fmax, n_fields)
        cr = chief_rays(lens, f)  # warm
        ts = []
        for _ in range(calls):
            t0 = time.perf_counter()
            chief_rays(lens, f)
            ts.append(time.perf_counter() - t0)
        out[name] = {
            "fields": n_fields,
            "max_field_deg": fmax,
            "median_ms": float(np.median(ts) * 1e3),
            "min_ms": float(np.min(ts) * 1e3),
            "all_ok": bool(np.all(cr.ok)),
            "traces_per_field": float(cr.iterations.mean()),
        }
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rays", type=int, default=1_000_000)
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args()
    t0 = time.perf_counter()
    chief_rays(load_lens("cooke-triplet-f4"), [0.0, 10.0])
    first_call = time.perf_counter() - t0
    res = {
        "machine": {
            "platform": platform.platform(),
            "cpus": os.cpu_count(),
            "numba": numba.__version__,
            "numba_threads": numba.config.NUMBA_NUM_THREADS,
        },
        "first_call_s": first_call,
        "bulk": bulk(args.rays, args.repeat),
        "crossover": crossover(),
        "chief_rays": chief_latency(),
    }
    print(f"first chief_rays call (import + cache load/compile): {first_call:.2f} s")
    print("\nBulk trace, Cooke triplet f/4 (7 ray-surfaces per ray, target >= 60 M/s)")
    print(f"{'threads':>8} {'rays':>10} {'time ms':>10} {'M ray-surf/s':>14} {'ok':>6}")
    for r in res["bulk"]:
        print(
            f"{r['threads']:>8} {r['rays']:>10} {r['seconds'] * 1e3:>10.1f} "
            f"{r['mray_surfaces_per_s']:>14.1f} {r['ok_fraction']:>6.3f}"
        )
    print("\nSerial / parallel crossover (kernel only)")
    print(f"{'rays':>8} {'serial us':>10} {'parallel us':>12}")
    for r in res["crossover"]:
        print(f"{r['rays']:>8} {r['serial_us']:>10.0f} {r['parallel_us']:>12.0f}")
    print("\nChief-ray curve latency, 50 fields via chief_rays (target <= 0.5 ms warm)")
    for name, r in res["chief_rays"].items():
        print(
            f"  {name:<26} median {r['median_ms']:.3f} ms  min {r['min_ms']:.3f} ms  "
            f"traces/field {r['traces_per_field']:.1f}  all ok {r['all_ok']}"
        )
    RESULTS.mkdir(parents=True, exist_ok=True)
    path = RESULTS / "bench_core.json"
    write_atomic(path, json.dumps(res, indent=2), overwrite=True)
    print(f"\nwrote {path}")


if __name__ == "__main__":
    main()
