"""Global search: many starts and basin hopping around the spec's local method (damped least
squares, or minimax), with glass substitution over the shipped catalogs (in the manner of
OpticStudio's Hammer / global search and CODE V's global synthesis).

Every local run is the spec's ``method`` (:func:`raytrace.optimize.optimize`), and the starts are
ranked by that method's merit: the sum of squared weighted residuals for ``least_squares``; for
``minimax`` the exact-penalty merit φ = max|weighted target residual| + penalty × Σ weighted
bound violations (:func:`raytrace.optimize.minimax.penalty_merit`, which is the max weighted
residual itself when every bound is met), so that breaking a bound costs penalty × the weighted
violation in the ranking.

One *start* (start 0 is the spec's start lens as given; start k > 0 perturbs its continuous
variables and draws a random real glass for every glass variable):

1. glass fitting (when the spec has glass variables and ``model_phase``): each glass becomes a
   continuous nd / vd model glass inside its pool's window, a local run goes over all
   variables, then each glass snaps to the nearest real glass and, variable by variable, takes
   the best of its ``neighbours`` nearest real glasses, each judged after a local run;
2. a local run (:func:`raytrace.optimize.optimize`, the spec's method);
3. ``hops`` basin hops: perturb the start's best design, substitute one glass by one of its
   ``neighbours`` nearest on the glass map, run the local method, keep the trial when its
   merit is lower.

The starts run in worker processes (``concurrent.futures.ProcessPoolExecutor``, spawn start
method), as tasks on a Dask cluster (``executor``; :func:`raytrace.executors.dask_client`) or,
with one worker, in this process. A worker receives the spec, the start lens and the
start's number, nothing else. Start k draws its random numbers from
``numpy.random.SeedSequence(seed).spawn(starts)[k]`` only, and every local run is deterministic,
so the same seed gives the same result — bit for bit — whatever the number of workers, as long as
no time budget or interruption cuts the search short. The best start (lowest merit, then lowest
number) is polished with the spec's ``max_evaluations``.

Stopping: a time budget (``time_budget_s``) or Ctrl-C (KeyboardInterrupt in the calling process)
stops every start at its next merit evaluation; the result is the best design found so far, with
``stopped`` saying why: the starts cut short compete with their best design by then, and
``starts_stopped`` counts them. Workers ignore SIGINT themselves; the caller's process tells them.
"""

from __future__ import annotations

import math
import multiprocessing as mp
import queue as queue_mod
import signal
import time
from collections.abc import Callable
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from dataclasses import dataclass, replace

import numpy as np

from ..errors import OrthoscopeError, TraceError
from ..lens import Lens
from ..materials import model_glass
from ..paraxial import paraxial
from .glasses import GlassPool, availability, glass_pool
from .minimax import bounds_met, penalty_merit
from .operands import OperandValue, evaluate, merit
from .solver import (
    ASPHERIC_KINDS,
    StartLensError,
    apply,
    bounds,
    check_spec,
    continuous,
    max_violation,
    optimize,
    set_materials,
    set_values,
    start_values,
)
from .spec import DesignSpec, SearchSettings, SpecError, Variable


@dataclass(frozen=True)
class GlassChoice:
    """The glass a glass variable took: the medium after ``surface`` (1-based).

    ``price`` is the vendor's relative price (:attr:`raytrace.glass.CatalogGlass.price`: Schott
    N-BK7 = 1, CDGM H-K9L = 1), ``nan`` where the vendor prints none.
    """

    surface: int
    name: str
    catalog: str
    nd: float
    vd: float
    availability: str
    price: float = math.nan


#: the name of :attr:`GlobalResult.merit` for each local method: with minimax, the exact
#: penalty merit φ, which is the max weighted residual when every bound is met
MERIT_NAMES = {
    "least_squares": "merit",
    "minimax": "max weighted residual (+ penalty x bound violations)",
}


@dataclass(frozen=True)
class SearchProgress:
    """A progress report of the global search.

    event: ``"local"`` (a local run of a start ended), ``"start"`` (a start ended) or
    ``"polish"`` (the final polish ended); start: the start's number; hop: the basin hop (-1 for
    the start's first local runs); merit: that start's best merit so far; best: the best merit
    reported so far in the whole search; starts_done / starts: ended (finished or cut short) /
    requested starts; elapsed_s: seconds since the search began; stopped: for a ``"start"``
    event, ``""`` when the start ran to its end, else why it was cut short (``"time"``,
    ``"interrupted"``: its merit is then that of its best design by then).
    """

    event: str
    start: int
    hop: int
    merit: float
    best: float
    starts_done: int
    starts: int
    elapsed_s: float
    stopped: str = ""


