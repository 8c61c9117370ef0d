"""orthoscope benchmark suite (issue 6): one command, a table, JSON and plots.

    python benchmarks/run.py            # full run (a few minutes)
    python benchmarks/run.py --quick    # toy sizes (seconds): checks that everything runs

Side by side in the same run: this project's public API, optiland (optional, ``pip install
.[bench]``; skipped with a message when absent), a plain-numpy vectorised tracer
(benchmarks/numpy_tracer.py) and a minimal hand-written numba loop
(benchmarks/handwritten_numba.py).

Workloads: 1 bulk throughput (Cooke triplet, Super-Angulon, an even-asphere lens; threads 1 and 2),
2 chief-ray distortion-curve latency (50/128/1000 fields; angles and finite object heights),
3 through-focus map (200 planes x 200 fields), 4 one optimizer iteration (Twinplex-like spec),
5 CLI wall time cold / warm (and wall + CPU medians of the start-up commands of
benchmarks/startup.py), 6 peak RSS for 1e7 rays; plus scaling fits (rays, surfaces) and
agreement checks (image heights equal to 1e-9 mm, or the comparison's timing is VOID).

Counting: "ray-surfaces" = rays x refracting surfaces of the lens (the analytic transfer to the
image plane is included in the timed call but NOT counted as a surface).

Writes benchmarks/results/bench.json (``--out``) and benchmarks/results/bench_*.png.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import replace
from pathlib import Path

import numba
import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(HERE))

import handwritten_numba as hw  # noqa: E402
import numpy_tracer as npt  # noqa: E402
import optiland_adapter as ola  # noqa: E402
from machine import load, machine_info  # noqa: E402

from raytrace.files.library import load_lens  # noqa: E402
from raytrace.lens import Lens, Surface  # noqa: E402
from raytrace.materials import AIR, fixed_index  # noqa: E402
from raytrace.packing import pack  # noqa: E402
from raytrace.trace import chief_rays, trace_rays  # noqa: E402

RESULTS = HERE / "results"
AGREE_TOL = 1e-9  # mm
LENSES = {
    "cooke-triplet-f4": "cooke-triplet-f4",
    "super-angulon-de975637": "super-angulon-de975637",
    "cooke-asphere-bench": str(HERE / "lenses" / "cooke-asphere-bench.toml"),
}
TARGETS = {
    "bulk_mrs_1e6_cooke": 100.0,  # M ray-surfaces/s, 2 threads
    "bulk_vs_optiland": 12.0,
    "bulk_vs_handwritten": 1.5,  # project time / hand-written time, at most
    "chief50_ms": 0.5,
    "chief50_vs_optiland": 150.0,
    "map_ms": 20.0,
    "cli_warm_s": 0.7,  # distortion LENS, warm (wall, median)
    "cli_paraxial_s": 0.35,
    "cli_paraxial_zmx_s": 0.4,
}


# ----------------------------------------------------------------------------- helpers
def bench_rays(lens: Lens, n: int, seed: int = 0, frac: float = 0.9):
    """n random real rays: start on z = -1 over ``frac`` of the paraxial entrance-pupil radius,
    directions uniform over the field circle (field angle up to the lens's max, capped at 20 deg,
    any azimuth; unit vectors). Inside the field the bench lenses pass > 99 % of them; the
    corners of a ±20° square of directions reach 28° and meet the Cooke triplet's last element
    beyond its 7.5 mm edge (a negative edge thickness: status "backward")."""
    from raytrace.paraxial import paraxial

    par = paraxial(lens)
    r_ep = 0.5 * par.epd
    fmax = min(20.0, lens.field.value if lens.field.kind == "angle" else 20.0)
    rng = np.random.default_rng(seed)
    r = frac * r_ep * np.sqrt(rng.uniform(0, 1, n))
    t = rng.uniform(0, 2 * np.pi, n)
    w = np.radians(fmax * np.sqrt(rng.uniform(0, 1, n)))  # uniform over the disk of angles
    phi = rng.uniform(0, 2 * np.pi, n)
    d = np.stack([np.tan(w) * np.cos(phi), np.tan(w) * np.sin(phi), np.ones(n)])
    d /= np.linalg.norm(d, axis=0)
    # start in front of the first vertex, on the plane z = zs, aimed through the pupil point
    zs = -1.0
    x = r * np.cos(t) + (zs - par.z_E0) * d[0] / d[2]
    y = r * np.sin(t) + (zs - par.z_E0) * d[1] / d[2]
    return x, y, np.full(n, zs), d[0].copy(), d[1].copy(), d[2].copy()


def best_of(fn, repeat: int, budget_s: float = 5.0) -> float:
    """Best wall time of ``repeat`` calls (fewer when they exceed ``budget_s``); one warm call."""
    fn()
    best = math.inf
    spent = 0.0
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        dt = time.perf_counter() - t0
        best = min(best, dt)
        spent += dt
        if spent > budget_s:
            break
    return best


def median_of(fn, calls: int, budget_s: float = 3.0) -> tuple[float, float]:
    fn()
    ts = []
    t_end = time.perf_counter() + budget_s
    for _ in range(calls):
        t0 = time.perf_counter()
        fn()
        ts.append(time.perf_counter() - t0)
        if time.perf_counter() > t_end:
            break
    return statistics.median(ts), min(ts)


def set_threads(n: int) -> int:
    n = min(n, numba.config.NUMBA_NUM_THREADS)
    numba.set_num_threads(n)
    return n


def agreement(a_xy, b_xy) -> tuple[float, int]:
    """max |Δ| (mm) of image (x, y) over rays valid in both, and that count."""
    (ax, ay), (bx, by) = a_xy, b_xy
    ok = np.isfinite(ax) & np.isfinite(bx) & np.isfinite(ay) & np.isfinite(by)
    if not ok.any():
        return math.inf, 0
    return float(max(np.max(np.abs(ax[ok] - bx[ok])), np.max(np.abs(ay[ok] - by[ok])))), int(
        ok.sum()
    )


def project_image(p, rays, threads=None):
    rb = trace_rays(p, rays[:3], rays[3:], threads=threads)
    return rb.at_plane(p.z_image), rb


def numpy_image(p, rays):
    x, y, z, L, M, N, st = npt.trace_numpy(p, *rays)
    t = (p.z_image - z) / N
    return x + t * L, y + t * M


# ----------------------------------------------------------------------------- 1 bulk
def bulk(sizes, quick: bool, optiland_ok: bool, log) -> dict:
    rows = []
    agree = []
    for key, src in LENSES.items():
        lens = load_lens(src)
        p = pack(lens)
        ns = p.n_surfaces
        op = ola.build_optic(lens) if optiland_ok else None
        has_hw = not np.any(p.kind == 2)
        # agreement on the benchmark rays (unclipped lenses: real rays everywhere)
        na = 2000 if quick else 20000
        rays = bench_rays(lens, na, seed=1)
        (pxy, rb) = project_image(p, rays)
        chk = {"lens": key, "rays": na, "ok_fraction": float(rb.ok.mean())}
        chk["numpy_max_dmm"], _ = agreement(pxy, numpy_image(p, rays))
        if has_hw:
            hx, hy, _ = hw.run(p, *rays)
            chk["handwritten_max_dmm"], _ = agreement(pxy, (hx, hy))
        if op is not None:
            chk["optiland_max_dmm"], chk["optiland_rays_compared"] = agreement(
                pxy, ola.trace_bulk(op, *rays, lens.wavelength)
            )
        agree.append(chk)
        for n in sizes:
            rays = bench_rays(lens, n)
            rep = 15 if n <= 1e6 else 3  # best of (budget 5 s): the machine may be shared
            for threads in (1, 2):
                th = set_threads(threads)
                if th != threads:
                    continue
                t = best_of(lambda r=rays, th=th, p=p: project_image(p, r, th), rep)
                row = {
                    "lens": key,
                    "impl": "orthoscope",
                    "threads": th,
                    "rays": n,
                    "surfaces": ns,
                    "seconds": t,
                }
                rows.append(row)
                if has_hw and n <= 10**6:
                    t = best_of(lambda r=rays, p=p: hw.run(p, *r), rep)
                    rows.append({**row, "impl": "handwritten-numba", "seconds": t})
            set_threads(numba.config.NUMBA_NUM_THREADS)
            if n <= (10**5 if quick else 10**6):
                t = best_of(lambda r=rays, p=p: numpy_image(p, r), 3)
                rows.append(
                    {
                        "lens": key,
                        "impl": "numpy",
                        "threads": 1,
                        "rays": n,
                        "surfaces": ns,
                        "seconds": t,
                    }
                )
                if op is not None:
                    t = best_of(
                        lambda r=rays, op=op, w=lens.wavelength: ola.trace_bulk(op, *r, w),
                        3,
                    )
                    rows.append(
                        {
                            "lens": key,
                            "impl": "optiland",
                            "threads": 1,
                            "rays": n,
                            "surfaces": ns,
                            "seconds": t,
                        }
                    )
            log(f"  bulk {key} n={n:.0e} done")
    for r in rows:
        r["rays_per_s"] = r["rays"] / r["seconds"]
        r["mray_surfaces_per_s"] = r["rays"] * r["surfaces"] / r["seconds"] / 1e6
    return {"rows": rows, "agreement": agree}


def scaling(quick: bool, log) -> dict:
    """Fitted exponents: time ∝ rays^a (Cooke, 1 thread, 1e5..1e7) and ∝ surfaces^b (stacks of
    weak singlets, 1e5 rays, 1 thread)."""
    set_threads(1)
    lens = load_lens("cooke-triplet-f4")
    p = pack(lens)
    ns_rays = [10**4, 3 * 10**4, 10**5] if quick else [10**5, 3 * 10**5, 10**6, 3 * 10**6, 10**7]
    tr = []
    for n in ns_rays:
        rays = bench_rays(lens, n)
        tr.append(
            best_of(lambda r=rays: trace_rays(p, r[:3], r[3:], threads=1), 3 if n < 10**7 else 1)
        )
    a = float(np.polyfit(np.log(ns_rays), np.log(tr), 1)[0])
    counts = [2, 4, 8] if quick else [4, 8, 16, 32, 64]
    ts = []
    n = 10**4 if quick else 10**5
    for m in counts:
        surfs = []
        for _ in range(m // 2):
            surfs.append(Surface(1 / 300.0, 2.0, fixed_index(1.5)))
            surfs.append(Surface(-1 / 300.0, 1.0, AIR))
        surfs[0] = replace(surfs[0], stop=True)
        sl = Lens(name=f"stack{m}", surfaces=tuple(surfs), aperture=lens.aperture, field=lens.field)
        sp = pack(sl)
        rays = bench_rays(lens, n, frac=0.3)
        ts.append(best_of(lambda r=rays, sp=sp: trace_rays(sp, r[:3], r[3:], threads=1), 5))
    b = float(np.polyfit(np.log(counts), np.log(ts), 1)[0])
    b_hi = float(np.polyfit(np.log(counts[-3:]), np.log(ts[-3:]), 1)[0])
    slope, icpt = np.polyfit(counts, ts, 1)  # t = icpt + slope * surfaces
    resid = float(np.max(np.abs(np.polyval([slope, icpt], counts) / np.asarray(ts) - 1.0)))
    a_lo = float(np.polyfit(np.log(ns_rays[:3]), np.log(tr[:3]), 1)[0])
    set_threads(numba.config.NUMBA_NUM_THREADS)
    log("  scaling done")
    return {
        "rays": ns_rays,
        "rays_seconds": tr,
        "exponent_rays": a,
        "exponent_rays_first3": a_lo,
        "surfaces": counts,
        "surfaces_seconds": ts,
        "surfaces_rays": n,
        "exponent_surfaces": b,
        "exponent_surfaces_last3": b_hi,
        "linear_fit_ns_per_ray_surface": float(slope / n * 1e9),
        "linear_fit_intercept_ns_per_ray": float(icpt / n * 1e9),
        "linear_fit_max_rel_residual": resid,
    }


# ----------------------------------------------------------------------------- 2 chief rays
def fkw(fields, kind: str) -> dict:
    """The API keyword for fields of ``kind``."""
    return {"fields_deg": fields} if kind == "angle" else {"object_heights_mm": fields}


def chief(quick: bool, optiland_ok: bool, log) -> dict:
    from distortion.characteristic import characteristic_distortion

    lens = load_lens("cooke-triplet-f4")
    rows = []
    for nf in (50, 128, 1000):
        fa = np.linspace(0.0, 20.0, nf)
        od = 500.0
        fh = np.linspace(0.0, od * math.tan(math.radians(20.0)), nf)
        for kind, f, kw in (("angle", fa, {}), ("height", fh, {"object_distance": od})):
            calls = 50 if quick else 500
            med, mn = median_of(
                lambda f=f, kw=kw, k=kind: chief_rays(lens, **fkw(f, k), **kw), calls
            )
            cr = chief_rays(lens, **fkw(f, kind), **kw)
            medd, _ = median_of(
                lambda f=f, kw=kw, k=kind: characteristic_distortion(lens, **fkw(f, k), **kw),
                calls,
            )
            rows.append(
                {
                    "fields": nf,
                    "field_kind": kind,
                    "chief_rays_ms": med * 1e3,
                    "chief_rays_min_ms": mn * 1e3,
                    "distortion_curve_ms": medd * 1e3,
                    "all_ok": bool(cr.ok.all()),
                    "traces_per_field": float(cr.iterations.mean()),
                }
            )
    out = {"lens": "cooke-triplet-f4", "rows": rows}
    if optiland_ok:
        op = ola.build_optic(lens)
        # agreement: our aimed chief rays, traced by optiland, land on the same image heights
        cr = chief_rays(lens, np.linspace(0.0, 20.0, 50))
        p = pack(lens)
        n = cr.fields.size
        rays = (np.zeros(n), cr.y_start, cr.z_start, np.zeros(n), cr.M_start, cr.N_start)
        ox, oy = ola.trace_bulk(op, *rays, lens.wavelength)
        d, _ = agreement((np.zeros(n), cr.heights_at(p.z_image)), (ox, oy))
        out["optiland_chief_agreement_max_dmm"] = d
        for nf in (50, 128, 1000):
            med, _ = median_of(lambda nf=nf: ola.distortion_curve(op, nf), 5 if quick else 20)
            out.setdefault("optiland_distortion_ms", {})[str(nf)] = med * 1e3
    log("  chief-ray latency done")
    return out


# ----------------------------------------------------------------------------- 3 map
def through_focus(quick: bool, log) -> dict:
    from distortion.characteristic import characteristic_distortion
    from raytrace.paraxial import paraxial

    lens = load_lens("cooke-triplet-f4")
    par = paraxial(lens)
    n = 200
    fields = np.linspace(0.0, 20.0, n)
    sp = (par.z_Fp - par.z_Hp) + np.linspace(-1.0, 1.0, n)  # s' from H' around the focus
    med, mn = median_of(
        lambda: characteristic_distortion(lens, fields, s_prime=sp), 20 if quick else 200
    )
    res = characteristic_distortion(lens, fields, s_prime=sp)
    sweep = []
    for npl in (1, 10, 50, 200, 1000):
        spp = (par.z_Fp - par.z_Hp) + np.linspace(-1.0, 1.0, npl)
        m, _ = median_of(
            lambda spp=spp: characteristic_distortion(lens, fields, s_prime=spp),
            10 if quick else 50,
            1.0,
        )
        sweep.append({"planes": npl, "median_ms": m * 1e3})
    log("  through-focus map done")
    return {
        "planes": n,
        "fields": n,
        "median_ms": med * 1e3,
        "min_ms": mn * 1e3,
        "shape": list(res.Dr.shape),
        "finite_fraction": float(np.isfinite(res.Dr).mean()),
        "planes_sweep_200_fields": sweep,
    }


# ----------------------------------------------------------------------------- 4 optimizer
def optimizer(log) -> dict:
    from raytrace.optimize import evaluate, optimize, read_spec, start_lens

    spec_path = ROOT / "lenses" / "specs" / "twinplex-like-55-525.toml"
    if not spec_path.is_file():
        return {"skipped": f"{spec_path} absent"}
    spec = read_spec(spec_path)
    lens = start_lens(spec)
    t_eval = best_of(lambda: evaluate(lens, spec.operands), 5)
    one = replace(spec, max_evaluations=1)
    t0 = time.perf_counter()
    res = optimize(lens, one)
    t_iter = time.perf_counter() - t0
    log("  optimizer done")
    return {
        "spec": str(spec_path.relative_to(ROOT)),
        "variables": len(spec.variables),
        "operands": len(spec.operands),
        "merit_evaluation_ms": t_eval * 1e3,
        "one_iteration_s": t_iter,
        "evaluations_in_iteration": res.evaluations,
    }


# ----------------------------------------------------------------------------- 5 CLI
def _timed(cmd, env, repeat=1) -> tuple[float, int]:
    best = math.inf
    rc = 0
    for _ in range(repeat):
        t0 = time.perf_counter()
        r = subprocess.run(cmd, env=env, capture_output=True, text=True, cwd=ROOT)
        best = min(best, time.perf_counter() - t0)
        rc = r.returncode
    return best, rc


def cli(quick: bool, log) -> dict:
    lens = "topogon-like-pestrecov"
    try:
        load_lens(lens)
    except Exception:  # noqa: BLE001
        lens = "topogon-us2031792-fig1"
    exe = shutil.which("orthoscope")
    base = [exe] if exe else [sys.executable, "-m", "orthoscope"]
    cmd = [*base, "distortion", lens]
    env = dict(os.environ)
    out = {"lens": lens, "command": " ".join(["orthoscope", "distortion", lens])}
    if not quick:
        with tempfile.TemporaryDirectory() as d:
            env_cold = {**env, "NUMBA_CACHE_DIR": d}
            out["cold_s"], out["cold_rc"] = _timed(cmd, env_cold)
            out["second_run_fresh_cache_s"], _ = _timed(cmd, env_cold)
    _timed(cmd, env)  # make sure the default cache is populated
    out["warm_s"], out["warm_rc"] = _timed(cmd, env, 1 if quick else 5)
    # median wall and CPU time of the start-up commands (benchmarks/startup.py), round-robin
    import startup

    su = startup.measure(1 if quick else 7, breakdown=False, log=log)
    out["startup"] = {
        k: {
            "args": v["args"],
            "target_s": v["target_s"],
            "wall_median_s": v["wall_median_s"],
            "cpu_median_s": v["cpu_median_s"],
        }
        for k, v in su["commands"].items()
    }
    imp = [sys.executable, "-c", "import numpy, numba"]
    out["import_numpy_numba_s"], _ = _timed(imp, env, 1 if quick else 3)
    imp2 = [sys.executable, "-c", "import orthoscope.cli.distortion, raytrace.trace"]
    out["import_project_s"], _ = _timed(imp2, env, 1 if quick else 3)
    out["python_startup_s"], _ = _timed([sys.executable, "-c", "pass"], env, 1 if quick else 3)
    log("  CLI done")
    return out


# ----------------------------------------------------------------------------- 6 memory
RSS_CHILD = """
import resource, numpy as np
from raytrace.files.library import load_lens
from raytrace.packing import pack
from raytrace.trace import trace_rays

