"""Tolerancing benchmark (issue 15): one exactly stated Monte Carlo workload, run by orthoscope and
by optiland's own tolerancing Monte Carlo in the same process, plus the Dask LocalCluster run.

    python benchmarks/tolerance.py            # 1,000 instances; optiland on 10 (extrapolated)
    python benchmarks/tolerance.py --quick    # toy sizes (seconds): what the smoke test runs

**The workload** (the issue's, stated exactly):

- lens: ``lenses/topogon-like-pestrecov.toml`` (Topogon-like 153.7 mm f/6.3, 9 surfaces, four
  aspheres), object at infinity, its reference wavelength 587.5618 nm;
- tolerances (:func:`workload_spec`): on every element (surfaces 1-2, 3-4, 6-7, 8-9) an element
  decenter TEDX, TEDY of ±0.02 mm and an element tilt TETX, TETY of ±0.02° about the element's
  front vertex, the surfaces after it returning: 16 items, each normal truncated at ±2σ;
- compensator: paraxial refocus (the image plane at the paraxial image of each instance);
- per instance: 50 real chief rays, fields 0…45° along +y (aimed at the centre of the real stop),
  their image heights in the refocused plane and the distortion curve; no 2-D fit, no plots, no
  files;
- 1,000 instances, seed 1 (instance i = the i-th stream of ``SeedSequence(1)``).

orthoscope runs it through the public API (:func:`distortion.tolerance.monte_carlo`, all
instances of a chunk in one kernel launch) on **one core**: this script sets
``NUMBA_NUM_THREADS=1`` before numba is imported (``--threads`` overrides), so the throughput is
per core. The same run is then repeated on a ``distributed.LocalCluster`` of 2 worker processes
(1 thread each); efficiency = local 1-core time / (2 × Dask time), and the summaries of the
two runs must be bit-identical.

optiland 0.6.3 runs the same instances (the values our generator drew, applied through its
``Perturbation`` objects) in ``optiland.tolerancing.monte_carlo.MonteCarlo``: an element move is
its effect on each surface of the element — decenter x, y, z and tilt x, y of the surface
(optiland places every surface absolutely, so the surfaces after the element stay in place, as
OpticStudio's "return"); the compensator is optiland's paraxial image solve
(``optic.updater.image_solve``, run in ``Tolerancing.apply_compensators``); the outputs are 50
``real_y_intercept`` operands on the image surface with optiland's iterative (real) chief-ray
aiming. optiland takes seconds per instance, so it runs ``--optiland-instances`` (default 10)
and its time is extrapolated per instance to 1,000 — said so in the printout.

Agreement: our chief rays of the same instances are traced to optiland's refocused image
planes and compared with its image heights; the ratio is printed VOID above ``AGREE_TOL``
(1e-9 mm). The two paraxial image solves differ slightly (optiland's uses the perturbed vertex
positions, ours the centred part, as OpticStudio's paraxial data do): that difference and its
effect on the heights in each program's own plane are printed apart.

Writes ``benchmarks/results/tolerance.json`` (``--out``).
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import sys
import time
import warnings
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
RESULTS = HERE / "results"
AGREE_TOL = 1e-9  # mm, image heights orthoscope vs optiland, same instances and image planes
AIM_TOL = 1e-12  # optiland's iterative chief-ray aiming tolerance (its default: 1e-6)

#: the elements of the Topogon-like (first, last surface; the stop is surface 5)
ELEMENTS = ((1, 2), (3, 4), (6, 7), (8, 9))
DECENTER_MM = 0.02
TILT_DEG = 0.02
N_FIELDS = 50
MAX_FIELD_DEG = 45.0
SEED = 1


def workload_spec():
    """The benchmark's tolerance spec (module docstring): 16 element items, paraxial refocus."""
    from raytrace.tolerance import spec_from_dict

    items = []
    for a, b in ELEMENTS:
        for t in ("TEDX", "TEDY"):
            items.append({"type": t, "surfaces": [a, b], "limit": DECENTER_MM})
        for t in ("TETX", "TETY"):
            items.append({"type": t, "surfaces": [a, b], "limit": TILT_DEG})
    return spec_from_dict(
        {
            "name": "benchmark: element decenters and tilts, every element",
            "compensator": "paraxial-refocus",
            "tolerances": items,
        },
        path="benchmarks/tolerance.py",
    )