@dataclass(frozen=True, eq=False)
class StartOutcome:
    """What one start found (picklable; the parent rebuilds the lens from it).

    x: the continuous variables (spec order, :func:`~raytrace.optimize.solver.continuous`);
    glasses: pool indices per glass variable; merit: its best merit (``nan`` when the start did
    not run); evaluations / local_runs / hops: work done; stopped: ``""``, ``"time"`` or
    ``"interrupted"``.
    """

    index: int
    merit: float
    x: np.ndarray
    glasses: tuple[int, ...]
    evaluations: int
    local_runs: int
    hops: int
    stopped: str
    seconds: float


@dataclass(frozen=True, eq=False)
class GlobalResult:
    """The result of :func:`global_optimize`.

    lens: the best design; method: the spec's local method; merit: its merit (``least_squares``:
    the sum of squared weighted residuals; ``minimax``: φ = max weighted residual + penalty ×
    bound violations, the max weighted residual when every bound is met); violation: the largest
    weighted bound violation of the design (0 when all are met); merit_start:
    the start lens's merit; start_merits: the best merit of each start (``nan`` for a start that
    did not run); starts_stopped: how many of those starts were cut short by the stop (their
    merit is that of their best design by then; :attr:`starts_finished` ran to their end);
    best_start: the start the design came from (-1: the start lens, when no finished start is
    better); best_start_cut_short: that start was cut short by the stop; seed: the root seed;
    glasses: the glass of each glass variable;
    operands: every operand on the best design; evaluations: merit evaluations in all starts and
    the polish; seconds: wall time; workers: processes used (on Dask: the cluster's workers);
    stopped: ``""``, ``"time"`` (budget spent), ``"interrupted"`` or ``"cluster"`` (the Dask
    cluster went away; the message says how); converged: the spec's merit
    goal is met (always true without a goal) and, with minimax, every bound is met; message: a
    one-line summary.
    """

    lens: Lens
    merit: float
    merit_start: float
    start_merits: np.ndarray
    best_start: int
    seed: int
    glasses: tuple[GlassChoice, ...]
    operands: tuple[OperandValue, ...]
    evaluations: int
    seconds: float
    workers: int
    stopped: str
    converged: bool
    message: str
    method: str = "least_squares"
    violation: float = 0.0
    starts_stopped: int = 0
    best_start_cut_short: bool = False

    @property
    def merit_is(self) -> str:
        """What :attr:`merit` is (:data:`MERIT_NAMES` of the method)."""
        return MERIT_NAMES[self.method]

    @property
    def starts(self) -> int:
        return int(self.start_merits.size)

    @property
    def starts_done(self) -> int:
        """Starts that gave a design: finished, or cut short (:attr:`starts_stopped`)."""
        return int(np.count_nonzero(np.isfinite(self.start_merits)))

    @property
    def starts_finished(self) -> int:
        """Starts that ran to their end."""
        return self.starts_done - self.starts_stopped

    def __repr__(self) -> str:
        count = starts_count(
            self.starts_finished, self.starts_stopped, self.starts, bool(self.stopped)
        )
        return (
            f"GlobalResult(merit {self.merit:.6g} from start {self.best_start}, {count}, "
            f"seed {self.seed}, "
            f"{self.seconds:.1f} s{', stopped: ' + self.stopped if self.stopped else ''})"
        )


def starts_count(finished: int, stopped: int, starts: int, search_stopped: bool = False) -> str:
    """How many starts gave a design: "3/8 starts"; in a search that was stopped
    (``search_stopped``) or had starts cut short (``stopped`` of them) "3 of 8 starts finished"
    and ", 1 cut short"."""
    if not (stopped or search_stopped):
        return f"{finished}/{starts} starts"
    return f"{finished} of {starts} starts finished" + (f", {stopped} cut short" if stopped else "")


#: why the search was stopped (:attr:`GlobalResult.stopped`), in words; "cluster" adds the cause
STOP_WORDS = {"time": "time budget spent", "interrupted": "interrupted"}


