"""A/B benchmark: this checkout against an earlier git revision, interleaved in one run.

    python benchmarks/ab.py                      # against f4081fc (before the reorganisation)
    python benchmarks/ab.py --ref HEAD~3 --rounds 5
    python benchmarks/ab.py --also 43d74ce       # + the general geometry, before the backward test

For each revision a git worktree is made in a temporary folder; every measurement runs in a fresh
Python process with that tree first on ``sys.path``, in the order A B A B ... (``--rounds``
rounds), so machine load falls on both alike; the result is the median over rounds. Before the
rounds each tree is run once so its numba cache is warm (stated in the output): no measurement
includes compilation.

Measured per revision:

* bulk throughput: 1e6 random rays through the Cooke triplet (``cooke-triplet-f4``), 1 and 2
  threads, best of 5 calls inside the process, in M ray-surfaces/s (6 refracting surfaces); for
  one thread also per CPU-second of the process (``bulk_mrs_1t_cpu``: steadier on a busy machine).
  Each call's results are released before the next, so that the calls reuse memory: when they
  were kept, every call paid the first-touch page faults of fresh 8 MB output arrays, which moved
  this row by 10-40 % between processes of the same code. Differences of a few per cent are
  resolved only in one process: ``benchmarks/kernel_ab.py``;
* the 50-field chief-ray curve (Cooke, 0–20°): median of 300 calls, ms;
* the 2-D chief-ray grid (``chief_rays_2d``, ``topogon-us2031792-fig1``, 21 × 21 field angles
  of ±30° on each axis): median of 50 calls, ms, and its mean traces to the stop per field;
* CLI wall time and CPU time (user + system of the child, ``os.wait4``: a busy machine inflates
  it far less than the wall time), warm: ``distortion topogon-like-pestrecov``, ``paraxial
  cooke-triplet-f4`` and ``paraxial`` of a .zmx with catalog glasses
  (tests/data/corpus/optiland/lens_thorlabs_iso_8859_1.zmx of this checkout; ``nan`` for a
  revision that cannot read it) (the console entry of each revision: ``python -m
  distortion.cli`` before the reorganisation, ``python -m orthoscope`` after), with
  byte-compiled sources. ``benchmarks/startup.py`` measures the start-up of this checkout alone.

Prints a table with the ratios B/A (B/A2, ...) and writes benchmarks/results/ab.json.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent

CHILD = r"""
import sys, time, json
import numpy as np
import numba
new = {new}
from {lib} import load_lens
lens = load_lens("cooke-triplet-f4")
if new:
    from raytrace.packing import pack
    from raytrace.trace import chief_rays, trace_rays
    def tr(p, r, threads): return trace_rays(p, r[:3], r[3:], threads=threads)
    def cr(l, f): return chief_rays(l, f)
else:
    from raytrace.lens import pack
    from raytrace.trace import chief_rays, trace_rays
    def tr(p, r, threads): return trace_rays(p, *r, threads=threads)
    def cr(l, f): return chief_rays(l, f)
p = pack(lens)
rng = np.random.default_rng(0)
n = 1_000_000
r = 6.25 * 0.9 * np.sqrt(rng.uniform(0, 1, n)); t = rng.uniform(0, 2 * np.pi, n)
a, b = np.radians(rng.uniform(-20, 20, (2, n)))
d = np.stack([np.tan(a), np.tan(b), np.ones(n)]); d /= np.linalg.norm(d, axis=0)
rays = (r * np.cos(t), r * np.sin(t), np.full(n, -1.0), d[0].copy(), d[1].copy(), d[2].copy())
out = {{}}
for th in (1, 2):
    if th > numba.config.NUMBA_NUM_THREADS:
        continue
    tr(p, rays, th)
    best = best_cpu = 1e9
    for _ in range(5):
        t0 = time.perf_counter(); c0 = time.process_time()
        rb = tr(p, rays, th); xy = rb.at_plane(p.z_image); del rb, xy
        best = min(best, time.perf_counter() - t0)
        if th == 1:
            best_cpu = min(best_cpu, time.process_time() - c0)
    out[f"bulk_mrs_{{th}}t"] = 6 * n / best / 1e6
    if th == 1:
        out["bulk_mrs_1t_cpu"] = 6 * n / best_cpu / 1e6
f = np.linspace(0.0, 20.0, 50)
cr(lens, f)
ts = []
for _ in range(300):
    t0 = time.perf_counter(); cr(lens, f); ts.append(time.perf_counter() - t0)
out["chief50_ms"] = float(np.median(ts) * 1e3)
try:
    from raytrace.trace.chief2d import chief_rays_2d
except ImportError:  # a revision before the 2-D aim
    chief_rays_2d = None
if chief_rays_2d is not None:
    tl = load_lens("topogon-us2031792-fig1")
    X, Y = np.meshgrid(np.linspace(-30.0, 30.0, 21), np.linspace(-30.0, 30.0, 21))
    c2 = chief_rays_2d(tl, X, Y)
    ts = []
    for _ in range(50):
        t0 = time.perf_counter(); chief_rays_2d(tl, X, Y); ts.append(time.perf_counter() - t0)
    out["grid21_ms"] = float(np.median(ts) * 1e3)
    out["grid21_traces"] = float(np.mean(c2.iterations))
