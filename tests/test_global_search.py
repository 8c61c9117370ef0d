"""The global search (raytrace.optimize.global_optimize): convergence from perturbed starts on
small problems, glass substitution that recovers a vendor's glass pair, the spread of merit over
seeds, determinism whatever the number of workers, and stopping (time budget, Ctrl-C) with the
best design kept. Budget: these tests together take well under a minute on 2 cores.

Small problems and their references:

- a singlet bent for least spherical aberration: the classical third-order shape factor
  (Kingslake, Lens Design Fundamentals, ch. 4; Welford, Aberrations of Optical Systems §7.2);
- the Cooke triplet (lenses/cooke-triplet-f4.toml) re-focused: the least-RMS image plane found
  independently by scanning the axis with a dense square pupil grid (not the operand's rings);
- a cemented achromat: the geometry of Thorlabs AC254-100-A (the vendor's Zemax file, as
  redistributed in tests/data/corpus/raytracing/AC254-100-A-Zemax(ZMX).zmx: curvatures
  1.5936254980e-2, -2.1877050974e-2, -7.7984870935e-3 1/mm, thicknesses 4.0 and 2.5 mm, ENPD
  22.86 mm, glasses N-BK7 and SF5) with its glasses replaced by wrong ones; the search must find
  the vendor's pair again from the lens's own first-order and spot data.
"""

from __future__ import annotations

import math
import os
import time
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from support import cooke_multimodal_spec_text, interrupt_group, run_cli, singlet, singlet_spec

from raytrace import AIR, Aperture, Field, Lens, Surface
from raytrace.files.library import load_lens
from raytrace.glass import lookup_glass
from raytrace.optimize import (
    DesignSpec,
    GlassSettings,
    Operand,
    SearchSettings,
    Variable,
    evaluate,
    global_optimize,
    merit,
    optimize,
)
from raytrace.optimize.global_search import perturb
from raytrace.packing import pack
from raytrace.paraxial import paraxial
from raytrace.trace import trace_rays

ROOT = Path(__file__).resolve().parents[1]


SINGLET_SPEC = singlet_spec(search=SearchSettings(starts=4, hops=1, perturbation=0.5))


# --------------------------------------------------------------------------- small problems
def test_singlet_from_perturbed_starts_reaches_the_coddington_shape():
    n = 1.5
    res = global_optimize(singlet(n), SINGLET_SPEC, seed=11)
    # every start (three of them perturbed by 50 %) ends in the same optimum
    assert res.starts_done == 4
    np.testing.assert_allclose(res.start_merits, res.merit, rtol=1e-6)
    c1, c2 = res.lens.surfaces[0].curvature, res.lens.surfaces[1].curvature
    K = (c1 + c2) / (c1 - c2)
    # Coddington shape factor of least spherical aberration, K = 2(n²-1)/(n+2) = 0.714 (thin
    # lens, third order); finite thickness and f/20 higher orders shift it slightly
    assert K == pytest.approx(2 * (n * n - 1) / (n + 2), abs=0.005)
    assert paraxial(res.lens).efl == pytest.approx(100.0, rel=1e-6)
    assert res.merit < res.merit_start


def test_perturbed_starts_really_differ():
    # the perturbation of a start is not a no-op: 50 % moves the curvatures by tens of percent
    rng = np.random.default_rng(np.random.SeedSequence(11, spawn_key=(1,)))
    x = np.array([0.01, -0.01])
    y = perturb(x, SINGLET_SPEC.variables, 100.0, rng, 0.5, np.full(2, -1.0), np.full(2, 1.0))
    assert np.all(np.abs(y - x) > 1e-4) and np.all(np.abs(y - x) < 0.05)