def fields_deg():
    import numpy as np

    return np.linspace(0.0, MAX_FIELD_DEG, N_FIELDS)


def load_workload_lens():
    from raytrace.files.library import load_lens

    return load_lens("topogon-like-pestrecov")


# ------------------------------------------------------------------------------ orthoscope
def run_ours(lens, spec, n: int, executor=None, chunk_size: int = 256):
    """One Monte Carlo run of the workload; (seconds, result)."""
    from distortion.tolerance import monte_carlo

    t0 = time.perf_counter()
    res = monte_carlo(lens, spec, n, seed=SEED, fields_deg=fields_deg(), grid_rings=(),
                      chunk_size=chunk_size, executor=executor)  # fmt: skip
    return time.perf_counter() - t0, res


def image_heights(res, idx):
    """Image heights y' (mm) of instances ``idx`` in their refocused planes from a
    MonteCarloResult: y' = F0_i tan(alpha) + D (D_um is y' - F0_i tan alpha)."""
    import numpy as np

    o = res.outputs
    t = np.tan(np.radians(np.asarray(o.fields_deg)))
    return o.k0[idx, None] * t[None, :] + o.D_um[idx] * 1e-3


def time_ours(lens, spec, n: int, repeat: int, log) -> dict:
    run_ours(lens, spec, min(n, 64))  # compile / load the kernel cache, prepare the aim
    times = []
    res = None
    for _ in range(repeat):
        dt, res = run_ours(lens, spec, n)
        times.append(dt)
        log(f"  orthoscope {n} instances: {dt:.3f} s")
    best = min(times)
    return {
        "instances": n,
        "times_s": times,
        "best_s": best,
        "median_s": statistics.median(times),
        "per_instance_ms": best / n * 1e3,
        "instances_per_s_per_core": n / best,
        "ok_fraction": float(res.outputs.ok.mean()),
        "summary": res.summary(),
        "result": res,
    }


# ------------------------------------------------------------------------------ optiland
def _element_surface_moves(lens, spec, values):
    """Per instance and element surface: absolute (x, y, z) of the vertex and the tilts (rx, ry)
    in radians that give optiland's surface (``globalize``: v -> Ry(ry) Rx(rx) v + (x, y, z))
    the same axis as our element move ``E = T(zp) (Rx(tx) Ry(ty), d) T(-zp)`` (pivot zp = the
    front vertex; raytrace.tolerance.model's docstring). The surfaces are rotationally
    symmetric, so only the axis direction matters, and optiland's rz is not needed.

    Returns {surface: array (I, 5)} (x, y, z, rx, ry)."""
    import numpy as np

    zv = np.concatenate([[0.0], np.cumsum([s.thickness for s in lens.surfaces[:-1]])])
    col = {(it.type, it.surface, it.last): k for k, it in enumerate(spec.items)}
    out = {}
    for a, b in ELEMENTS:
        dx = values[:, col[("TEDX", a, b)]]
        dy = values[:, col[("TEDY", a, b)]]
        tx = np.radians(values[:, col[("TETX", a, b)]])
        ty = np.radians(values[:, col[("TETY", a, b)]])
        cx, sx, cy, sy = np.cos(tx), np.sin(tx), np.cos(ty), np.sin(ty)
        # Q = Rx(tx) Ry(ty): its columns are the moved axes
        q_z = np.stack([sy, -sx * cy, cx * cy], axis=1)  # Q e_z
        zp = zv[a - 1]
        for s in range(a, b + 1):
            h = zv[s - 1] - zp  # vertex behind the pivot, on the element's axis
            x = dx + h * q_z[:, 0]
            y = dy + h * q_z[:, 1]
            z = zp + h * q_z[:, 2]
            # optiland axis Ry(ry) Rx(rx) e_z = (cos rx sin ry, -sin rx, cos rx cos ry)
            rx = -np.arcsin(q_z[:, 1])
            ry = np.arctan2(q_z[:, 0], q_z[:, 2])
            out[s] = np.stack([x, y, z, rx, ry], axis=1)
    return out