def goal_missed(
    method: str,
    merit: float,
    violation: float,
    merit_goal: float | None,
    *,
    name_merit: bool = True,
) -> str:
    """How a design misses the spec's goal, in words; ``""`` when it meets it (the search's
    ``converged``). With minimax a design that breaks a bound (:func:`.minimax.bounds_met`)
    misses it first: "a bound is not met (largest weighted violation 0.012)"; else a merit above
    ``merit_goal`` (or not a number): "merit 0.5 is above the merit goal 0.01", without the
    "merit 0.5 is " where ``name_merit`` is false (a text that has just said the merit)."""
    if method == "minimax" and not bounds_met(violation, merit):
        return f"a bound is not met (largest weighted violation {violation:.3g})"
    if merit_goal is None or merit <= merit_goal:
        return ""
    above = f"above the merit goal {merit_goal:.6g}"
    return f"{MERIT_NAMES[method]} {merit:.6g} is {above}" if name_merit else above


def stop_words(stopped: str, lost: str = "") -> str:
    """Why the search was stopped, in words (``lost``: what ended the Dask cluster)."""
    if stopped == "cluster":
        return "the Dask cluster was lost" + (f" ({lost})" if lost else "")
    return STOP_WORDS.get(stopped, stopped)


# ----------------------------------------------------------------------------- the design
def _glass_vars(spec: DesignSpec) -> tuple[Variable, ...]:
    return tuple(v for v in spec.variables if v.kind == "glass")


def _pools(spec: DesignSpec) -> tuple[GlassPool, ...]:
    return tuple(glass_pool(spec.glass_settings(v)) for v in _glass_vars(spec))


def _base(lens: Lens, spec: DesignSpec, x: np.ndarray, g, pools) -> Lens:
    """The start lens with glasses ``g`` (pool indices) and continuous values ``x`` set in it
    (pick-ups not yet applied; ``image_solve`` kept), the lens damped least squares starts from."""
    mats = {v.surface: pools[j].material(g[j]) for j, v in enumerate(_glass_vars(spec))}
    out = set_materials(lens, mats)
    ks = [(v.kind, v.surface) for v in continuous(spec)]
    if ks:
        out = replace(set_values(out, ks, x), image_solve=lens.image_solve)
    return out


def design(lens: Lens, spec: DesignSpec, x: np.ndarray, g, pools=None) -> Lens:
    """The full design of a state: glasses ``g`` (pool indices), continuous values ``x``,
    pick-ups applied."""
    pools = _pools(spec) if pools is None else pools
    return apply(_base(lens, spec, x, g, pools), spec, x)


def _search_merit(spec: DesignSpec, values: tuple[OperandValue, ...]) -> float:
    """The merit that ranks designs: the spec's method's (module docstring)."""
    if spec.method == "minimax":
        return penalty_merit(spec, values)
    return merit(values)


def _run_merit(spec: DesignSpec, res) -> float:
    """The ranking merit of a local run's result: damped least squares reports it; a minimax
    result reports max|e| alone, so φ is taken from its operands."""
    return res.merit if spec.method == "least_squares" else _search_merit(spec, res.operands)


def _merit_of(lens: Lens, spec: DesignSpec) -> float:
    try:
        return _search_merit(spec, evaluate(lens, spec.operands, check=False))
    except (OrthoscopeError, ValueError, ZeroDivisionError, FloatingPointError):
        return math.inf


def perturb(
    x: np.ndarray, variables: tuple[Variable, ...], efl: float, rng, sigma: float, lo, hi
) -> np.ndarray:
    """A random perturbation of the continuous variables ``x`` of relative size ``sigma``
    (one standard normal draw per variable, always, so the random stream does not depend on
    the values): curvature c + σ z (|c| + 0.1/|EFL|); thickness t·exp(σ z) (t + σ z for
    t ≤ 0); index n + 0.1 σ z; Abbe number ν·exp(σ z); conic k + σ z; aspheric A_k + σ z ×
    0.01 (0.1 EFL)^(1−k). Clipped into the bounds."""
    z = rng.standard_normal(len(x))
    out = np.array(x, dtype=float)
    r = 0.1 * abs(efl)
    for i, v in enumerate(variables):
        s = sigma * z[i]
        if v.kind == "curvature":
            out[i] = x[i] + s * (abs(x[i]) + 0.1 / abs(efl))
        elif v.kind == "thickness":
            out[i] = x[i] * math.exp(s) if x[i] > 0 else x[i] + s
        elif v.kind == "index":
            out[i] = x[i] + 0.1 * s
        elif v.kind == "abbe":
            out[i] = x[i] * math.exp(s)
        elif v.kind == "conic":
            out[i] = x[i] + s
        elif v.kind in ASPHERIC_KINDS:
            out[i] = x[i] + 0.01 * s * r ** (1 - (4 + 2 * ASPHERIC_KINDS.index(v.kind)))
    return np.clip(out, lo, hi)


