"""Start-up benchmark: warm wall and CPU time of short ``orthoscope`` commands.

    python benchmarks/startup.py                 # 9 rounds
    python benchmarks/startup.py --runs 15 --out benchmarks/results/startup.json
    python benchmarks/startup.py --quick         # one round (what the smoke test runs)

Every measurement is a fresh process of the installed console script (``python -m orthoscope``
where there is none) with its output discarded. The commands run round-robin, one of each per
round, so that the load of other jobs falls on all of them alike; the result per command is the
median (and the minimum) over rounds of

* **wall**: time from start to exit of the child;
* **CPU**: user + system time of the child (``os.wait4``), which a busy machine inflates far less
  than the wall time. On a 2-core machine shared with other jobs, compare CPU times; the load
  average at the start and end is printed beside them.

Before the rounds the sources are byte-compiled (``compileall``: a checkout where
``PYTHONDONTWRITEBYTECODE`` is set would otherwise compile changed modules on every run) and
each command runs once to fill the numba cache; a command whose warm-up printed the compile
notice runs again. A child process then runs each command in-process and reports which numba
kernels it loaded from the cache or compiled, and whether numba's registries
(``numba.np.arraymath``), ``scipy.linalg`` or matplotlib were imported. The breakdown rows time
``python -c pass``, ``import numpy`` and ``import numpy, numba`` the same way.

Targets (benchmarks/README.md): ``distortion LENS`` <= 0.7 s, ``paraxial`` of a bundled lens
<= 0.35 s, ``paraxial FILE.zmx`` with catalog glasses <= 0.4 s, warm, on the 2-core development
machine.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent

#: (key, orthoscope arguments, target seconds or None). The .zmx is a Thorlabs asphere
#: (tests/data/corpus/optiland, source in tests/data/corpus/SOURCES.md): GCAT SCHOTT HOYA OHARA,
#: glass S-LAH64 found in the third catalog searched. US05331467-1 (tests/data/corpus/rayoptics)
#: names glasses of four catalogs (Schott, Ohara, Hikari, Sumita).
COMMANDS: list[tuple[str, list[str], float | None]] = [
    ("distortion", ["distortion", "topogon-like-pestrecov"], 0.7),
    ("paraxial", ["paraxial", "cooke-triplet-f4"], 0.35),
    (
        "paraxial_zmx",
        ["paraxial", str(ROOT / "tests/data/corpus/optiland/lens_thorlabs_iso_8859_1.zmx")],
        0.4,
    ),
    (
        "paraxial_zmx_4_catalogs",
        ["paraxial", str(ROOT / "tests/data/corpus/rayoptics/US05331467-1.zmx")],
        None,
    ),
]

BREAKDOWN: list[tuple[str, list[str]]] = [
    ("python -c pass", ["-c", "pass"]),
    ("import numpy", ["-c", "import numpy"]),
    ("import numpy, numba", ["-c", "import numpy, numba"]),
]

#: the line a run that compiles a kernel prints (orthoscope.cli.COMPILE_NOTICE, its start)
NOTICE = "orthoscope: compiling ray-tracing kernels"

#: run in a child: one command in-process, then what it loaded
PROBE = r"""
import io, json, sys
from contextlib import redirect_stderr, redirect_stdout
from orthoscope.cli import main
with redirect_stdout(io.StringIO()), redirect_stderr(io.StringIO()):
    rc = main(sys.argv[1:])
kernels = {}
for name, mod in list(sys.modules.items()):
    if not name.startswith("raytrace.kernels.") or mod is None:
        continue
    for attr, obj in vars(mod).items():
        stats = getattr(obj, "stats", None)
        if stats is None or not hasattr(obj, "signatures") or not obj.signatures:
            continue
        kernels[f"{name.rsplit('.', 1)[1]}.{attr}"] = {
            "signatures": len(obj.signatures),
            "cache_hits": sum(stats.cache_hits.values()),
            "compiled": sum(stats.cache_misses.values()),
        }