def optiland_monte_carlo(lens, spec, m: int, log) -> dict:
    """optiland's MonteCarlo on instances 0..m-1 of the workload (module docstring)."""
    import numpy as np

    sys.path.insert(0, str(HERE))
    import optiland_adapter as ola
    from optiland.tolerancing.core import Tolerancing
    from optiland.tolerancing.monte_carlo import MonteCarlo
    from optiland.tolerancing.perturbation import BaseSampler

    from raytrace.tolerance import draw_instances

    class TableSampler(BaseSampler):
        """The values our generator drew for instances 0, 1, ... (one per MonteCarlo
        iteration, in order)."""

        def __init__(self, values) -> None:
            self.values = [float(v) for v in values]
            self.i = 0

        def sample(self):
            v = self.values[self.i]
            self.i += 1
            return v

    class ParaxialRefocus(Tolerancing):
        """Tolerancing whose compensator is optiland's paraxial image solve."""

        image_z: list = []

        def apply_compensators(self):
            self.optic.updater.image_solve()
            self.image_z.append(float(self.optic.surfaces.surfaces[-1].geometry.cs.z))
            return {}

    values = draw_instances(spec, SEED, range(m))
    optic = ola.build_optic(lens)
    optic.ray_tracer.set_aiming("iterative", tol=AIM_TOL, max_iter=50)
    tol = ParaxialRefocus(optic)
    moves = _element_surface_moves(lens, spec, values)
    for s, mv in moves.items():
        for k, (kind, axis) in enumerate(
            (("decenter", "x"), ("decenter", "y"), ("decenter", "z"), ("tilt", "x"),
             ("tilt", "y"))
        ):  # fmt: skip
            tol.add_perturbation(kind, TableSampler(mv[:, k]), surface_number=s, axis=axis)
    hy = fields_deg() / MAX_FIELD_DEG  # optiland's normalised field (max field 45 deg)
    wl = optic.primary_wavelength
    for h in hy:
        tol.add_operand(
            "real_y_intercept",
            {"optic": optic, "surface_number": -1, "Hx": 0.0, "Hy": float(h), "Px": 0.0,
             "Py": 0.0, "wavelength": wl},
        )  # fmt: skip
    mc = MonteCarlo(tol)
    with warnings.catch_warnings():
        # optiland warns on every paraxial call that decentered surfaces are treated as
        # centred (its image solve, as ours, uses the centred part)
        warnings.simplefilter("ignore")
        t0 = time.perf_counter()
        mc.run(m)
        dt = time.perf_counter() - t0
    df = mc.get_results()
    names = [c for c in df.columns if "real y intercept" in c]
    heights = df[names].to_numpy(dtype=float)
    log(f"  optiland {m} instances: {dt:.2f} s ({dt / m:.3f} s per instance)")
    return {"instances": m, "time_s": dt, "per_instance_s": dt / m, "heights": heights,
            "image_z": np.array(tol.image_z)}  # fmt: skip


def agreement(lens, spec, opt: dict) -> dict:
    """Our chief rays of the same instances, in optiland's refocused planes (the two image
    solves differ slightly: optiland's uses the perturbed vertex positions, ours the centred
    part), against optiland's image heights: max |Δy'| (mm); and the largest difference of the
    two compensators' image planes (mm), reported apart."""
    import numpy as np

    from raytrace.tolerance import (
        aim_instances,
        draw_instances,
        nominal_aim,
        pack_instances,
        paraxial_batch,
    )

    m = opt["instances"]
    values = draw_instances(spec, SEED, range(m))
    arr = pack_instances(lens, spec, values)
    f = fields_deg()
    cr = aim_instances(arr, nominal_aim(lens, spec, np.zeros_like(f), f), parallel=False)
    y = cr.points_at(opt["image_z"])[:, :, 1]
    z_ours = paraxial_batch(arr, lens.object_distance).z_image
    return {
        "max_dy_mm": float(np.nanmax(np.abs(y - opt["heights"]))),
        "max_image_z_diff_mm": float(np.max(np.abs(z_ours - opt["image_z"]))),
    }