class _Start:
    """The state of one start while it runs."""

    def __init__(self, lens, spec, k, seed, should_stop, report) -> None:
        self.lens, self.spec, self.k = lens, spec, k
        self.rng = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(k,)))
        self.should_stop, self.report = should_stop, report
        self.pools = _pools(spec)
        self.gvars = _glass_vars(spec)
        self.cont = continuous(spec)
        self.lo, self.hi = bounds(spec)
        s = spec.search
        self.local_n = s.local_evaluations or spec.max_evaluations
        self.evaluations = 0
        self.local_runs = 0
        self.hops = 0
        self.stopped = ""
        self.best_m = math.inf
        self.best_x = np.zeros(len(self.cont))
        self.best_g: tuple[int, ...] = ()

    # one local run from (x, g): returns (merit, x)
    def local(self, x: np.ndarray, g, spec: DesignSpec | None = None, lens: Lens | None = None):
        spec = self.spec if spec is None else spec
        lens = self.lens if lens is None else lens
        self.local_runs += 1
        if not continuous(spec):
            m = _merit_of(design(lens, spec, x, g, self.pools), spec)
            self.evaluations += 1
            return m, x
        base = _base(lens, spec, x, g, self.pools) if spec is self.spec else lens
        try:
            res = optimize(base, spec, stop=self.should_stop, max_evaluations=self.local_n)
        except (OrthoscopeError, ValueError, ZeroDivisionError, FloatingPointError):
            return math.inf, x  # the start design itself cannot be evaluated
        self.evaluations += res.evaluations + 2
        if res.stopped:
            self.stopped = res.stopped
        return _run_merit(spec, res), res.x

    def offer(self, m: float, x, g, hop: int) -> None:
        if m < self.best_m:
            self.best_m, self.best_x, self.best_g = m, np.array(x, dtype=float), tuple(g)
        self.report("local", self.k, hop, self.best_m)

    def initial(self) -> tuple[np.ndarray, list[int]]:
        """Start values: the lens's own for start 0; perturbed, with random glasses, else."""
        x0 = start_values(self.lens, self.spec)
        g0 = []
        for v, pool in zip(self.gvars, self.pools, strict=True):
            m = self.lens.surfaces[v.surface - 1].material
            i = pool.index_of(m)
            g0.append(int(pool.nearest(m.nd, m.vd, 1)[0]) if i is None else i)
        if self.k == 0:
            return x0, g0
        efl = paraxial(self.lens).efl

        def draw() -> list[int]:
            return [int(self.rng.integers(len(pool))) for pool in self.pools]

        def traces(x, g) -> bool:
            return math.isfinite(
                _merit_of(design(self.lens, self.spec, x, g, self.pools), self.spec)
            )

        g = draw()
        # a perturbed start that cannot be traced (a chief ray fails, an impossible lens) is
        # drawn again with half the perturbation, up to 8 times, every second time with other
        # random glasses too (a glass far from the lens's can make it untraceable at any
        # perturbation); then the lens's own values with the drawn glasses, else with its own
        sigma = self.spec.search.perturbation
        for attempt in range(8):
            x = perturb(x0, self.cont, efl, self.rng, sigma, self.lo, self.hi)
            if traces(x, g):
                return x, g
            sigma *= 0.5
            if attempt % 2 and self.pools:
                g = draw()
        return (x0, g) if traces(x0, g) else (x0, g0)

    def fit_glasses(self, x: np.ndarray, g: list[int]) -> tuple[np.ndarray, list[int]]:
        """Glass fitting: nd / vd model glasses optimized, then snapped to real glasses."""
        spec, gv = self.spec, self.gvars
        extra = []
        mats = {}
        for v, pool, gi in zip(gv, self.pools, g, strict=True):
            (n0, n1), (v0, v1) = pool.window()
            extra += [Variable("index", v.surface, n0, n1), Variable("abbe", v.surface, v0, v1)]
            if self.k == 0:
                m = self.lens.surfaces[v.surface - 1].material
                nd, vd = (m.nd, m.vd) if math.isfinite(m.vd) else (pool.nd[gi], pool.vd[gi])
            else:
                nd, vd = pool.nd[gi], pool.vd[gi]
            mats[v.surface] = model_glass(float(np.clip(nd, n0, n1)), float(np.clip(vd, v0, v1)))
        mspec = replace(spec, variables=self.cont + tuple(extra))
        mlens = set_materials(_base(self.lens, spec, x, g, self.pools), mats)
        m, xm = self.local(start_values(mlens, mspec), g, mspec, mlens)
        nc = len(self.cont)
        x = np.array(xm[:nc])
        if self.stopped:
            return x, g
        # snap: nearest real glass to each fitted nd / vd
        fitted = np.asarray(xm[nc:]).reshape(-1, 2)
        g = [int(p.nearest(nd, vd, 1)[0]) for p, (nd, vd) in zip(self.pools, fitted, strict=True)]
        best_m, best_x = self.local(x, g)
        self.offer(best_m, best_x, g, -1)
        # each glass in turn: the best of its nearest real glasses, the others held
        for j, (pool, (nd, vd)) in enumerate(zip(self.pools, fitted, strict=True)):
            n = pool.settings.neighbours
            for c in pool.nearest(nd, vd, n)[1:]:
                if self.stopped or self.should_stop():
                    return best_x, g
                trial = list(g)
                trial[j] = int(c)
                mt, xt = self.local(x, trial)
                self.offer(mt, xt, trial, -1)
                if mt < best_m:
                    best_m, best_x, g = mt, xt, trial
        return best_x, g

    def run(self) -> None:
        if self.should_stop():
            self.stopped = self.should_stop() or ""
            return
        x, g = self.initial()
        if (
            self.gvars
            and self.spec.glass.model_phase
            and all(p.settings.model_phase for p in self.pools)
        ):
            x, g = self.fit_glasses(x, g)
        if not self.stopped:
            m, x = self.local(x, g)
            self.offer(m, x, g, -1)
        efl = paraxial(self.lens).efl
        s = self.spec.search
        for h in range(s.hops):
            if self.stopped or self.should_stop():
                self.stopped = self.stopped or self.should_stop() or ""
                break
            if not math.isfinite(self.best_m):
                break
            xt = perturb(
                self.best_x, self.cont, efl, self.rng, s.hop_perturbation, self.lo, self.hi
            )
            gt = list(self.best_g)
            if self.gvars:
                j = int(self.rng.integers(len(self.gvars)))
                nb = self.pools[j].neighbours(gt[j], self.pools[j].settings.neighbours)
                gt[j] = int(nb[int(self.rng.integers(len(nb)))]) if len(nb) else gt[j]
            mt, xt = self.local(xt, gt)
            self.hops += 1
            self.offer(mt, xt, gt, h)

    def outcome(self, seconds: float) -> StartOutcome:
        return StartOutcome(
            self.k,
            self.best_m if math.isfinite(self.best_m) else math.nan,
            self.best_x,
            self.best_g,
            self.evaluations,
            self.local_runs,
            self.hops,
            self.stopped,
            seconds,
        )