def _scan_best_focus(lens: Lens) -> float:
    """Least-RMS plane of the axial bundle by brute force: a dense square pupil grid, RMS radius
    about the centroid on 4001 planes (independent of the operand's equal-area rings)."""
    par = paraxial(lens)
    g = np.linspace(-1.0, 1.0, 81)
    px, py = np.meshgrid(g, g)
    keep = px**2 + py**2 <= 1.0
    px, py = px[keep] * par.epd / 2, py[keep] * par.epd / 2
    z0 = np.full_like(px, -1.0)
    d = (np.zeros_like(px), np.zeros_like(px), np.ones_like(px))
    batch = trace_rays(pack(lens), (px, py, z0), d, clip=False)
    assert np.all(batch.status == 0)
    zs = par.z_last + np.linspace(30.0, 60.0, 4001)
    rms = []
    for z in zs:
        x, y = batch.at_plane(z)
        rms.append(np.sqrt(np.mean((x - x.mean()) ** 2 + (y - y.mean()) ** 2)))
    return float(zs[int(np.argmin(rms))] - par.z_last)


def test_cooke_triplet_refocused_from_perturbed_starts():
    lens = load_lens("cooke-triplet-f4")
    n = lens.n_surfaces
    spec = DesignSpec(
        start="cooke-triplet-f4",
        variables=(Variable("thickness", n, 20.0, 70.0),),
        operands=(Operand("rms_spot", 0.0, 1000.0, {"field": 0.0, "plane": "file"}),),
        max_evaluations=100,
        search=SearchSettings(starts=4, hops=0, perturbation=0.2),
    )
    res = global_optimize(lens, spec, seed=5)
    np.testing.assert_allclose(res.start_merits, res.merit, rtol=1e-6)
    t = res.lens.surfaces[-1].thickness
    # the Gaussian image is at 43.080 mm (lens file); spherical aberration puts the least-RMS
    # plane a little nearer; the brute-force scan has a step of 0.0075 mm and another sampling
    assert t == pytest.approx(_scan_best_focus(res.lens), abs=0.03)
    assert t < paraxial(lens).bfl


THORLABS_C = (1.593625498007969800e-002, -2.187705097352880100e-002, -7.798487093503899700e-003)
CROWNS = ("N-SK16", "N-BK7", "N-K5", "N-BAK4", "N-PSK3", "N-SK2", "N-BAK1", "N-SSK8")
FLINTS = ("N-F2", "SF5", "N-SF6", "N-SF11", "N-BAF10", "N-SF2", "N-SF4", "N-LAF7")
F_LINE, C_LINE = 486.1327, 656.2725


def achromat(glass1: str, glass2: str) -> Lens:
    """Thorlabs AC254-100-A geometry (module docstring) with the given Schott glasses."""
    g1 = lookup_glass(glass1, ["Schott"]).material
    g2 = lookup_glass(glass2, ["Schott"]).material
    c1, c2, c3 = THORLABS_C
    return Lens(
        "AC254-100-A geometry",
        (
            Surface(c1, 4.0, g1, semi_diameter=12.7, stop=True),
            Surface(c2, 2.5, g2, semi_diameter=12.7),
            Surface(c3, 97.068, AIR, semi_diameter=12.7),
        ),
        Aperture("epd", 22.86),
        Field("angle", 3.0),
        wavelength=587.6,
    )


def achromat_operands() -> tuple[Operand, ...]:
    """EFL, axial colour F-C, best focus and RMS spots at F, d, C of the vendor's design (targets
    traced on the vendor's glasses: the merit is zero exactly at the vendor's pair)."""
    ops = [
        Operand("efl", 0.0, 100.0),
        Operand("axial_color", 0.0, 1000.0),
        Operand("best_focus", 0.0, 100.0),
    ]
    for wl in (F_LINE, 587.6, C_LINE):
        ops.append(Operand("rms_spot", 0.0, 1e4, {"plane": "best", "wavelength": wl}))
    vals = evaluate(achromat("N-BK7", "SF5"), tuple(ops))
    return tuple(replace(o, target=v.value) for o, v in zip(ops, vals, strict=True))