# ------------------------------------------------------------------------------ Dask
def dask_run(lens, spec, n: int, workers: int, local_s: float, local_summary, log) -> dict:
    """The workload on a LocalCluster of ``workers`` processes (1 thread each): time with the
    cluster warm (started before timing, one warm-up run), efficiency against the local
    1-core run, and whether the summary is bit-identical."""
    try:
        from distributed import Client, LocalCluster
    except ImportError as e:
        return {"skipped": f"dask not installed ({e}); pip install 'orthoscope[dask]'"}
    t0 = time.perf_counter()
    cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                           dashboard_address=None)  # fmt: skip
    client = Client(cluster)
    start_s = time.perf_counter() - t0
    try:
        run_ours(lens, spec, min(n, 64), executor=client)  # warm the workers' kernels
        times = []
        for _ in range(2):
            dt, res = run_ours(lens, spec, n, executor=client)
            times.append(dt)
            log(f"  Dask {workers} workers, {n} instances: {dt:.3f} s")
        best = min(times)
        same = json.dumps(res.summary(), sort_keys=True) == json.dumps(
            local_summary, sort_keys=True
        )
    finally:
        client.close()
        cluster.close()
    return {
        "workers": workers,
        "instances": n,
        "cluster_start_s": start_s,
        "times_s": times,
        "best_s": best,
        "instances_per_s": n / best,
        "efficiency": local_s / (workers * best),
        "summary_bit_identical": same,
    }