def run_start(
    lens: Lens,
    spec: DesignSpec,
    k: int,
    seed: int,
    should_stop: Callable[[], str | None],
    report: Callable[[str, int, int, float], None],
) -> StartOutcome:
    """Run start ``k`` of the search (see the module docstring); a KeyboardInterrupt ends it
    with its best design so far."""
    t0 = time.perf_counter()
    st = _Start(lens, spec, k, seed, should_stop, report)
    try:
        st.run()
    except KeyboardInterrupt:
        st.stopped = "interrupted"
    return st.outcome(time.perf_counter() - t0)


# ----------------------------------------------------------------------------- workers
_WORKER: dict = {}


def _init_worker(event, q) -> None:
    from ..executors import ignore_worker_warnings

    signal.signal(signal.SIGINT, signal.SIG_IGN)  # the parent decides when to stop
    # what the parent says once (a glass outside its range, no kernel cache) a worker would say
    # at every evaluation, in raw multi-line form (raytrace.executors.WORKER_QUIET_WARNINGS)
    ignore_worker_warnings()
    _WORKER["event"], _WORKER["queue"] = event, q


def _worker_start(lens: Lens, spec: DesignSpec, k: int, seed: int, deadline: float):
    event, q = _WORKER["event"], _WORKER["queue"]

    def should_stop() -> str | None:
        if event.is_set():
            return "interrupted"
        return "time" if time.time() > deadline else None

    def report(kind, start, hop, m) -> None:
        q.put((kind, start, hop, m))

    return run_start(lens, spec, k, seed, should_stop, report)


