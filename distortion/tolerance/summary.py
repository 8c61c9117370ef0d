"""The summary of a Monte Carlo run computed chunk by chunk, so that a run of 10⁷ instances never
holds all its instances (:func:`distortion.tolerance.monte_carlo` with ``summary="streaming"``).

What is summarised: every *quantity* of the run — the scalar outputs of
:class:`~distortion.tolerance.ToleranceOutputs` (``SCALARS``), K1..Kn, and the curves ``D_um``
and ``D_cal_um`` at each curve field — over the instances that traced (``ok``) and have a finite
value; and the yields against limits declared before the run.

Determinism. The instances are grouped into fixed **blocks** of ``block`` consecutive instance
numbers (block b holds instances b·block .. (b+1)·block − 1), whatever the chunks that deliver
them: rows are copied into their block's matrix as chunks arrive (in any order), and a block is
reduced when its last row arrives. A block's reduction depends only on its instances (numpy
reductions over a matrix of fixed shape), and the block results are merged strictly in block
order, so the summary is bit-identical for any chunk size, any number of workers, any completion
order and after a resume, on one host and build (docs/tolerance.md, "Random numbers,
determinism").

Statistics per quantity:

* count, minimum, maximum: exact;
* mean and variance: each block's mean ``Σx/n`` and sum of squared deviations
  ``M2 = Σ(x − mean)²``, merged in block order by the pairwise update of Chan, Golub & LeVeque
  (1979; "Updating formulae and a pairwise algorithm for computing sample variances")::

      n = nA + nB,  δ = meanB − meanA,  mean = meanA + δ nB / n,  M2 = M2A + M2B + δ² nA nB / n

  (std = √(M2 / (n − 1))); they equal numpy's two-pass ``mean``/``std`` of all the values to
  round-off (≈1e-15 relative, not bit for bit: numpy sums in another order);
* percentiles: from a fixed-bin histogram. Its range is set by block 0 (instances
  0 .. block − 1, computed first): the range [min, max] of its values widened ``widen`` times
  about its centre, cut into ``bins`` equal bins; values outside are counted as underflow /
  overflow. The k-th order statistic is placed inside its bin (spread evenly over the bin's
  count) and percentiles interpolate between order statistics as ``numpy.percentile``'s default
  ("linear") method does, so **every percentile is within one bin width of numpy's exact
  percentile** of the same values (the bin width is reported per quantity). The 0 % and 100 %
  points are the exact minimum and maximum. A percentile whose order statistics fall in the
  underflow or overflow is NaN (the counts say how many values lie outside).
* yields: exact integer counts of instances with |D| < limit at a field (each instance's curve
  interpolated linearly, as :meth:`MonteCarloResult.yield_fraction`), raw and calibrated.

Memory: the rows of the blocks not yet complete (one (block, Q) matrix per open block: 4096 ×
~120 quantities × 8 bytes ≈ 4 MB for F = 50) plus, per quantity, ``bins + 2`` integer counts.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .outputs import SCALARS

#: instances per block (the unit of reduction; fixed by instance numbers, not by chunks)
SUMMARY_BLOCK = 4096
#: histogram bins per quantity
SUMMARY_BINS = 4096
#: the histogram spans the first block's range widened this many times about its centre
RANGE_WIDEN = 4.0

PERCENTILE_METHOD = (
    "fixed-bin histograms ({bins} bins per quantity over the range of instances 0..{last} "
    "widened {widen:g}x; order statistics placed inside their bins, linear interpolation as "
    "numpy.percentile): within one bin width (bin_width) of the exact percentile"
)


def quantity_names(scalars: tuple[str, ...], radial_terms: int, n_fields: int) -> list[str]:
    """The quantities summarised, in column order: the scalars, K1..Kn, then ``D_um[j]`` and
    ``D_cal_um[j]`` for each curve field j."""
    names = list(scalars) + [f"K{i + 1}" for i in range(radial_terms)]
    names += [f"D_um[{j}]" for j in range(n_fields)]
    names += [f"D_cal_um[{j}]" for j in range(n_fields)]
    return names


def quantity_matrix(arrays: dict, scalars: tuple[str, ...]) -> np.ndarray:
    """(I, Q) values of the quantities of :func:`quantity_names` from a chunk's arrays (the
    :meth:`ToleranceOutputs.arrays` dict)."""
    cols = [np.asarray(arrays[k], dtype=float)[:, None] for k in scalars]
    cols += [np.asarray(arrays["K"], dtype=float), np.asarray(arrays["D_um"], dtype=float),
             np.asarray(arrays["D_cal_um"], dtype=float)]  # fmt: skip
    return np.concatenate(cols, axis=1)


def interpolation_weights(fields_deg: np.ndarray, field_deg: float) -> tuple[int, float]:
    """(j, w): the curve at ``field_deg`` is ``D[j − 1]·(1 − w) + D[j]·w`` (linear
    interpolation between the traced fields). ValueError outside the traced fields."""
    fd = np.asarray(fields_deg, dtype=float)
    if not (fd.min() <= field_deg <= fd.max()):
        raise ValueError(
            f"field {field_deg:g} deg is outside the traced {fd.min():g}..{fd.max():g}"
        )
    j = int(np.clip(np.searchsorted(fd, field_deg), 1, fd.size - 1))
    return j, float((field_deg - fd[j - 1]) / (fd[j] - fd[j - 1]))


def yield_counts(D: np.ndarray, ok: np.ndarray, j: int, w: float, limit_um: float) -> int:
    """Number of instances with ``ok`` and |D| < ``limit_um`` at the interpolated field."""
    d = D[:, j - 1] * (1.0 - w) + D[:, j] * w
    good = ok & np.isfinite(d)
    return int(np.count_nonzero(good & (np.abs(d) < limit_um)))


@dataclass(frozen=True, eq=False)
class StreamedSummary:
    """The merged summary (module docstring); arrays over the quantities ``names``.

    count : (Q,) int, finite values among ok instances; mean, std, min, max : (Q,);
    lo, width : (Q,) the histogram's lower edge and bin width (NaN: no finite value in block 0);
    hist : (Q, bins + 2) int64 counts, column 0 underflow, column −1 overflow;
    n, n_ok : instances, instances that traced; limits : ((µm, deg), ...);
    yields_raw, yields_cal : (L,) int counts per limit; block, bins, widen : the settings.
    """

    names: tuple[str, ...]
    count: np.ndarray
    mean: np.ndarray
    std: np.ndarray
    min: np.ndarray
    max: np.ndarray
    lo: np.ndarray
    width: np.ndarray
    hist: np.ndarray
    n: int
    n_ok: int
    limits: tuple
    yields_raw: np.ndarray
    yields_cal: np.ndarray
    block: int
    bins: int
    widen: float

    def index(self, name: str) -> int:
        return self.names.index(name)

    def _order_stat(self, q: int, k: int, cum: np.ndarray) -> float:
        n = int(self.count[q])
        if k <= 0:
            return float(self.min[q])
        if k >= n - 1:
            return float(self.max[q])
        i = int(np.searchsorted(cum, k, side="right"))  # first slot with cum > k
        if i == 0 or i >= self.bins + 1:
            return math.nan  # in the underflow or overflow
        c = int(self.hist[q, i])
        j = k - int(cum[i - 1])
        return float(self.lo[q] + self.width[q] * ((i - 1) + (j + 0.5) / c))

    def percentiles(self, name: str, levels) -> np.ndarray:
        """Percentiles (``levels`` in %) of quantity ``name`` (module docstring: within one bin
        width of ``numpy.percentile``); NaN without values or outside the histogram."""
        q = self.index(name)
        lev = np.atleast_1d(np.asarray(levels, dtype=float))
        n = int(self.count[q])
        out = np.full(lev.shape, np.nan)
        if n == 0 or not np.isfinite(self.lo[q]):
            if n == 1:
                out[:] = self.min[q]
            return out
        cum = np.cumsum(self.hist[q])
        for a, p in enumerate(lev):
            h = (n - 1) * p / 100.0
            k = int(math.floor(h))
            f = h - k
            x = self._order_stat(q, k, cum)
            if f > 0.0:
                x = x + f * (self._order_stat(q, k + 1, cum) - x)
            out[a] = x
        return out

    def stats(self, name: str) -> dict:
        """mean, std, min, max, p2.5, p97.5 of quantity ``name`` (the keys of the exact
        summary) plus ``bin_width`` and the values outside the histogram."""
        q = self.index(name)
        if self.count[q] == 0:
            return {k: math.nan for k in ("mean", "std", "min", "max", "p2.5", "p97.5")}
        p = self.percentiles(name, (2.5, 97.5))
        return {
            "mean": float(self.mean[q]),
            "std": float(self.std[q]),
            "min": float(self.min[q]),
            "max": float(self.max[q]),
            "p2.5": float(p[0]),
            "p97.5": float(p[1]),
            "bin_width": float(self.width[q]),
            "outside": float(self.hist[q, 0] + self.hist[q, -1]),
        }

    def histogram(self, name: str, bins: int = 50) -> tuple[np.ndarray, np.ndarray]:
        """(counts, edges) of quantity ``name`` for plotting: the fine bins between the exact
        min and max grouped into about ``bins`` bins (counts are exact sums of fine bins)."""
        q = self.index(name)
        if self.count[q] == 0 or not np.isfinite(self.lo[q]):
            return np.zeros(0, dtype=np.int64), np.zeros(1)
        i0 = int(np.clip(math.floor((self.min[q] - self.lo[q]) / self.width[q]), 0, self.bins - 1))
        i1 = int(np.clip(math.floor((self.max[q] - self.lo[q]) / self.width[q]), 0, self.bins - 1))
        group = max(1, -(-(i1 - i0 + 1) // bins))
        fine = self.hist[q, 1 + i0 : 2 + i1]
        pad = (-fine.size) % group
        counts = np.concatenate([fine, np.zeros(pad, dtype=np.int64)]).reshape(-1, group).sum(1)
        edges = self.lo[q] + self.width[q] * (i0 + group * np.arange(counts.size + 1))
        return counts, edges


class StreamingSummary:
    """Accumulates the summary of ``n`` instances from chunks given in any order
    (:meth:`add`), reducing fixed blocks and merging them in block order (module docstring).

    Parameters
    ----------
    n : int, instances of the run.
    fields_deg : (F,) the curve fields (for the yields).
    radial_terms : int, K1..Kn.
    limits : ((limit µm, field deg), ...) yields counted during the run.
    block, bins, widen : the block size, histogram bins and range widening.
    """

    def __init__(self, n: int, fields_deg, radial_terms: int, limits=(), *,
                 block: int = SUMMARY_BLOCK, bins: int = SUMMARY_BINS,
                 widen: float = RANGE_WIDEN) -> None:  # fmt: skip
        if block < 1 or bins < 1 or not widen >= 1.0:
            raise ValueError("block and bins must be >= 1 and widen >= 1")
        self.n = int(n)
        self.fields = np.asarray(fields_deg, dtype=float)
        self.names = tuple(quantity_names(SCALARS, radial_terms, self.fields.size))
        self.Q = len(self.names)
        self.block = int(block)
        self.bins = int(bins)
        self.widen = float(widen)
        self.limits = tuple((float(a), float(b)) for a, b in limits)
        self.weights = [interpolation_weights(self.fields, deg) for _, deg in self.limits]
        self.n_blocks = max(1, -(-self.n // self.block))
        self.open: dict[int, list] = {}  # block -> [matrix, ok, D, Dcal, filled]
        self.done: dict[int, tuple] = {}  # reduced blocks waiting for their predecessors
        self.waiting: dict[int, list] = {}  # complete blocks waiting for the histogram range
        self.next = 0  # the next block to merge
        self.lo = None
        self.width = None
        self.acc = None
        self.yields = np.zeros((2, len(self.limits)), dtype=np.int64)
        self.n_ok = 0

    def _size(self, b: int) -> int:
        return min(self.n, (b + 1) * self.block) - b * self.block

    def add(self, start: int, arrays: dict) -> None:
        """The outputs ``arrays`` (:meth:`ToleranceOutputs.arrays` of instances ``start ..``)."""
        M = quantity_matrix(arrays, SCALARS)
        ok = np.asarray(arrays["ok"], dtype=bool)
        D = np.asarray(arrays["D_um"], dtype=float)
        Dc = np.asarray(arrays["D_cal_um"], dtype=float)
        stop = start + M.shape[0]
        i = start
        while i < stop:
            b = i // self.block
            b0 = b * self.block
            j = min(stop, b0 + self._size(b))
            ent = self.open.get(b)
            if ent is None:
                size = self._size(b)
                ent = [np.full((size, self.Q), np.nan), np.zeros(size, dtype=bool),
                       np.full((size, D.shape[1]), np.nan), np.full((size, D.shape[1]), np.nan),
                       0]  # fmt: skip
                self.open[b] = ent
            r = slice(i - b0, j - b0)
            s = slice(i - start, j - start)
            ent[0][r], ent[1][r], ent[2][r], ent[3][r] = M[s], ok[s], D[s], Dc[s]
            ent[4] += j - i
            if ent[4] == ent[0].shape[0]:
                del self.open[b]
                self._complete(b, ent)
            i = j

    def _complete(self, b: int, ent: list) -> None:
        M, ok, D, Dc, _ = ent
        for k, ((lim, _), (j, w)) in enumerate(zip(self.limits, self.weights, strict=True)):
            self.yields[0, k] += yield_counts(D, ok, j, w, lim)
            self.yields[1, k] += yield_counts(Dc, ok, j, w, lim)
        self.n_ok += int(np.count_nonzero(ok))
        if self.lo is None and b != 0:
            self.waiting[b] = [M, ok]
            return
        if b == 0:
            self._set_range(M, ok)
        self.done[b] = self._reduce(M, ok)
        for w_b in sorted(self.waiting):
            Mw, okw = self.waiting.pop(w_b)
            self.done[w_b] = self._reduce(Mw, okw)
        while self.next in self.done:
            self._merge(self.done.pop(self.next))
            self.next += 1

    def _set_range(self, M: np.ndarray, ok: np.ndarray) -> None:
        mask = ok[:, None] & np.isfinite(M)
        with np.errstate(invalid="ignore"):
            lo = np.where(mask, M, np.inf).min(axis=0)
            hi = np.where(mask, M, -np.inf).max(axis=0)
        have = mask.any(axis=0)
        lo, hi = np.where(have, lo, 0.0), np.where(have, hi, 0.0)
        c = 0.5 * (lo + hi)
        h = 0.5 * (hi - lo)
        h = np.maximum(h, np.maximum(64.0 * np.spacing(np.abs(c)), 1e-300))
        self.lo = np.where(have, c - self.widen * h, np.nan)
        self.width = np.where(have, 2.0 * self.widen * h / self.bins, np.nan)

    def _reduce(self, M: np.ndarray, ok: np.ndarray) -> tuple:
        """(count, mean, M2, min, max, hist) of one block (module docstring)."""
        mask = ok[:, None] & np.isfinite(M)
        cnt = mask.sum(axis=0)
        v = np.where(mask, M, 0.0)
        with np.errstate(invalid="ignore", divide="ignore"):
            mean = np.where(cnt > 0, v.sum(axis=0) / cnt, 0.0)
            dev = np.where(mask, M - mean, 0.0)
            m2 = (dev * dev).sum(axis=0)
            mn = np.where(mask, M, np.inf).min(axis=0)
            mx = np.where(mask, M, -np.inf).max(axis=0)
            idx = np.floor((M - self.lo) / self.width)
        use = mask & np.isfinite(idx)
        slot = np.clip(np.where(use, idx, 0.0), -1.0, float(self.bins)).astype(np.int64) + 1
        flat = (np.arange(self.Q)[None, :] * (self.bins + 2) + slot)[use]
        hist = np.bincount(flat, minlength=self.Q * (self.bins + 2)).reshape(self.Q, -1)
        return cnt.astype(np.int64), mean, m2, mn, mx, hist.astype(np.int64)

    def _merge(self, part: tuple) -> None:
        if self.acc is None:
            self.acc = [np.array(a, copy=True) for a in part]
            return
        nA, mA, m2A, mnA, mxA, hA = self.acc
        nB, mB, m2B, mnB, mxB, hB = part
        n = nA + nB
        with np.errstate(invalid="ignore", divide="ignore"):
            d = mB - mA
            mean = np.where(n > 0, mA + d * np.where(n > 0, nB / n, 0.0), 0.0)
            m2 = m2A + m2B + np.where(n > 0, d * d * (nA * nB) / n, 0.0)
        mean = np.where(nB == 0, mA, np.where(nA == 0, mB, mean))
        m2 = np.where(nB == 0, m2A, np.where(nA == 0, m2B, m2))
        self.acc = [n, mean, m2, np.minimum(mnA, mnB), np.maximum(mxA, mxB), hA + hB]

    def result(self) -> StreamedSummary:
        """The summary; every instance must have been added."""
        if self.open or self.waiting or self.next != self.n_blocks:
            missing = sorted(set(range(self.n_blocks)) - set(range(self.next)))
            raise RuntimeError(f"the summary is missing blocks {missing[:5]}...")
        n, mean, m2, mn, mx, hist = self.acc
        with np.errstate(invalid="ignore", divide="ignore"):
            std = np.where(n > 1, np.sqrt(m2 / np.maximum(n - 1, 1)), np.nan)
        none = n == 0
        return StreamedSummary(
            names=self.names,
            count=n,
            mean=np.where(none, np.nan, mean),
            std=std,
            min=np.where(none, np.nan, mn),
            max=np.where(none, np.nan, mx),
            lo=self.lo,
            width=self.width,
            hist=hist,
            n=self.n,
            n_ok=self.n_ok,
            limits=self.limits,
            yields_raw=self.yields[0].copy(),
            yields_cal=self.yields[1].copy(),
            block=self.block,
            bins=self.bins,
            widen=self.widen,
        )
