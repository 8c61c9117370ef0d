"""Minimax optimization (raytrace.optimize.minimax; ``optimize(..., method="minimax")``, the
spec's ``method`` and ``penalty``, ``min`` / ``max`` on any operand, ``orthoscope optimize
--method minimax``).

The reference answers are computed here, independently of the optimizer, from closed forms:
the sag of a sphere, z(h) = c h² / (1 + √(1 − c²h²)), and the thick-lens focal length in air,
1/f = (n − 1) (c1 − c2 + (n − 1) t c1 c2 / n) (Hecht, *Optics*, 4th ed., Eq. 6.2), searched by
brute force on a grid and then solved exactly on the equioscillation set the grid exposes
(Chebyshev's alternation theorem: at the minimax solution of k parameters, k + 1 residuals reach
the maximum with alternating signs, here k = 2, three residuals).
"""

from __future__ import annotations

import itertools
import json
import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import brentq, fsolve
from support import read_spec_text, singlet

from orthoscope.cli import main
from raytrace.optimize import (
    DesignSpec,
    Operand,
    SpecError,
    Variable,
    global_optimize,
    optimize,
)
from raytrace.paraxial import paraxial

N_GLASS = 1.5
C1 = 0.01  # 1/mm, first surface (fixed)
H = (0.0, 4.0, 8.0, 12.0)  # mm: centre, then edge thickness at these heights
TARGETS = (3.0, 2.9, 2.5, 1.75)  # mm: a profile t + z2(h) − z1(h) cannot follow exactly
WEIGHTS = (1.0, 2.0, 1.0, 1.5)


def _lens(t: float = 3.0, c2: float = -0.01):
    """A singlet (n = 1.5, c1 = 0.01/mm) of centre thickness t and back curvature c2."""
    lens = singlet(n=N_GLASS, f=100.0, t=t)
    s = list(lens.surfaces)
    s[0] = replace(s[0], curvature=C1)
    s[1] = replace(s[1], curvature=c2)
    return replace(lens, surfaces=tuple(s))


def _operands() -> tuple[Operand, ...]:
    out = []
    for h, target, w in zip(H, TARGETS, WEIGHTS, strict=True):
        if h == 0:
            out.append(Operand("center_thickness", target, w, {"surface": 1}))
        else:
            out.append(Operand("edge_thickness", target, w, {"surface": 1, "height": h}))
    return tuple(out)


def _spec(*extra: Operand, **kw) -> DesignSpec:
    return DesignSpec(
        start="(built in test)",
        variables=(Variable("thickness", 1), Variable("curvature", 2)),
        operands=_operands() + extra,
        max_evaluations=400,
        method="minimax",
        **kw,
    )


# ----------------------------------------------------------------------------- the reference
def _sag(h, c):
    return c * h * h / (1.0 + np.sqrt(1.0 - c * c * h * h))


def _residuals(t, c2):
    """Weighted residuals w (t + z(h; c2) − z(h; c1) − target), broadcast over t, c2."""
    t, c2 = np.asarray(t, float), np.asarray(c2, float)
    return np.stack(
        [
            w * (t + _sag(h, c2) - _sag(h, C1) - tg)
            for h, tg, w in zip(H, TARGETS, WEIGHTS, strict=True)
        ]
    )