# ----------------------------------------------------------------------------- the search
def _settings(spec: DesignSpec, **over) -> SearchSettings:
    s = spec.search
    kw = {k: v for k, v in over.items() if v is not None}
    out = replace(s, **kw)
    if out.starts < 1 or out.workers < 1 or out.hops < 0 or out.seed < 0:
        raise SpecError(
            "global search: starts and workers must be >= 1, hops and seed >= 0 "
            f"(got starts={out.starts}, workers={out.workers}, hops={out.hops}, seed={out.seed})"
        )
    if out.time_budget_s is not None and not out.time_budget_s > 0:
        raise SpecError(f"global search: time budget must be positive, got {out.time_budget_s}")
    return out


def global_optimize(
    lens: Lens,
    spec: DesignSpec,
    *,
    seed: int | None = None,
    starts: int | None = None,
    time_budget_s: float | None = None,
    workers: int | None = None,
    progress: Callable[[SearchProgress], None] | None = None,
    hops: int | None = None,
    executor=None,
) -> GlobalResult:
    """Global search for the spec's best design (module docstring).

    Parameters
    ----------
    lens : Lens
        The start lens (usually :func:`~raytrace.optimize.start_lens` of the spec).
    spec : DesignSpec
        Variables (continuous and ``glass``), pick-ups, operands; ``spec.search`` gives the
        defaults of the keywords below and ``spec.glass`` the glass pool.
    seed, starts, time_budget_s, workers, hops
        Override ``spec.search``: root seed (int >= 0), number of starts, wall-clock budget in
        seconds (None: none), worker processes (1: this process), basin hops per start.
    progress : callable, optional
        Called with a :class:`SearchProgress` after every local run and start (in this
        process); raising KeyboardInterrupt from it stops the search like Ctrl-C.
    executor : str or distributed.Client, optional
        Run the starts on a Dask cluster instead of local processes
        (:func:`raytrace.executors.dask_client`: ``"local:N"``, ``"tcp://HOST:PORT"`` or a
        client); ``workers`` then plays no part (the cluster has its own). The result is the
        same design, bit for bit; progress comes once per finished start.

    Returns
    -------
    GlobalResult
        The best design found, per-start merits, the seed; ``stopped`` tells whether a time
        budget or an interruption cut the search short (the result is then the best so far and
        depends on timing).
    """
    s = _settings(
        spec, seed=seed, starts=starts, time_budget_s=time_budget_s, workers=workers, hops=hops
    )
    spec = replace(spec, search=s)
    check_spec(lens, spec, need_continuous=False)
    pools = _pools(spec)  # raises SpecError for an unknown glass / empty pool, before any work
    t0 = time.perf_counter()
    deadline = time.time() + s.time_budget_s if s.time_budget_s is not None else math.inf
    merit_start = _merit_of(apply(lens, spec, start_values(lens, spec)), spec)
    outcomes: dict[int, StartOutcome] = {}
    best = [math.inf]
    stopped = ""
    n_workers, lost = s.workers, ""  # on Dask: the cluster's workers; what ended the cluster

    def emit(kind: str, k: int, hop: int, m: float, stopped: str = "") -> None:
        if m < best[0]:
            best[0] = m
        if progress is not None:
            progress(
                SearchProgress(
                    kind,
                    k,
                    hop,
                    m,
                    best[0],
                    len(outcomes),
                    s.starts,
                    time.perf_counter() - t0,
                    stopped,
                )
            )

    def finished(o: StartOutcome) -> None:
        outcomes[o.index] = o
        if math.isfinite(o.merit):  # not a start stopped before its first design
            emit("start", o.index, o.hops - 1, o.merit, o.stopped)

    try:
        if s.workers == 1 and executor is None:
            for k in range(s.starts):
                if time.time() > deadline:
                    stopped = "time"
                    break

                def should_stop() -> str | None:
                    return "time" if time.time() > deadline else None

                o = run_start(lens, spec, k, s.seed, should_stop, emit)
                finished(o)
                if o.stopped:
                    stopped = o.stopped
                    break
        elif executor is not None:
            stopped, n_workers, lost = _run_dask(executor, lens, spec, s, deadline, finished)
        else:
            stopped = _run_pool(lens, spec, s, deadline, emit, finished)
    except KeyboardInterrupt:
        stopped = "interrupted"

    done = [o for o in outcomes.values() if math.isfinite(o.merit)]
    start_merits = np.full(s.starts, math.nan)
    for o in done:
        start_merits[o.index] = o.merit
    evaluations = sum(o.evaluations for o in outcomes.values())
    polished = False
    if not done or min(o.merit for o in done) > merit_start:
        # nothing finished, or only starts cut short above the start lens (a stop): the start
        # lens is the best design known
        final = apply(lens, spec, start_values(lens, spec))
        g = ()
        best_k = -1
    else:
        bo = min(done, key=lambda o: (o.merit, o.index))
        best_k, g = bo.index, bo.glasses
        final = design(lens, spec, bo.x, g, pools)
        if not stopped and continuous(spec):
            try:
                pol = optimize(
                    _base(lens, spec, bo.x, g, pools),
                    spec,
                    stop=lambda: "time" if time.time() > deadline else None,
                )
                evaluations += pol.evaluations
                stopped, polished = pol.stopped, True
                if _run_merit(spec, pol) < _merit_of(final, spec):
                    final = pol.lens
            except KeyboardInterrupt:
                stopped = "interrupted"
            except (OrthoscopeError, ValueError, ZeroDivisionError, FloatingPointError):
                pass
    try:
        vals = evaluate(final, spec.operands, check=False)  # check_spec ran before the starts
    except TraceError as e:
        if best_k >= 0:
            raise
        # no start gave a design that can be evaluated, and the start lens cannot be either
        raise StartLensError(spec, e, ", kept: no start of the search gave a design") from None
    m = _search_merit(spec, vals)
    viol = max_violation(vals)
    if polished:
        emit("polish", best_k, -1, m)
    choices = tuple(
        GlassChoice(
            v.surface,
            pools[j].glasses[g[j]].name,
            pools[j].glasses[g[j]].catalog,
            pools[j].glasses[g[j]].nd,
            pools[j].glasses[g[j]].vd,
            availability(pools[j].glasses[g[j]]),
            pools[j].glasses[g[j]].price,
        )
        for j, v in enumerate(_glass_vars(spec))
        if g
    )
    # as a minimax run: a design that breaks a bound has not converged
    missed = goal_missed(spec.method, m, viol, spec.merit_goal, name_merit=False)
    converged = not missed
    n_cut = sum(1 for o in done if o.stopped)  # cut short by the stop, with a design
    best_cut = best_k >= 0 and bool(outcomes[best_k].stopped)
    name = MERIT_NAMES[spec.method]
    if stopped:  # first what stopped it and how far it got, then what it kept
        msg = (
            f"stopped ({stop_words(stopped, lost)}) with "
            f"{starts_count(len(done) - n_cut, n_cut, s.starts, True)}; "
            + (
                f"{name} {m:.6g}: the start lens, kept (no start better)"
                if best_k < 0
                else f"best {name} {m:.6g} from start {best_k}"
                + (", cut short" if best_cut else "")
            )
            + f" (seed {s.seed})"
        )
    elif best_k < 0:
        count = starts_count(len(done) - n_cut, n_cut, s.starts)
        if not n_cut:
            count = count.replace(" starts", " starts finished")
        msg = f"{name} {m:.6g}: the start lens, kept ({count}, none better; seed {s.seed})"
    else:
        count = starts_count(len(done) - n_cut, n_cut, s.starts)
        msg = f"best {name} {m:.6g} from start {best_k} of {count} (seed {s.seed})"
    if missed:
        msg += f"; {missed}"
    return GlobalResult(
        lens=final,
        merit=m,
        merit_start=merit_start,
        start_merits=start_merits,
        best_start=best_k,
        seed=s.seed,
        glasses=choices,
        operands=vals,
        evaluations=evaluations,
        seconds=time.perf_counter() - t0,
        workers=n_workers,
        stopped=stopped,
        converged=converged,
        message=msg,
        method=spec.method,
        violation=viol,
        starts_stopped=n_cut,
        best_start_cut_short=best_cut,
    )