mods = ("numba", "numba.np.arraymath", "scipy.linalg", "matplotlib")
print("PROBE", json.dumps({
    "rc": rc,
    "kernels": kernels,
    "imported": {m: m in sys.modules for m in mods},
    "modules": len(sys.modules),
}))
"""


def base_command() -> list[str]:
    exe = shutil.which("orthoscope")
    return [exe] if exe else [sys.executable, "-m", "orthoscope"]


def run_once(cmd: list[str], env: dict | None = None) -> tuple[float, float, int, str]:
    """(wall s, child CPU s = user + system, exit status, stderr) of one fresh process."""
    t0 = time.perf_counter()
    p = subprocess.Popen(
        cmd, cwd=ROOT, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True
    )
    err = p.stderr.read()
    _, status, usage = os.wait4(p.pid, 0)
    wall = time.perf_counter() - t0
    p.stderr.close()
    p.returncode = os.waitstatus_to_exitcode(status)
    return wall, usage.ru_utime + usage.ru_stime, p.returncode, err


def _summary(walls: list[float], cpus: list[float]) -> dict:
    return {
        "wall_median_s": statistics.median(walls),
        "wall_min_s": min(walls),
        "cpu_median_s": statistics.median(cpus),
        "cpu_min_s": min(cpus),
        "wall_s": walls,
        "cpu_s": cpus,
    }


def byte_compile() -> None:
    pkgs = [str(ROOT / p) for p in ("raytrace", "distortion", "orthoscope", "lenses")]
    subprocess.run(
        [sys.executable, "-m", "compileall", "-q", *pkgs], capture_output=True, check=False
    )


def probe(args: list[str]) -> dict:
    r = subprocess.run(
        [sys.executable, "-c", PROBE, *args], cwd=ROOT, capture_output=True, text=True
    )
    if "PROBE" not in r.stdout:
        return {"error": r.stderr[-500:]}
    return json.loads(r.stdout.split("PROBE", 1)[1])


def measure(
    runs: int = 9,
    commands: list[tuple[str, list[str], float | None]] | None = None,
    breakdown: bool = True,
    log=print,
) -> dict:
    """Warm start-up of each command: ``runs`` rounds, round-robin; see the module docstring."""
    commands = COMMANDS if commands is None else commands
    base = base_command()
    byte_compile()
    warm = {}
    for key, args, _ in commands:  # fill the numba cache; a compile notice means: again
        _, _, rc, err = run_once([*base, *args])
        if NOTICE in err:
            _, _, rc, err = run_once([*base, *args])
        warm[key] = {"rc": rc, "notice_after_warm_up": NOTICE in err}
        if rc:
            log(f"  {key}: exit status {rc}: {err.strip()[-300:]}")
    load0 = os.getloadavg()
    series: dict[str, tuple[list[float], list[float]]] = {}
    rows = [(k, [*base, *a]) for k, a, _ in commands]
    if breakdown:
        rows += [(k, [sys.executable, *a]) for k, a in BREAKDOWN]
    for _ in range(max(runs, 1)):
        for key, cmd in rows:
            wall, cpu, _, _ = run_once(cmd)
            w, c = series.setdefault(key, ([], []))
            w.append(wall)
            c.append(cpu)
    load1 = os.getloadavg()
    out = {
        "date": time.strftime("%Y-%m-%d %H:%M"),
        "runs": max(runs, 1),
        "command": " ".join(base),
        "load_average_start": list(load0),
        "load_average_end": list(load1),
        "cpus": os.cpu_count(),
        "commands": {},
        "breakdown": {},
    }
    for key, args, target in commands:
        out["commands"][key] = {
            "args": args,
            "target_s": target,
            **warm[key],
            **_summary(*series[key]),
            "loaded": probe(args),
        }
    if breakdown:
        for key, _ in BREAKDOWN:
            out["breakdown"][key] = _summary(*series[key])
    return out


def summarize(res: dict) -> list[str]:
    la0 = ", ".join(f"{v:.2f}" for v in res["load_average_start"])
    la1 = ", ".join(f"{v:.2f}" for v in res["load_average_end"])
    L = [
        f"orthoscope start-up, warm numba cache, {res['runs']} rounds round-robin, medians (min); "
        f"{res['cpus']} CPUs, load average {la0} -> {la1}",
        f"{'command':28} {'wall s':>15} {'CPU s':>15}  target (wall)",
    ]
    for key, r in res["commands"].items():
        t = r["target_s"]
        verdict = (
            "" if t is None else f"<= {t}: " + ("met" if r["wall_median_s"] <= t else "MISSED")
        )
        L.append(
            f"{key:28} {r['wall_median_s']:7.3f} ({r['wall_min_s']:.3f}) "
            f"{r['cpu_median_s']:7.3f} ({r['cpu_min_s']:.3f})  {verdict}"
        )
    for key, r in res.get("breakdown", {}).items():
        L.append(
            f"{key:28} {r['wall_median_s']:7.3f} ({r['wall_min_s']:.3f}) "
            f"{r['cpu_median_s']:7.3f} ({r['cpu_min_s']:.3f})"
        )
    for key, r in res["commands"].items():
        p = r.get("loaded", {})
        if "kernels" not in p:
            L.append(f"{key}: probe failed: {p.get('error', '')}")
            continue
        ks = ", ".join(
            f"{k} (cached {v['cache_hits']}, compiled {v['compiled']})"
            for k, v in sorted(p["kernels"].items())
        )
        imp = ", ".join(k for k, v in p["imported"].items() if v) or "none of them"
        L.append(
            f"{key}: kernels {ks or 'none'}; of numba, numba.np.arraymath, scipy.linalg, "
            f"matplotlib imported: {imp}; {p['modules']} modules"
        )
    return L


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=9, help="rounds (default 9)")
    ap.add_argument("--quick", action="store_true", help="one round, no breakdown")
    ap.add_argument("--out", default=str(HERE / "results" / "startup.json"))
    args = ap.parse_args(argv)
    res = measure(1 if args.quick else args.runs, breakdown=not args.quick)
    print("\n".join(summarize(res)))
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    from raytrace.files.output import write_atomic

    write_atomic(out, json.dumps(res, indent=1), overwrite=True)
    print(f"wrote {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