def _reference_minimax():
    """(t, c2, E): brute force on a grid, then the exact equioscillation solution."""
    t, c2 = np.meshgrid(np.linspace(2.5, 3.5, 401), np.linspace(-0.03, 0.01, 801))
    grid = np.max(np.abs(_residuals(t, c2)), axis=0)
    i = np.unravel_index(np.argmin(grid), grid.shape)
    t0, c0, e_grid = float(t[i]), float(c2[i]), float(grid[i])
    best = None
    for idx in itertools.combinations(range(4), 3):  # three residuals at ±E, alternating
        for sign in (1.0, -1.0):
            signs = np.array([sign, -sign, sign])

            def eqs(p, idx=idx, signs=signs):
                return _residuals(p[0], p[1])[list(idx)] - signs * p[2]

            sol, _, ok, _ = fsolve(eqs, [t0, c0, e_grid], full_output=True, xtol=1e-14)
            r = _residuals(sol[0], sol[1])
            if ok == 1 and sol[2] > 0 and np.max(np.abs(r)) <= sol[2] * (1 + 1e-9):
                if best is None or sol[2] < best[2]:
                    best = sol
    assert best is not None
    # the exact solution is what the grid found, to the grid's resolution
    assert best[2] <= e_grid and e_grid - best[2] < 2e-3
    return float(best[0]), float(best[1]), float(best[2])


REF = _reference_minimax()


def _max_residual(res) -> float:
    return max(abs(o.residual) for o in res.operands if not o.operand.bounded)


# ----------------------------------------------------------------------------- (a) minimax
@pytest.mark.parametrize("seed", [0, 1, 2, 3, 4])
def test_minimax_reaches_the_equioscillating_optimum_from_perturbed_starts(seed):
    t_ref, c_ref, e_ref = REF
    rng = np.random.default_rng(seed)
    start = _lens(3.0 + 0.4 * rng.standard_normal(), -0.01 + 0.008 * rng.standard_normal())
    res = optimize(start, _spec())
    assert res.converged, res.message
    assert res.method == "minimax"
    assert res.merit == pytest.approx(e_ref, rel=1e-9)
    assert res.merit == pytest.approx(_max_residual(res), rel=1e-12)
    assert res.x == pytest.approx([t_ref, c_ref], rel=1e-7)
    # equioscillation: three residuals at ±E with alternating signs, the fourth inside
    r = np.array([o.residual for o in res.operands])
    at_max = np.flatnonzero(np.abs(r) > e_ref * (1 - 1e-6))
    assert len(at_max) == 3
    assert np.all(np.diff(np.sign(r[at_max])) != 0)


def test_least_squares_gives_a_different_answer():
    # the same problem by damped least squares: lower sum of squares, larger worst residual
    t_ref, c_ref, e_ref = REF
    mm = optimize(_lens(), _spec())
    ls = optimize(_lens(), _spec(), method="least_squares")
    assert ls.method == "least_squares" and ls.converged
    assert _max_residual(ls) > 1.05 * e_ref
    assert sum(o.residual**2 for o in ls.operands) < sum(o.residual**2 for o in mm.operands)


# ----------------------------------------------------------------------------- (b) constraints
EFL_MAX = 110.0  # mm; the unconstrained optimum has EFL ≈ 116 mm


def _efl(t, c2):
    """Thick-lens focal length in air (Hecht Eq. 6.2)."""
    n = N_GLASS
    return 1.0 / ((n - 1.0) * (C1 - c2 + (n - 1.0) * t * C1 * c2 / n))


def _c2_for_efl(t, f):
    """The back curvature that gives focal length f at thickness t (Hecht Eq. 6.2 solved)."""
    n = N_GLASS
    return (1.0 / (f * (n - 1.0)) - C1) / ((n - 1.0) * t * C1 / n - 1.0)


def _bound_reference() -> tuple[float, float]:
    """(t, E) of the minimax optimum under efl <= EFL_MAX: on the boundary efl = EFL_MAX the
    problem has one parameter (t), so two residuals equioscillate; grid, then the root of their
    difference."""
    t_ref, c_ref, _ = REF
    assert _efl(t_ref, c_ref) > EFL_MAX + 5  # the bound cuts the unconstrained optimum off
    ts = np.linspace(2.5, 3.5, 20001)
    worst = np.max(np.abs(_residuals(ts, _c2_for_efl(ts, EFL_MAX))), axis=0)
    k = int(np.argmin(worst))
    r = _residuals(ts[k], _c2_for_efl(ts[k], EFL_MAX))
    i, j = np.argsort(-np.abs(r))[:2]

    def diff(t):
        rr = _residuals(t, _c2_for_efl(t, EFL_MAX))
        return abs(rr[i]) - abs(rr[j])

    t_b = brentq(diff, ts[k - 5], ts[k + 5], xtol=1e-15)
    e_b = float(np.max(np.abs(_residuals(t_b, _c2_for_efl(t_b, EFL_MAX)))))
    assert e_b <= worst[k] + 1e-12
    return float(t_b), e_b