def _stop_reason(stopped: str, o: StartOutcome, deadline: float) -> str:
    """Why the search stops after start ``o`` finished: the reason already known, else the
    start's own (it was stopped), else the time budget (``deadline``, epoch s), else none."""
    if stopped:
        return stopped
    if o.stopped:
        return o.stopped
    return "time" if time.time() > deadline else ""


#: how often (s) a start on a Dask worker asks the scheduler whether the search was stopped
DASK_STOP_POLL_S = 1.0


def _dask_start(lens: Lens, spec: DesignSpec, k: int, seed: int, deadline: float, stop: str):
    """One start on a Dask worker; the stop signal is the distributed Event ``stop``."""
    from distributed import Event

    event = Event(stop)
    asked = [-math.inf, False]

    def should_stop() -> str | None:
        now = time.time()
        if now - asked[0] > DASK_STOP_POLL_S:
            asked[0], asked[1] = now, event.is_set()
        if asked[1]:
            return "interrupted"
        return "time" if now > deadline else None

    return run_start(lens, spec, k, seed, should_stop, lambda *_: None)


def _run_dask(executor, lens, spec, s: SearchSettings, deadline: float, finished) -> tuple:
    """Run the starts as tasks on a Dask cluster; returns ``(why it stopped early, workers,
    what went wrong with the cluster or "")``. A stop (time budget, Ctrl-C) sets a distributed
    Event the running starts poll; every task then ends with its best so far, and those are
    kept (starts that had not begun end at once, without a design). A cluster that goes away
    (scheduler killed, connection lost) stops the search with the finished starts kept."""
    import uuid
    from concurrent.futures import CancelledError

    from ..executors import dask_client

    client, close = dask_client(executor)  # a clear error when Dask is not installed
    from distributed import Event, as_completed

    name = f"orthoscope-global-stop-{uuid.uuid4().hex}"
    stopped, lost = "", ""
    workers = 0

    try:
        workers = len(client.scheduler_info().get("workers", {}))
        event = Event(name, client=client)
        futures = {
            client.submit(_dask_start, lens, spec, k, s.seed, deadline, name, pure=False): k
            for k in range(s.starts)
        }
        ac = as_completed(futures)
        try:
            for f in ac:
                o = f.result()
                finished(o)
                stopped = _stop_reason(stopped, o, deadline)
                if stopped:
                    event.set()
        except KeyboardInterrupt:
            stopped = "interrupted"
            event.set()
            for f in ac:  # the starts end at their next poll with their best so far
                finished(f.result())
    except (OSError, CancelledError) as e:  # CommClosedError, TimeoutError, cancelled futures
        text = " ".join(f"{type(e).__name__}: {e}".split()).rstrip(":")  # one line
        stopped, lost = stopped or "cluster", text[:200]
    finally:
        try:
            if not lost:
                Event(name, client=client).clear()
            if close is not None:
                close()
        except (OSError, CancelledError):
            pass
    return stopped, workers, lost