def test_glass_substitution_recovers_the_vendor_achromat_pair():
    ops = achromat_operands()
    pool = {"catalogs": ("Schott",), "neighbours": 7}
    spec = DesignSpec(
        start="(built in test)",
        variables=(
            Variable("glass", 1, glass=GlassSettings(glasses=CROWNS, **pool)),
            Variable("glass", 2, glass=GlassSettings(glasses=FLINTS, **pool)),
        ),
        operands=ops,
        max_evaluations=200,
        search=SearchSettings(starts=2, hops=3),
    )
    wrong = achromat("N-SK16", "N-F2")  # start from another crown and flint
    res = global_optimize(wrong, spec, seed=2)
    assert res.merit_start > 1e4
    assert [(g.surface, g.name, g.catalog) for g in res.glasses] == [
        (1, "N-BK7", "Schott"),
        (2, "SF5", "Schott"),
    ]
    assert res.merit < 1e-12
    # the problem discriminates: every other pair of the 64 is far worse (exhaustive check)
    others = [
        merit(evaluate(achromat(a, b), ops))
        for a in CROWNS
        for b in FLINTS
        if (a, b) != ("N-BK7", "SF5")
    ]
    assert min(others) > 1e3
    # the designed lens carries the vendor formula materials
    assert res.lens.surfaces[0].material == lookup_glass("N-BK7", ["Schott"]).material


# --------------------------------------------------------------------------- seeds, workers
def cooke_multimodal(starts: int = 3) -> DesignSpec:
    """Cooke triplet, six curvatures free, EFL 50 and RMS spot at 0, 14, 20 deg in the lens
    file's (Gaussian) plane: several local minima. At 20 deg the bundle is 0.8 of the pupil: the
    file's lens has no semi-diameters, and its full f/4 beam there meets surface 6 beyond the
    edge where it crosses surface 5 (32 of 240 rays travel backwards), which the real lens
    vignettes."""
    ops = (Operand("efl", 50.0, 10.0),) + tuple(
        Operand("rms_spot", 0.0, 100.0, {"field": f, "plane": "file", "aperture": a})
        for f, a in ((0.0, 1.0), (14.0, 1.0), (20.0, 0.8))
    )
    return DesignSpec(
        start="cooke-triplet-f4",
        variables=tuple(Variable("curvature", i) for i in range(1, 7)),
        operands=ops,
        max_evaluations=200,
        search=SearchSettings(
            starts=starts, hops=1, perturbation=0.15, hop_perturbation=0.05, local_evaluations=40
        ),
    )


def test_two_seeds_reach_merits_within_five_percent():
    lens = load_lens("cooke-triplet-f4")
    spec = cooke_multimodal()
    local = optimize(lens, spec)
    a = global_optimize(lens, spec, seed=1)
    b = global_optimize(lens, spec, seed=2)
    # our own runs (2026-11-27), for orientation: local 8.692; seeds 1..6 reach 8.033, 7.988,
    # 7.990, 8.478, 7.985, 8.220 (3 starts, 1 hop each). (Before a spot bundle with failing rays
    # became an error the 20 deg spot dropped them and the local run stuck at 11.35 in a valley
    # of that artefact; the global search then won by 20 %, now by 3-8 %.)
    assert abs(a.merit - b.merit) <= 0.05 * min(a.merit, b.merit)
    assert max(a.merit, b.merit) < 0.95 * local.merit  # the global search beats the local one
    assert not np.array_equal(a.start_merits, b.start_merits)  # the seeds do differ


def crown_singlet_spec(starts: int, hops: int) -> DesignSpec:
    """The singlet's spec with its glass chosen among four Schott crowns."""
    crowns = GlassSettings(
        glasses=("N-BK7", "N-SK16", "N-LAK22", "N-K5"), catalogs=("Schott",), neighbours=2
    )
    return replace(
        SINGLET_SPEC,
        variables=SINGLET_SPEC.variables + (Variable("glass", 1, glass=crowns),),
        max_evaluations=60,
        search=SearchSettings(starts=starts, hops=hops, perturbation=0.3),
    )