print("RESULT", json.dumps(out))
"""


def _tree(ref: str, tmp: Path) -> Path:
    dest = tmp / ref.replace("/", "_").replace("~", "_")
    subprocess.run(
        ["git", "-C", str(ROOT), "worktree", "add", "--detach", str(dest), ref],
        check=True,
        capture_output=True,
    )
    return dest


def _env(tree: Path, tmp: Path) -> dict:
    """Environment of a child that imports the project from ``tree`` only. The children run with
    ``python -S`` (no site hooks: an editable install's import finder would otherwise pick the
    installed tree), with site-packages on PYTHONPATH for numpy / numba."""
    import site

    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(
        [str(tree), str(_lenses_pkg(tree, tmp)), *site.getsitepackages()]
    )
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    return env


def _is_new(tree: Path) -> bool:
    return (tree / "orthoscope" / "cli" / "__init__.py").is_file()


def _lenses_pkg(tree: Path, tmp: Path) -> Path:
    """A folder holding ``orthoscope_lenses`` (the bundled lens package) for ``tree``."""
    d = tmp / f"lenses_{tree.name}"
    if not d.exists():
        d.mkdir()
        (d / "orthoscope_lenses").symlink_to(tree / "lenses")
    return d


def _run_child(tree: Path, tmp: Path) -> dict:
    new = _is_new(tree)
    lib = "raytrace.files.library" if new else "raytrace.library"
    env = _env(tree, tmp)
    code = CHILD.format(new=new, lib=lib)
    r = subprocess.run(
        [sys.executable, "-S", "-c", code], env=env, capture_output=True, text=True, cwd=tmp
    )
    if r.returncode:
        raise RuntimeError(r.stderr[-2000:])
    return json.loads(r.stdout.split("RESULT", 1)[1])


def _cli(tree: Path, tmp: Path, args: list[str], must: bool = True) -> tuple[float, float]:
    """(wall s, CPU s of the child) of one warm CLI run; (nan, nan) for a failed run when not
    ``must``."""
    env = _env(tree, tmp)
    mod = "orthoscope" if _is_new(tree) else "distortion.cli"
    t0 = time.perf_counter()
    p = subprocess.Popen(
        [sys.executable, "-S", "-m", mod, *args],
        env=env,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        cwd=tmp,
    )
    err = p.stderr.read()
    _, status, usage = os.wait4(p.pid, 0)
    dt = time.perf_counter() - t0
    p.stderr.close()
    p.returncode = os.waitstatus_to_exitcode(status)
    if p.returncode:
        if must:
            raise RuntimeError(err[-2000:].decode(errors="replace"))
        return math.nan, math.nan
    return dt, usage.ru_utime + usage.ru_stime


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--ref", default="f4081fc", help="the A revision (default: f4081fc)")
    ap.add_argument(
        "--also",
        action="append",
        default=[],
        metavar="REV",
        help="a further revision measured in the same rounds (A2, A3, ...), e.g. an "
        "intermediate commit that isolates one change",
    )
    ap.add_argument("--rounds", type=int, default=5)
    args = ap.parse_args()
    refs = {"A": args.ref, **{f"A{i + 2}": r for i, r in enumerate(args.also)}}
    with tempfile.TemporaryDirectory() as d:
        tmp = Path(d)
        trees = {key: _tree(ref, tmp) for key, ref in refs.items()}
        trees["B"] = ROOT
        try:
            for t in trees.values():  # compile once, byte-compile the sources: warm caches
                pkgs = [
                    str(t / p) for p in ("raytrace", "distortion", "orthoscope") if (t / p).is_dir()
                ]
                subprocess.run([sys.executable, "-m", "compileall", "-q", *pkgs], check=False)
                _run_child(t, tmp)
            zmx = ROOT / "tests/data/corpus/optiland/lens_thorlabs_iso_8859_1.zmx"
            cli_cmds = {  # key: (arguments, must succeed)
                "cli_distortion": (["distortion", "topogon-like-pestrecov"], True),
                "cli_paraxial": (["paraxial", "cooke-triplet-f4"], True),
                "cli_paraxial_zmx": (["paraxial", str(zmx)], False),
            }
            for t in trees.values():
                for c, must in cli_cmds.values():
                    _cli(t, tmp, c, must)
            rows: dict[str, dict[str, list[float]]] = {k: {} for k in trees}
            load0 = os.getloadavg()
            for _ in range(args.rounds):
                for key, t in trees.items():
                    for k, v in _run_child(t, tmp).items():
                        rows[key].setdefault(k, []).append(v)
                    for k, (c, must) in cli_cmds.items():
                        wall, cpu = _cli(t, tmp, c, must)
                        rows[key].setdefault(f"{k}_s", []).append(wall)
                        rows[key].setdefault(f"{k}_cpu_s", []).append(cpu)
            load1 = os.getloadavg()
        finally:
            for key in refs:
                subprocess.run(
                    ["git", "-C", str(ROOT), "worktree", "remove", "--force", str(trees[key])],
                    capture_output=True,
                )
    med = {k: {m: statistics.median(v) for m, v in r.items()} for k, r in rows.items()}
    names = ", ".join(f"{k} = {r}" for k, r in refs.items())
    print(f"{names}, B = this checkout; {args.rounds} interleaved rounds, medians; ")
    print(f"numba caches warm (each tree run once before); load average {load0} -> {load1}")
    print(f"{'measurement':24}" + "".join(f"{k:>10}" for k in trees)
          + "".join(f"{'B/' + k:>8}" for k in refs))  # fmt: skip
    for m in med["A"]:
        vals = [med[k].get(m, float("nan")) for k in trees]
        vb = vals[-1]
        print(f"{m:24}" + "".join(f"{v:10.4g}" for v in vals)
              + "".join(f"{vb / med[k].get(m, float('nan')):8.3f}" for k in refs))  # fmt: skip
    out = HERE / "results"
    out.mkdir(exist_ok=True)
    from raytrace.files.output import write_atomic

    write_atomic(
        out / "ab.json",
        json.dumps({"refs": refs, "rounds": rows, "median": med, "load": [load0, load1]}),
        overwrite=True,
    )
    print(f"wrote {out / 'ab.json'}")


if __name__ == "__main__":
    main()