def test_a_bound_is_active_at_the_optimum_and_met():
    t_b, e_b = _bound_reference()
    bound = Operand("efl", weight=1.0, params={"max": EFL_MAX})
    res = optimize(_lens(), _spec(bound))
    assert res.converged, res.message
    efl = paraxial(res.lens).efl
    assert efl <= EFL_MAX + 1e-9  # met
    assert efl == pytest.approx(EFL_MAX, abs=1e-7)  # active
    assert res.violation == pytest.approx(0.0, abs=1e-9)
    assert res.merit == pytest.approx(e_b, rel=1e-7)
    assert res.x == pytest.approx([t_b, _c2_for_efl(t_b, EFL_MAX)], rel=1e-6)
    # the bound operand reports its violation (0), not a distance to a target
    (bv,) = [o for o in res.operands if o.operand.bounded]
    assert bv.residual == 0.0 and bv.value == pytest.approx(EFL_MAX, abs=1e-7)


def test_least_squares_treats_a_bound_as_a_one_sided_residual():
    bound = Operand("efl", weight=1.0, params={"max": EFL_MAX})
    res = optimize(_lens(), _spec(bound), method="least_squares")
    (bv,) = [o for o in res.operands if o.operand.bounded]
    assert bv.residual == pytest.approx(max(0.0, bv.value - EFL_MAX), abs=1e-15)
    assert res.violation == pytest.approx(abs(bv.residual))


def test_a_penalty_too_small_ends_unconverged_and_says_so():
    bound = Operand("efl", weight=1.0, params={"max": EFL_MAX})
    res = optimize(_lens(), _spec(bound, penalty=1e-6))
    assert not res.converged
    assert res.violation > 1.0  # the bound was traded for the objective
    assert "bound not met" in res.message and "penalty" in res.message


def test_stop_and_evaluation_limit_keep_the_best_design():
    calls = []

    def stop():
        calls.append(1)
        return "time" if len(calls) > 12 else None

    res = optimize(_lens(2.6, -0.02), _spec(), stop=stop)
    assert res.stopped == "time" and not res.converged
    assert res.merit < res.merit_start
    res = optimize(_lens(2.6, -0.02), _spec(), max_evaluations=8)
    assert not res.converged and "evaluation limit (8)" in res.message
    assert res.evaluations <= 8


@pytest.mark.parametrize("method", ["minimax", "least_squares"])
def test_a_stop_asked_at_once_returns_the_start_design_stopped(method):
    """A stop that is already asked when a run begins (the global search's time budget or
    Ctrl-C landing between two local runs) ends the run with the start design, not an error:
    minimax raised Stopped from its first evaluation, which crashed the global search."""
    start = _lens(2.6, -0.02)
    res = optimize(start, _spec(), stop=lambda: "time", method=method)
    assert res.stopped == "time" and not res.converged
    assert res.lens.surfaces[0].thickness == start.surfaces[0].thickness
    assert res.lens.surfaces[1].curvature == start.surfaces[1].curvature
    assert res.merit == res.merit_start


# ----------------------------------------------------------------------------- (c) the spec
HEAD = 'start = "cooke-triplet-f4"\nvariables = [ { kind = "curvature", surface = 1 } ]\n'


_read = read_spec_text