# ------------------------------------------------------------------------------ report
def summarize(res: dict) -> list[str]:
    o = res["orthoscope"]
    m = res["machine"]
    lines = [
        "",
        f"Tolerancing Monte Carlo benchmark — {m['cpu']}, {m['cpus']} CPUs, numba "
        f"{m['numba']} ({m['numba_threads']} thread), numpy {m['numpy']}, load "
        f"{m['load_start']} -> {m.get('load_end')}",
        f"workload: {res['workload']}",
        "",
        f"orthoscope, 1 core: {o['instances']} instances in {o['best_s']:.3f} s (best of "
        f"{len(o['times_s'])}) = {o['instances_per_s_per_core']:,.0f} instances/s/core "
        f"({o['per_instance_ms']:.3f} ms each; target >= 2,000/s/core: "
        f"{'met' if o['instances_per_s_per_core'] >= 2000 else 'MISSED'}); "
        f"all rays traced in {100 * o['ok_fraction']:.1f} % of instances",
    ]
    opt = res.get("optiland")
    if opt and "skipped" not in opt:
        ratio = opt["per_instance_s"] / (o["per_instance_ms"] * 1e-3)
        void = opt["max_dy_mm"] > AGREE_TOL
        lines += [
            f"optiland {m.get('optiland')} MonteCarlo: {opt['instances']} instances in "
            f"{opt['time_s']:.1f} s = {opt['per_instance_s']:.3f} s per instance -> 1,000 "
            f"instances ~ {1000 * opt['per_instance_s']:.0f} s (extrapolated from "
            f"{opt['instances']})",
            f"ratio optiland / orthoscope per instance: "
            f"{'VOID ' if void else ''}{ratio:,.0f}x (target >= 100x: "
            f"{'met' if ratio >= 100 and not void else 'MISSED' if not void else 'VOID'})",
            f"agreement: image heights of the {opt['instances']} common instances in the same "
            f"planes differ by <= {opt['max_dy_mm']:.2e} mm (limit {AGREE_TOL:g} mm); the two "
            f"paraxial image solves differ by <= {opt['max_image_z_diff_mm']:.1e} mm (optiland "
            f"uses the perturbed vertex positions, orthoscope the centred part), which moves the "
            f"heights in each program's own plane by <= {opt['max_dy_own_planes_mm']:.1e} mm",
        ]
    elif opt:
        lines.append(f"optiland: {opt['skipped']}")
    for d in res.get("dask", []):
        if "skipped" in d:
            lines.append(f"Dask: {d['skipped']}")
            break
        lines.append(
            f"Dask LocalCluster({d['workers']} workers x 1 thread), {d['instances']} instances: "
            f"{d['best_s']:.3f} s = {d['instances_per_s']:,.0f} instances/s; efficiency vs the "
            f"local 1-core run {100 * d['efficiency']:.0f} % (local {d['local_s']:.3f} s for "
            f"the same n); summary bit-identical: {d['summary_bit_identical']}; cluster start "
            f"{d['cluster_start_s']:.1f} s (not timed)"
        )
    return lines


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="toy sizes: a smoke run in seconds")
    ap.add_argument("--instances", type=int, default=1000, help="orthoscope instances")
    ap.add_argument("--optiland-instances", type=int, default=10,
                    help="optiland instances (extrapolated per instance)")  # fmt: skip
    ap.add_argument("--dask-instances", type=int, default=20000,
                    help="a second, larger Dask comparison (besides --instances)")  # fmt: skip
    ap.add_argument("--repeat", type=int, default=3, help="timed orthoscope runs (best taken)")
    ap.add_argument("--threads", type=int, default=1, help="numba threads (default 1: per core)")
    ap.add_argument("--no-optiland", action="store_true")
    ap.add_argument("--no-dask", action="store_true")
    ap.add_argument("--out", default=str(RESULTS / "tolerance.json"), help="JSON output path")
    args = ap.parse_args(argv)
    if "numba" not in sys.modules:
        os.environ["NUMBA_NUM_THREADS"] = str(args.threads)
    import numpy as np

    if args.quick:
        args.instances = min(args.instances, 64)
        args.optiland_instances = min(args.optiland_instances, 1)
        args.dask_instances = None
        args.repeat = 1
    t_start = time.perf_counter()

    def log(msg):
        print(f"[{time.perf_counter() - t_start:6.1f} s]{msg}", file=sys.stderr, flush=True)

    sys.path.insert(0, str(HERE))
    from machine import load, machine_info

    res: dict = {
        "machine": machine_info(),
        "workload": (
            f"topogon-like-pestrecov, TEDX/TEDY +/-{DECENTER_MM} mm and TETX/TETY "
            f"+/-{TILT_DEG} deg on elements {', '.join(f'{a}-{b}' for a, b in ELEMENTS)} "
            f"(normal, 2 sigma), paraxial refocus, {N_FIELDS} real chief rays 0..{MAX_FIELD_DEG:g}"
            f" deg, seed {SEED}"
        ),
    }
    lens = load_workload_lens()
    spec = workload_spec()
    log(" orthoscope")
    ours = time_ours(lens, spec, args.instances, args.repeat, log)
    result = ours.pop("result")
    res["orthoscope"] = ours
    if not args.no_optiland:
        sys.path.insert(0, str(HERE))
        import optiland_adapter as ola

        ok, ver = ola.available()
        res["machine"]["optiland"] = ver if ok else None
        if ok:
            log(" optiland")
            m = min(args.optiland_instances, args.instances)
            opt = optiland_monte_carlo(lens, spec, m, log)
            opt.update(agreement(lens, spec, opt))
            # in the compensators' own planes (informative: the image solves differ)
            dy = np.abs(opt.pop("heights") - image_heights(result, np.arange(m)))
            opt["max_dy_own_planes_mm"] = float(np.nanmax(dy))
            opt["image_z"] = opt["image_z"].tolist()
            res["optiland"] = opt
        else:
            res["optiland"] = {"skipped": f"optiland not available ({ver})"}
    if not args.no_dask:
        sizes = [args.instances]
        if args.dask_instances and args.dask_instances != args.instances:
            sizes.append(args.dask_instances)
        res["dask"] = []
        for n in sizes:
            log(f" Dask, {n} instances")
            if n == args.instances:
                local_s, local_summary = ours["best_s"], ours["summary"]
            else:
                local_s, r = run_ours(lens, spec, n)
                local_summary = r.summary()
                log(f"  orthoscope {n} instances (local, 1 core): {local_s:.3f} s")
            d = dask_run(lens, spec, n, 2, local_s, local_summary, log)
            d["local_s"] = local_s
            res["dask"].append(d)
    res["machine"]["load_end"] = load()
    res["wall_s"] = time.perf_counter() - t_start
    print("\n".join(summarize(res)))
    res["orthoscope"].pop("summary", None)
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    from raytrace.files.output import write_atomic

    write_atomic(out, json.dumps(res, indent=1, default=float), overwrite=True)
    print(f"wrote {out}  (wall time {res['wall_s']:.0f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