@pytest.mark.parametrize("method", ["least_squares", "minimax"])
def test_same_seed_same_result_with_one_and_two_workers(method):
    lens = singlet()
    spec = replace(crown_singlet_spec(starts=3, hops=1), method=method)
    one = global_optimize(lens, spec, seed=7, workers=1)
    two = global_optimize(lens, spec, seed=7, workers=2)
    assert one.stopped == two.stopped == ""
    assert two.workers == 2
    np.testing.assert_array_equal(one.start_merits, two.start_merits)
    assert one.merit == two.merit  # bit for bit
    assert one.lens == two.lens
    assert one.glasses == two.glasses
    assert one.method == two.method == method and math.isfinite(one.merit)


@pytest.mark.parametrize("poisoned", ["all but the lens", "first draw"])
def test_an_untraceable_random_glass_is_drawn_again(monkeypatch, poisoned):
    """A start's random glasses can make the lens untraceable at any perturbation (seen on a
    five-element Topogon: 6 of 10 starts died). Model it: designs in poisoned glasses (or, in
    the first case, any design but the start lens itself) do not trace. The start draws its
    glasses again, or falls back to the lens's own values and glasses: it never dies for that."""
    from raytrace.optimize import global_search as gs

    lens = singlet()  # N-BK7
    spec = crown_singlet_spec(starts=2, hops=0)
    st = gs._Start(lens, spec, 1, 7, lambda: None, lambda *a: None)
    names = [g.name for g in st.pools[0].glasses]
    first = int(np.random.default_rng(np.random.SeedSequence(7, spawn_key=(1,))).integers(4))
    own = tuple(s.curvature for s in lens.surfaces)
    real = gs._merit_of

    def merit_of(d: Lens, spec_) -> float:
        name = d.surfaces[0].material.name
        if poisoned == "first draw":
            bad = name == names[first]
        else:
            bad = name != "N-BK7" or tuple(s.curvature for s in d.surfaces) != own
        return math.inf if bad else real(d, spec_)

    assert names[first] != "N-BK7"  # the seed's first draw is another glass
    monkeypatch.setattr(gs, "_merit_of", merit_of)
    x, g = st.initial()
    assert math.isfinite(merit_of(gs.design(lens, spec, x, g, st.pools), spec))
    if poisoned == "first draw":
        assert names[g[0]] != names[first]
    else:  # only the lens's own values and glass trace
        assert names[g[0]] == "N-BK7"
        np.testing.assert_array_equal(x, gs.start_values(lens, spec))
    monkeypatch.setattr(gs, "_merit_of", real)
    out = gs.run_start(lens, spec, 1, 7, lambda: None, lambda *a: None)
    assert math.isfinite(out.merit)


# --------------------------------------------------------------------------- stopping
def test_time_budget_keeps_the_best_design():
    lens = load_lens("cooke-triplet-f4")
    spec = cooke_multimodal(starts=50)
    t0 = time.perf_counter()
    res = global_optimize(lens, spec, seed=3, time_budget_s=1.5)
    wall = time.perf_counter() - t0
    assert res.stopped == "time"
    assert res.starts_done < 50
    assert wall < 15.0  # a start stops at its next merit evaluation once the budget is spent
    assert res.merit <= res.merit_start
    # the result is a real design: its operands give the merit reported
    assert merit(evaluate(res.lens, spec.operands)) == pytest.approx(res.merit, rel=1e-12)


def test_ctrl_c_keeps_the_best_design():
    # in this process; the worker-process path is test_cli_sigint_to_the_process_group_...
    lens = load_lens("cooke-triplet-f4")
    spec = cooke_multimodal(starts=6)
    seen = []

    def progress(ev):  # Ctrl-C arrives during the run
        seen.append(ev.best)
        if len(seen) == 2:
            raise KeyboardInterrupt

    res = global_optimize(lens, spec, seed=4, progress=progress)
    assert res.stopped == "interrupted"
    assert res.starts_done < 6
    assert math.isfinite(res.merit) and res.merit <= res.merit_start
    assert res.merit <= min(seen[:2]) * (1 + 1e-9)  # nothing found before the stop is lost
    assert merit(evaluate(res.lens, spec.operands)) == pytest.approx(res.merit, rel=1e-12)