def rss():  # current resident set (MB)
    for line in open("/proc/self/status"):
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) / 1024

def peak():
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024

p = pack(load_lens("cooke-triplet-f4"))
n = {n}
trace_rays(p, (np.zeros(10), np.zeros(10), -1.0), (0.0, 0.0, 1.0))
r0 = rss()
rng = np.random.default_rng(0)
x = rng.uniform(-5, 5, n); y = rng.uniform(-5, 5, n); z = np.full(n, -1.0)
L = rng.uniform(-0.3, 0.3, n); M = rng.uniform(-0.3, 0.3, n); N = np.sqrt(1 - L * L - M * M)
r1 = rss()
rb = trace_rays(p, (x, y, z), (L, M, N))
xi, yi = rb.at_plane(p.z_image)
r2 = rss()
print(r0, r1, r2, peak())
"""


def memory(n: int, log) -> dict:
    """Peak RSS of a fresh process that traces n rays (Cooke triplet) and transfers them to the
    image plane; RSS read from /proc/self/status, the peak from getrusage."""
    code = RSS_CHILD.format(n=n)
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT)
    if r.returncode != 0:
        return {"error": r.stderr[-500:]}
    r0, r1, r2, pk = (float(v) for v in r.stdout.split())
    log("  memory done")
    return {
        "rays": n,
        "peak_rss_mb": pk,
        "after_import_mb": r0,
        "after_rays_mb": r1,
        "trace_increment_mb": r2 - r1,
        "ideal_output_mb": n * (6 * 8 + 1 + 4 + 16) / 2**20,
    }


# ----------------------------------------------------------------------------- report
def _fmt_rate(v):
    return f"{v / 1e6:8.2f} M" if v >= 1e5 else f"{v / 1e3:8.1f} k"


def summarize(res: dict) -> list[str]:
    L = []
    L.append(
        f"machine: {res['machine']['cpu']} x{res['machine']['cpus']}, load avg "
        f"{res['machine']['load_start']} (start) / {res['machine'].get('load_end')} (end)"
    )
    L.append("")
    L.append("1. bulk trace (time includes the analytic transfer to the image plane)")
    L.append(
        f"{'lens':<24}{'impl':<19}{'thr':>3}{'rays':>10}{'ms':>10}{'rays/s':>12}"
        f"{'M ray-surf/s':>14}"
    )
    for r in res["bulk"]["rows"]:
        L.append(
            f"{r['lens']:<24}{r['impl']:<19}{r['threads']:>3}{r['rays']:>10.0e}"
            f"{r['seconds'] * 1e3:>10.2f}{_fmt_rate(r['rays_per_s']):>12}"
            f"{r['mray_surfaces_per_s']:>14.1f}"
        )
    L.append("")
    L.append("agreement on the benchmark rays (max |Δ image x, y|, mm; limit 1e-9)")
    for a in res["bulk"]["agreement"]:
        parts = [
            f"{k.replace('_max_dmm', '')} {v:.2e}" + ("" if v <= AGREE_TOL else " VOID")
            for k, v in a.items()
            if k.endswith("_max_dmm")
        ]
        L.append(f"  {a['lens']:<24} ok {a['ok_fraction']:.4f}  " + ", ".join(parts))
    s = res.get("scaling")
    if s:
        L.append(
            f"scaling (1 thread, Cooke): time ∝ rays^{s['exponent_rays']:.3f} over "
            f"{s['rays'][0]:.0e}..{s['rays'][-1]:.0e} (^{s.get('exponent_rays_first3', 0):.3f} "
            f"over the first three sizes)"
        )
        L.append(
            f"  surfaces {s['surfaces']} ({s['surfaces_rays']:.0e} rays): time ∝ "
            f"surfaces^{s['exponent_surfaces']:.3f} (^{s.get('exponent_surfaces_last3', 0):.3f} "
            f"over the last three); linear fit t = "
            f"{s.get('linear_fit_intercept_ns_per_ray', 0):.1f} ns + "
            f"{s.get('linear_fit_ns_per_ray_surface', 0):.2f} ns x surfaces per ray "
            f"(max residual {100 * s.get('linear_fit_max_rel_residual', 0):.1f} %)"
        )
    L.append("")
    c = res["chief"]
    L.append("2. chief-ray curve latency, Cooke triplet (median ms; public API)")
    L.append(
        f"{'fields':>7}{'kind':>8}{'chief_rays':>12}{'distortion':>12}{'traces/f':>10}"
        f"{'optiland':>10}"
    )
    for r in c["rows"]:
        o = c.get("optiland_distortion_ms", {}).get(str(r["fields"]))
        L.append(
            f"{r['fields']:>7}{r['field_kind']:>8}{r['chief_rays_ms']:>12.3f}"
            f"{r['distortion_curve_ms']:>12.3f}{r['traces_per_field']:>10.1f}"
            f"{'' if o is None or r['field_kind'] != 'angle' else f'{o:.2f}':>10}"
        )
    if "optiland_chief_agreement_max_dmm" in c:
        d = c["optiland_chief_agreement_max_dmm"]
        L.append(
            f"  chief rays re-traced by optiland: max |Δy'| {d:.2e} mm"
            + ("" if d <= AGREE_TOL else " VOID")
        )
    m = res["map"]
    L.append(
        f"3. through-focus map {m['planes']}x{m['fields']}: median {m['median_ms']:.3f} ms "
        f"(min {m['min_ms']:.3f})"
    )
    if m.get("planes_sweep_200_fields"):
        L.append(
            "   planes sweep (200 fields): "
            + ", ".join(
                f"{r['planes']}: {r['median_ms']:.2f} ms" for r in m["planes_sweep_200_fields"]
            )
        )
    o = res["optimizer"]
    if "skipped" in o:
        L.append(f"4. optimizer: skipped ({o['skipped']})")
    else:
        L.append(
            f"4. optimizer ({o['spec']}, {o['variables']} vars, {o['operands']} operands): "
            f"merit evaluation {o['merit_evaluation_ms']:.2f} ms, one iteration "
            f"{o['one_iteration_s']:.3f} s ({o['evaluations_in_iteration']} evaluations)"
        )
    k = res["cli"]
    L.append(
        f"5. CLI `{k['command']}`: warm {k['warm_s']:.3f} s"
        + (
            f", cold {k['cold_s']:.2f} s (2nd run {k['second_run_fresh_cache_s']:.2f} s)"
            if "cold_s" in k
            else ""
        )
        + f"; python {k['python_startup_s']:.3f} s, import numpy+numba "
        f"{k['import_numpy_numba_s']:.3f} s, import project {k['import_project_s']:.3f} s"
    )
    for key, v in k.get("startup", {}).items():
        L.append(
            f"   {key}: wall {v['wall_median_s']:.3f} s, CPU {v['cpu_median_s']:.3f} s (medians)"
        )
    mem = res.get("memory")
    if mem and "peak_rss_mb" in mem:
        L.append(
            f"6. peak RSS for {mem['rays']:.0e} rays: {mem['peak_rss_mb']:.0f} MB "
            f"(inputs {mem['after_rays_mb'] - mem['after_import_mb']:.0f} MB, trace + image "
            f"+{mem['trace_increment_mb']:.0f} MB; outputs need {mem['ideal_output_mb']:.0f} MB)"
        )
    L.append("")
    L.append("targets")
    for name, val, tgt, ok in res["targets"]:
        verdict = "" if name.startswith("(info)") else ("met" if ok else "MISSED")
        L.append(f"  {name:<46}{val:>12.3f}  target {tgt:<13}{verdict}")
    return L


def targets(res: dict) -> list:
    out = []
    rows = res["bulk"]["rows"]

    def get(impl, thr, n=10**6, lens="cooke-triplet-f4"):
        for r in rows:
            if (r["impl"], r["threads"], r["rays"], r["lens"]) == (impl, thr, n, lens):
                return r
        return None

    thr = min(2, numba.config.NUMBA_NUM_THREADS)
    n = max(r["rays"] for r in rows if r["rays"] <= 10**6)
    one = get("orthoscope", 1, n)
    if one and thr > 1:
        v = one["mray_surfaces_per_s"]
        out.append(("(info) bulk M ray-surf/s, Cooke, 1e6, 1 thr", v, ">= 100 @2thr", v >= 100))
    me = get("orthoscope", thr, n)
    if me:
        out.append(
            (
                "bulk M ray-surf/s, Cooke, 1e6, 2 thr",
                me["mray_surfaces_per_s"],
                ">= 100",
                me["mray_surfaces_per_s"] >= 100,
            )
        )
        h = get("handwritten-numba", thr, n)
        if h:
            v = me["seconds"] / h["seconds"]
            out.append(("time / hand-written numba (same threads)", v, "<= 1.5", v <= 1.5))
        o = get("optiland", 1, n)
        a = next(a for a in res["bulk"]["agreement"] if a["lens"] == "cooke-triplet-f4")
        if o and "optiland_max_dmm" in a:
            v = o["seconds"] / me["seconds"]
            void = a["optiland_max_dmm"] > AGREE_TOL
            if one and thr > 1:
                v1 = o["seconds"] / one["seconds"]
                out.append(("(info) speed-up vs optiland, 1 thread", v1, ">= 12 @2thr", v1 >= 12))
            out.append(
                (
                    "speed-up vs optiland (VOID if disagree)" if void else "speed-up vs optiland",
                    v,
                    ">= 12",
                    (v >= 12) and not void,
                )
            )
    c = next(r for r in res["chief"]["rows"] if r["fields"] == 50 and r["field_kind"] == "angle")
    out.append(("50-field chief rays ms", c["chief_rays_ms"], "<= 0.5", c["chief_rays_ms"] <= 0.5))
    od = res["chief"].get("optiland_distortion_ms", {}).get("50")
    if od:
        v = od / c["chief_rays_ms"]
        out.append(("speed-up vs optiland Distortion (50)", v, ">= 150", v >= 150))
    out.append(
        ("through-focus map ms", res["map"]["median_ms"], "<= 20", res["map"]["median_ms"] <= 20)
    )
    out.append(("CLI warm s", res["cli"]["warm_s"], "<= 0.7", res["cli"]["warm_s"] <= 0.7))
    su = res["cli"].get("startup", {})
    for key, name in (("paraxial", "CLI paraxial warm s"), ("paraxial_zmx", "CLI paraxial .zmx s")):
        if key in su and su[key]["target_s"] is not None:
            v, t = su[key]["wall_median_s"], su[key]["target_s"]
            out.append((name, v, f"<= {t}", v <= t))
    return out


def _finish_axes(ax, xlabel: str, ylabel: str, title: str) -> None:
    """Axis labels, title, a log-log grid and the legend of one benchmark panel."""
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)


def _save(fig, path_prefix: Path, suffix: str) -> str:
    """Write ``fig`` to ``path_prefix`` + ``suffix`` (PNG, 110 dpi), close it; the path."""
    import matplotlib.pyplot as plt

    fig.tight_layout()
    f = str(path_prefix) + suffix
    fig.savefig(f, dpi=110)
    plt.close(fig)
    return f


def plots(res: dict, path_prefix: Path) -> list[str]:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    files = []
    fig, ax = plt.subplots(figsize=(8, 5.5))
    rows = res["bulk"]["rows"]
    for lens in LENSES:
        for impl in ("orthoscope", "handwritten-numba", "numpy", "optiland"):
            for thr in (1, 2):
                rr = sorted(
                    (r for r in rows if (r["lens"], r["impl"], r["threads"]) == (lens, impl, thr)),
                    key=lambda r: r["rays"],
                )
                if not rr or (lens != "cooke-triplet-f4" and impl != "orthoscope"):
                    continue
                ax.loglog(
                    [r["rays"] for r in rr],
                    [r["rays_per_s"] for r in rr],
                    "o-",
                    label=f"{lens} {impl} {thr}t",
                )
    _finish_axes(
        ax, "rays per call", "rays / s", "Bulk trace throughput (incl. transfer to the image plane)"
    )
    files.append(_save(fig, path_prefix, "_throughput.png"))

    fig, (ax, ax2) = plt.subplots(1, 2, figsize=(12, 5))
    for kind in ("angle", "height"):
        rr = [r for r in res["chief"]["rows"] if r["field_kind"] == kind]
        ax.loglog(
            [r["fields"] for r in rr],
            [r["chief_rays_ms"] for r in rr],
            "o-",
            label=f"chief_rays ({kind})",
        )
        ax.loglog(
            [r["fields"] for r in rr],
            [r["distortion_curve_ms"] for r in rr],
            "s--",
            label=f"characteristic_distortion ({kind})",
        )
    od = res["chief"].get("optiland_distortion_ms")
    if od:
        ks = sorted(od, key=int)
        ax.loglog([int(k) for k in ks], [od[k] for k in ks], "^-", label="optiland Distortion")
    m = res["map"]
    ax.loglog(
        [m["fields"]],
        [m["median_ms"]],
        "k*",
        ms=12,
        label=f"through-focus map {m['planes']} planes x {m['fields']} fields",
    )
    _finish_axes(
        ax, "number of fields", "time per call (ms)", "Distortion-curve latency, Cooke triplet"
    )
    sw = m.get("planes_sweep_200_fields", [])
    ax2.loglog(
        [r["planes"] for r in sw],
        [r["median_ms"] for r in sw],
        "o-",
        label="characteristic_distortion, 200 fields",
    )
    _finish_axes(
        ax2,
        "number of image planes (one trace, analytic transfer)",
        "time per call (ms)",
        "Through-focus map, Cooke triplet",
    )
    files.append(_save(fig, path_prefix, "_latency.png"))
    return files


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="toy sizes: a smoke run in seconds")
    ap.add_argument("--no-optiland", action="store_true", help="skip optiland even if installed")
    ap.add_argument("--max-rays", type=float, default=1e7, help="largest bulk batch (default 1e7)")
    ap.add_argument("--out", default=str(RESULTS / "bench.json"), help="JSON output path")
    ap.add_argument("--no-plots", action="store_true")
    args = ap.parse_args(argv)
    t_start = time.perf_counter()

    def log(msg):
        print(f"[{time.perf_counter() - t_start:6.1f} s]{msg}", file=sys.stderr, flush=True)

    ok, ver = (False, "disabled") if args.no_optiland else ola.available()
    if not ok:
        print(f"optiland not available ({ver}): its columns are skipped (pip install '.[bench]')")
    res = {"machine": {**machine_info(), "optiland": ver if ok else None}}
    sizes = [10**3, 10**4, 10**5] if args.quick else [10**k for k in range(3, 8)]
    sizes = [n for n in sizes if n <= args.max_rays]
    log(" bulk")
    res["bulk"] = bulk(sizes, args.quick, ok, log)
    res["scaling"] = scaling(args.quick, log)
    res["chief"] = chief(args.quick, ok, log)
    res["map"] = through_focus(args.quick, log)
    res["optimizer"] = optimizer(log)
    res["cli"] = cli(args.quick, log)
    res["memory"] = memory(10**5 if args.quick else int(args.max_rays), log)
    res["machine"]["load_end"] = load()
    res["targets"] = targets(res)
    res["wall_s"] = time.perf_counter() - t_start
    res["peak_rss_mb_suite"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print("\n".join(summarize(res)))
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    if not args.no_plots:
        res["plots"] = plots(res, out.with_suffix(""))
        print("plots: " + ", ".join(res["plots"]))
    from raytrace.files.output import write_atomic

    write_atomic(out, json.dumps(res, indent=1, default=float), overwrite=True)
    print(f"wrote {out}  (suite wall time {res['wall_s']:.0f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