@pytest.mark.parametrize(
    "text, message",
    [
        (
            'operands = [ { type = "efl", min = 50, max = 40 } ]\n',
            "'min' (50) is above 'max' (40): swap them",
        ),
        (
            'operands = [ { type = "efl", target = 50, max = 60 } ]\n',
            "give a 'target' (two-sided) or 'min' / 'max' (one-sided bound), not both",
        ),
        ('operands = [ { type = "efl", min = "big" } ]\n', "'min' must be a number"),
        ('operands = [ { type = "efl", min = "inf" } ]\n', "'min' cannot be +inf"),
        (
            'operands = [ { type = "center_thickness", surface = 1 } ]\n',
            "needs a 'target' or 'min' and/or 'max'",
        ),
        (
            'method = "minmax"\noperands = [ { type = "efl", target = 50 } ]\n',
            "'method' must be one of 'least_squares', 'minimax', got 'minmax' "
            "(did you mean 'minimax'?)",
        ),
        ('penalty = 0\noperands = [ { type = "efl", target = 50 } ]\n', "'penalty' must be"),
    ],
)
def test_spec_errors(tmp_path: Path, text: str, message: str):
    with pytest.raises(SpecError) as e:
        _read(tmp_path, HEAD + text)
    assert message in str(e.value)
    assert len(str(e.value).splitlines()) == 1


def test_spec_reads_method_and_bounds_on_any_operand(tmp_path: Path):
    spec = _read(
        tmp_path,
        HEAD + 'method = "minimax"\npenalty = 30\noperands = [\n'
        '  { type = "efl", target = 50 },\n'
        '  { type = "rms_spot", field = 0, plane = "gaussian", max = 0.05, weight = 20 },\n'
        '  { type = "distortion", field = 20, min = -0.01, max = "inf" },\n'
        '  { type = "center_thickness", surface = 2, target = 3.0 },\n'
        "]\n",
    )
    assert spec.method == "minimax" and spec.penalty == 30.0
    assert [o.bounded for o in spec.operands] == [False, True, True, False]
    assert spec.operands[1].limits == (-math.inf, 0.05)
    assert spec.operands[2].limits == (-0.01, math.inf)
    assert _read(tmp_path, HEAD + 'operands = [ { type = "efl" } ]\n').method == "least_squares"


def test_api_refuses_mixed_target_and_bounds():
    bad = Operand("efl", 50.0, 1.0, {"max": 60.0})
    with pytest.raises(SpecError, match="not both"):
        optimize(_lens(), _spec(bad))
    with pytest.raises(SpecError, match="unknown method 'newton'"):
        optimize(_lens(), _spec(), method="newton")


# ----------------------------------------------------------------------------- (c2) global
def test_global_search_runs_minimax_and_reaches_the_reference_optimum():
    """Every start's local run is minimax: each perturbed start ends at the equioscillating
    optimum computed above from the closed forms, and so does the result."""
    t_ref, c_ref, e_ref = REF
    res = global_optimize(_lens(), _spec(), starts=3, seed=5, hops=1)
    assert res.method == "minimax" and res.converged, res.message
    # the one-line message names the merit it reports (phi, not a sum of squares)
    assert res.merit_is == "max weighted residual (+ penalty x bound violations)"
    assert res.message.startswith(f"best {res.merit_is} {res.merit:.6g} from start")
    assert res.merit == pytest.approx(e_ref, rel=1e-9)
    assert res.start_merits == pytest.approx([e_ref] * 3, rel=1e-7)
    assert res.violation == 0.0
    t, c2 = res.lens.surfaces[0].thickness, res.lens.surfaces[1].curvature
    assert [t, c2] == pytest.approx([t_ref, c_ref], rel=1e-7)