def test_starts_cut_short_are_counted_apart():
    # Ctrl-C (here: from the progress callback) in start 1's first local run: start 0 finished,
    # start 1 ends with its best so far; the result and the start event say it was cut short
    seen = []

    def progress(ev):
        seen.append(ev)
        if ev.event == "local" and ev.start == 1:
            raise KeyboardInterrupt

    res = global_optimize(singlet(), SINGLET_SPEC, seed=11, progress=progress)
    assert res.stopped == "interrupted"
    assert res.starts_done == 2 and res.starts_stopped == 1 and res.starts_finished == 1
    assert res.message.startswith("stopped (interrupted) with 1 of 4 starts finished, 1 cut short;")
    assert "best merit " in res.message and "from start " in res.message
    ends = [(ev.start, ev.stopped) for ev in seen if ev.event == "start"]
    assert ends == [(0, ""), (1, "interrupted")]
    # a run that is not stopped counts its starts as before
    whole = global_optimize(singlet(), replace(SINGLET_SPEC, search=replace(
        SINGLET_SPEC.search, starts=2)), seed=11)  # fmt: skip
    assert whole.starts_stopped == 0 and "of 2/2 starts (seed 11)" in whole.message


@pytest.mark.parametrize("where", [["--workers", "2"], ["--dask", "local:2"]], ids=["pool", "dask"])
def test_cli_sigint_to_the_process_group_writes_the_best_design(tmp_path: Path, where):
    # A real Ctrl-C: SIGINT to the whole process group (parent and workers), as a terminal does.
    # The Dask workers ignore it (raytrace.executors.dask_setup) and end their starts when the
    # search's stop Event is set; a start that had not begun is not reported.
    if where[0] == "--dask":
        pytest.importorskip("distributed")
    spec = tmp_path / "cooke.toml"
    spec.write_text(
        cooke_multimodal_spec_text(200, "[global]\nstarts = 40\nhops = 3\nlocal_evaluations = 20\n")
    )
    out = tmp_path / "best.toml"
    argv = ["optimize", str(spec), "-o", str(out), "--global", *where, "--seed", "1"]
    # the first line after a first run's "compiling" notice: the first finished start
    before, rc, stdout, stderr = interrupt_group(
        argv, cwd=ROOT, ready=lambda line: "compiling" not in line
    )
    assert before[-1].startswith("start "), before[-1]
    assert rc == 130, stderr
    assert "interrupted" in stderr and "Traceback" not in stderr
    assert "merit nan" not in stderr  # starts that never ran are not reported as done
    assert out.is_file() and "wrote" in stdout
    from raytrace.files.native import read_lens

    notes = read_lens(out).notes
    assert "--global --seed 1" in notes and "stopped early (interrupted)" in notes
    assert "with 2 worker(s)" in notes
    assert ("on Dask (local:2)" in notes) == (where[0] == "--dask")
    merits = [float(x.split("merit ")[1].split(",")[0]) for x in stderr.splitlines() if "done" in x]
    start = float(notes.split("(start ")[1].split(")")[0])
    # the written design is the best seen (the progress lines print 6 significant digits)
    assert float(notes.split("; merit ")[1].split(" ")[0]) <= min([start, *merits]) * (1 + 1e-5)