def _run_pool(lens, spec, s: SearchSettings, deadline: float, emit, finished) -> str:
    """Run the starts in ``s.workers`` spawned processes; returns why it stopped early."""
    ctx = mp.get_context("spawn")
    event = ctx.Event()
    q = ctx.Queue()
    stopped = ""

    def drain() -> None:
        while True:
            try:
                item = q.get_nowait()
            except queue_mod.Empty:
                return
            emit(*item)

    ex = ProcessPoolExecutor(
        max_workers=s.workers, mp_context=ctx, initializer=_init_worker, initargs=(event, q)
    )
    try:
        futures = {
            ex.submit(_worker_start, lens, spec, k, s.seed, deadline): k for k in range(s.starts)
        }
        pending = set(futures)
        try:
            while pending:
                done, pending = wait(pending, timeout=0.2, return_when=FIRST_COMPLETED)
                drain()
                for f in sorted(done, key=lambda f: futures[f]):
                    if not f.cancelled():
                        o = f.result()
                        finished(o)
                        stopped = _stop_reason(stopped, o, deadline)
                if time.time() > deadline and not stopped:
                    stopped = "time"
                if stopped:
                    event.set()
                    for f in pending:
                        f.cancel()
        except KeyboardInterrupt:
            stopped = "interrupted"
            event.set()
            for f in pending:
                f.cancel()
            # the running starts end at their next merit evaluation with their best so far
            for f in sorted(pending, key=lambda f: futures[f]):
                if not f.cancelled():
                    o = f.result()
                    finished(o)
        drain()
    finally:
        ex.shutdown(wait=True, cancel_futures=True)
    return stopped