def test_global_minimax_ranks_by_the_exact_penalty_and_meets_the_bound():
    """With a bound, designs are ranked by phi = max|e| + penalty x violation (checked here on
    the start lens against the closed forms), and the search ends on the constrained optimum."""
    from raytrace.optimize import evaluate
    from raytrace.optimize.minimax import penalty_merit

    bound = Operand("efl", weight=1.0, params={"max": EFL_MAX})
    spec = _spec(bound, penalty=100.0)
    start = _lens(3.0, -0.006)
    f = _efl(3.0, -0.006)
    assert f > EFL_MAX  # the start breaks the bound
    phi = float(np.max(np.abs(_residuals(3.0, -0.006)))) + 100.0 * (f - EFL_MAX)
    vals = evaluate(start, spec.operands)
    assert penalty_merit(spec, vals) == pytest.approx(phi, rel=1e-9)

    t_b, e_b = _bound_reference()
    res = global_optimize(start, spec, starts=3, seed=1, hops=1)
    assert res.converged, res.message
    assert res.violation == pytest.approx(0.0, abs=1e-9)
    assert paraxial(res.lens).efl <= EFL_MAX + 1e-9
    assert res.merit == pytest.approx(e_b, rel=1e-7)
    assert res.merit_start == pytest.approx(phi, rel=1e-9)


# ----------------------------------------------------------------------------- (d) the CLI
# EFL 48 with weight 1 and EFL 50 with weight 3: minimax gives |f − 48| = 3 |f − 50|, f = 49.5,
# max weighted residual 1.5; least squares gives f = (48 + 9·50)/10 = 49.8.
CLI_SPEC = """
name = "cooke-efl-minimax"
start = "cooke-triplet-f4"
max_evaluations = 200
variables = [ { kind = "curvature", surface = 6 } ]
operands = [
  { type = "efl", target = 48.0, weight = 1 },
  { type = "efl", target = 50.0, weight = 3 },
  { type = "center_thickness", surface = 1, min = 0.5 },  # met by the start lens; not varied
]
"""


def test_cli_method_minimax(tmp_path: Path, capsys):
    spec = tmp_path / "s.toml"
    spec.write_text(CLI_SPEC)
    out = tmp_path / "out.toml"
    assert main(["optimize", str(spec), "-o", str(out), "--method", "minimax", "--quiet"]) == 0
    text = capsys.readouterr().out
    assert "max weighted residual" in text and "-> 1.5 in" in text
    assert ">= 0.5" in text  # the bound operand's row shows its bound, not a target
    from raytrace.files.native import read_lens

    lens = read_lens(out)
    assert paraxial(lens).efl == pytest.approx(49.5, abs=1e-8)
    assert "--method minimax" in lens.notes and "max weighted residual 1.5" in lens.notes

    out2 = tmp_path / "ls.toml"
    assert main(["optimize", str(spec), "-o", str(out2), "--quiet", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["method"] == "least_squares"
    bound = d["operands"][2]
    assert bound["target"] is None and bound["min"] == 0.5 and bound["max"] is None
    assert paraxial(read_lens(out2)).efl == pytest.approx(49.8, abs=1e-6)


def test_cli_global_minimax(tmp_path: Path, capsys):
    """--global with --method minimax: minimax in every local run; f = 49.5 as above."""
    from raytrace.files.native import read_lens

    spec = tmp_path / "s.toml"
    spec.write_text(CLI_SPEC)
    out = tmp_path / "o.toml"
    argv = ["optimize", str(spec), "-o", str(out), "--method", "minimax", "--quiet"]
    assert main(argv + ["--global", "--starts", "2", "--seed", "3"]) == 0
    text = capsys.readouterr().out
    assert "max weighted residual (+ penalty x bound violations)" in text
    assert "largest bound violation 0" in text
    lens = read_lens(out)
    assert paraxial(lens).efl == pytest.approx(49.5, abs=1e-8)
    assert "--global --seed 3 --starts 2 --method minimax'" in lens.notes
    assert "local method minimax" in lens.notes
    out2 = tmp_path / "o2.toml"
    argv2 = ["optimize", str(spec), "-o", str(out2), "--method", "minimax", "--json"]
    assert main(argv2 + ["--global", "--starts", "2", "--seed", "3"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["method"] == "minimax" and d["violation"] == 0.0
    assert d["merit"] == pytest.approx(1.5, rel=1e-9)