# --------------------------------------------------------------------------- Dask
def test_dask_cluster_gives_the_same_design_as_one_process():
    """The starts as tasks on a Dask LocalCluster (two worker processes): the same per-start
    merits and the same design, bit for bit, as in this process, with either local method; a
    time budget stops it with the best design so far."""
    pytest.importorskip("distributed")
    from raytrace.executors import dask_client

    lens = load_lens("cooke-triplet-f4")
    spec = cooke_multimodal(starts=2)
    here = global_optimize(lens, spec, seed=7, workers=1)
    minimax = replace(spec, method="minimax")  # the local runs are minimax on the workers too
    here_mm = global_optimize(lens, minimax, seed=7, workers=1)
    client, close = dask_client("local:2")  # one cluster for the runs (a client is accepted)
    try:
        dask = global_optimize(lens, spec, seed=7, executor=client)
        dask_mm = global_optimize(lens, minimax, seed=7, executor=client)
        budget = global_optimize(
            lens, cooke_multimodal(starts=12), seed=7, executor=client, time_budget_s=1.0
        )
    finally:
        close()
    assert np.array_equal(here.start_merits, dask.start_merits)
    assert here.merit == dask.merit and not dask.stopped
    assert np.array_equal(here_mm.start_merits, dask_mm.start_merits)
    assert here_mm.merit == dask_mm.merit and dask_mm.method == "minimax"
    for a, b in zip(here.lens.surfaces, dask.lens.surfaces, strict=True):
        assert a.curvature == b.curvature
    assert budget.stopped == "time" and math.isfinite(budget.merit)
    assert np.isnan(budget.start_merits).any()  # not every start ran to its end


def test_a_lost_cluster_stops_the_search_with_the_finished_starts_kept():
    """The scheduler goes away after the first finished start (here: closed from the progress
    callback): the search stops with that start's design, says why, and does not hang."""
    pytest.importorskip("distributed")
    from raytrace.executors import dask_client

    client, close = dask_client("local:2")
    seen = []

    def progress(ev):
        seen.append((ev.event, ev.start, ev.merit))
        if ev.event == "start" and len(seen) == 1:
            client.cluster.close()  # the scheduler and its workers; the client stays

    try:
        res = global_optimize(
            load_lens("cooke-triplet-f4"), cooke_multimodal(starts=12), seed=7, executor=client,
            progress=progress,
        )  # fmt: skip
    finally:
        close()
    assert res.stopped == "cluster" and "the Dask cluster was lost" in res.message
    assert "\n" not in res.message
    assert res.workers == 2
    (_, k, m), *_ = seen
    assert res.best_start == k and res.merit == pytest.approx(m, rel=1e-12)


@pytest.mark.parametrize(
    "text", ["local", "local:1", "local:2", "tcp://127.0.0.1:8786", "tcp://[::1]:8786", "tcp://h:1"]
)
def test_executor_specs_accepted(text):
    from raytrace.executors import check_executor

    assert check_executor(text) == text


def test_cli_dask_flags_are_checked(tmp_path: Path):
    spec = ROOT / "lenses" / "specs" / "twinplex-like-55-525.toml"
    many = f"local:{4 * (os.cpu_count() or 1) + 1}"
    for flags, msg in (
        (["--dask", "local:2"], "--dask belong(s) to the global search"),
        (["--global", "--dask", "local:2", "--workers", "2"], "--workers is for local processes"),
        # a cluster without workers would wait for ever; a host:port is not a LocalCluster size
        (["--global", "--dask", "local:0"], "local:N (N >= 1 workers)"),
        (["--global", "--dask", "localhost:8786"], "tcp://HOST:PORT (a running scheduler)"),
        (["--global", "--dask", "tcp://host:notaport"], "tcp://HOST:PORT (a running scheduler)"),
        (["--global", "--dask", "tcp://host:70000"], "the port must be 1 to 65535"),
        (["--global", "--dask", many], "worker processes on a machine with"),
    ):
        rc, _, err = run_cli(["optimize", str(spec), "-o", str(tmp_path / "x.toml"), *flags])
        lines = [x for x in err.splitlines() if "compiling" not in x]
        assert rc == 2 and len(lines) == 1 and msg in lines[0], err
        assert not (tmp_path / "x.toml").exists()
