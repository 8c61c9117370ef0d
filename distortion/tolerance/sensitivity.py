"""Sensitivity analysis: each tolerance alone at its limits, the others nominal, the compensator
applied — the change of every distortion output, ranked (finite differences on the instance
kernels: all 2 n_items instances in one launch).

The linear prediction of a Monte Carlo's spread (:meth:`SensitivityResult.rss`): item k changes an
output by the slope ``(Δ(max) − Δ(min)) / (max − min)`` per unit, so its 1-σ contribution is that
slope times the item's standard deviation (:attr:`raytrace.tolerance.ToleranceItem.std`), and
for independent items the standard deviations add in quadrature (root sum of squares).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from raytrace.lens import Lens
from raytrace.tolerance import ToleranceSpec, ToleranceSpecError, one_at_a_time

from .checks import split_where, unit_hint, warn_units, where_of
from .outputs import CURVES, DEFAULT_AZIMUTHS, DEFAULT_RINGS, ToleranceOutputs, evaluate, prepare


@dataclass(frozen=True, eq=False)
class SensitivityResult:
    """Outputs of the nominal lens and of every item at its min and max.

    Attributes
    ----------
    names, units : list of str
        Item labels and units (spec order).
    min, max : (n,) the limits.
    std : (n,) each item's standard deviation under its distribution.
    nominal : ToleranceOutputs (1 instance).
    at_min, at_max : ToleranceOutputs (n instances; row k = item k at its limit).
    fields_deg : (F,) curve fields, degrees.
    compensator : str
    lens_name : str
    g_object_distance : the object plane s' of g_ss' (mm from the first vertex), None when g was
        not computed (then the ``g`` outputs are NaN).
    """

    names: list
    units: list
    min: np.ndarray
    max: np.ndarray
    std: np.ndarray
    nominal: ToleranceOutputs
    at_min: ToleranceOutputs
    at_max: ToleranceOutputs
    fields_deg: np.ndarray
    compensator: str
    lens_name: str
    g_object_distance: float | None = None

    def _value(self, outputs: ToleranceOutputs, output: str, field_deg):
        v = getattr(outputs, output)
        if output in CURVES and field_deg is not None:
            return np.array([np.interp(field_deg, self.fields_deg, row) for row in v])
        return v

    def delta(self, output: str, field_deg: float | None = None) -> np.ndarray:
        """Change of ``output`` (a :class:`ToleranceOutputs` field name) from the nominal: (n, 2,
        ...) with [:, 0] at min and [:, 1] at max; a curve output at ``field_deg`` (linear
        interpolation) or at every curve field."""
        nom = self._value(self.nominal, output, field_deg)
        lo = self._value(self.at_min, output, field_deg) - nom
        hi = self._value(self.at_max, output, field_deg) - nom
        return np.stack([lo, hi], axis=1)

    def slope(self, output: str, field_deg: float | None = None) -> np.ndarray:
        """d output / d item (per unit of the item), from the two limits: (n, ...)."""
        d = self.delta(output, field_deg)
        w = (self.max - self.min).reshape((-1,) + (1,) * (d.ndim - 2))
        return (d[:, 1] - d[:, 0]) / w

    def rss(self, output: str, field_deg: float | None = None) -> np.ndarray:
        """Root sum of squares of the 1-σ contributions (module docstring): the standard
        deviation a Monte Carlo of small tolerances must show."""
        s = self.slope(output, field_deg)
        st = self.std.reshape((-1,) + (1,) * (s.ndim - 1))
        return np.sqrt(np.sum((s * st) ** 2, axis=0))

    def table(self, output: str, field_deg: float | None = None) -> list[dict]:
        """Items ranked by their largest |change| of a scalar output (a curve output needs
        ``field_deg``): dicts with name, unit, min, max, delta_min, delta_max, worst_abs, and
        share (the item's fraction of the squared RSS)."""
        d = self.delta(output, field_deg)
        if d.ndim != 2:
            raise ValueError(f"{output} is not a scalar output; give field_deg for a curve")
        s = self.slope(output, field_deg) * self.std
        tot = float(np.sum(s * s))
        rows = []
        for k, name in enumerate(self.names):
            rows.append(
                dict(
                    name=name,
                    unit=self.units[k],
                    min=float(self.min[k]),
                    max=float(self.max[k]),
                    delta_min=float(d[k, 0]),
                    delta_max=float(d[k, 1]),
                    worst_abs=_largest_abs(d[k]),
                    share=float(s[k] ** 2 / tot) if tot > 0 else float("nan"),
                )
            )
        rows.sort(key=lambda r: -r["worst_abs"] if np.isfinite(r["worst_abs"]) else 0.0)
        return rows

    def __repr__(self) -> str:
        return (
            f"SensitivityResult({self.lens_name}: {len(self.names)} items, "
            f"{self.fields_deg.size} fields, compensator {self.compensator})"
        )


def _largest_abs(v) -> float:
    """The largest finite |v| (NaN when none is finite; no All-NaN warning)."""
    a = np.abs(np.asarray(v, dtype=float))
    a = a[np.isfinite(a)]
    return float(a.max()) if a.size else float("nan")


def _refuse_untraceable(spec: ToleranceSpec, vals: np.ndarray, ok: np.ndarray) -> None:
    """ToleranceSpecError (one line) naming the first item whose min or max makes the lens
    untraceable (row 2k at min, 2k + 1 at max), with the unit hint
    (:func:`.checks.unit_hint`) and the number of other such items."""
    bad = [k for k in range(spec.n_items) if not (ok[2 * k] and ok[2 * k + 1])]
    if not bad:
        return
    k = bad[0]
    it = spec.items[k]
    at = [lab for lab, r in (("min", 2 * k), ("max", 2 * k + 1)) if not ok[r]]
    vals_s = " and ".join(f"{lab} {vals[2 * k + (lab == 'max'), k]:g}" for lab in at)
    unit = f" {it.unit}" if it.unit else ""
    hint = unit_hint(spec, k)
    more = ""
    if len(bad) > 1:
        others = ", ".join(split_where(where_of(spec, j))[1] for j in bad[1:4])
        more = f"; {others}{', ...' if len(bad) > 4 else ''} fail too"
    raise ToleranceSpecError(
        f"{where_of(spec, k)}: {it.name} at its {vals_s}{unit}: the lens cannot be traced "
        f"(chief rays or image plane fail){more}; {hint or 'give a limit the lens can take'}"
    )


def sensitivity(
    lens: Lens,
    spec: ToleranceSpec,
    *,
    fields_deg=None,
    object_distance: float | None = None,
    wavelength: float | None = None,
    which: str = "limits",
    grid_rings=DEFAULT_RINGS,
    grid_azimuths: int = DEFAULT_AZIMUTHS,
    radial_terms: int = 3,
    g_object_distance=None,
    setup=None,
) -> SensitivityResult:
    """Each item of ``spec`` alone at its min and at its max (module docstring). Arguments as
    :func:`distortion.tolerance.monte_carlo`; ``setup`` a :class:`ToleranceSetup` to reuse.

    Raises ToleranceSpecError (one line, naming the item) when an item at one of its limits
    makes the lens untraceable, saying so when the limit looks like another unit
    (:func:`distortion.tolerance.checks.unit_hint`); warns (:class:`UnitWarning`) for such a
    limit that still traces.

    Parameters
    ----------
    lens : Lens
        The nominal lens.
    spec : ToleranceSpec
        The items, their limits and the compensator
        (:func:`raytrace.tolerance.read_tolerance_spec`).
    fields_deg : array_like, optional
        Curve field angles in degrees along +y, in [0, 90); default 50 from 0 to the lens's
        field.
    object_distance : float or str, optional
        mm from the object plane to the first vertex (positive; ``inf``, ``"2m"``, ``"10x"``);
        default the lens's.
    wavelength : float or str, optional
        nm (or ``"0.55um"``, ``"d"``); default the lens's reference wavelength.
    which : {"limits"}
        Each item at its ``min`` and at its ``max`` (the only choice).
    grid_rings : sequence of float
        Rings of the 2-D fit points, fractions of the largest curve field (default 0.2 … 1.0);
        at least ``radial_terms`` + 2 distinct ones.
    grid_azimuths : int
        Points per ring (default 8; fewer than 3: no 2-D fit).
    radial_terms : int
        Radial order of the 2-D fit (c, K1 … K_n; default 3).
    g_object_distance : float or str, optional
        The object plane s' of Fraser & Shortis's g_ss' (Eq. 6), the lens focused at
        ``object_distance`` by its compensator (mm, ``inf``, ``"2m"``, ``"10x"``); default the
        spec's ``[outputs] g_object_distance``; without either g is not computed (NaN).
    setup : ToleranceSetup, optional
        A prepared setup to reuse; the arguments from ``fields_deg`` to ``g_object_distance``
        are then ignored.

    Returns
    -------
    SensitivityResult
        The nominal outputs and every item's outputs at its min and max (``rss`` is the linear
        prediction of a Monte Carlo's spread).

    Raises
    ------
    ToleranceSpecError
        A spec that does not fit the lens, or an item whose limit makes the lens untraceable.
    TypeError
        ``spec`` is not a ToleranceSpec.
    TraceError
        Field angles out of range, or a nominal chief ray that fails.
    DataError
        Too few distinct ``grid_rings``, or a g_ss' plane that cannot be defined.
    ValueError
        ``which`` other than ``"limits"``.

    Warns
    -----
    UnitWarning
        A limit that looks like another unit but still traces.
    """
    st = setup or prepare(lens, spec, fields_deg=fields_deg, object_distance=object_distance,
                          wavelength=wavelength, grid_rings=grid_rings,
                          grid_azimuths=grid_azimuths, radial_terms=radial_terms,
                          g_object_distance=g_object_distance)  # fmt: skip
    vals, _ = one_at_a_time(spec, which)
    nom = evaluate(st, np.zeros((1, spec.n_items)), parallel=False)
    out = evaluate(st, vals, parallel=False)
    _refuse_untraceable(spec, vals, np.asarray(out.ok, dtype=bool))
    warn_units(spec)
    return SensitivityResult(
        names=spec.names(),
        units=[it.unit for it in spec.items],
        min=np.array([it.min for it in spec.items]),
        max=np.array([it.max for it in spec.items]),
        std=np.array([it.std for it in spec.items]),
        nominal=nom,
        at_min=out.take(slice(0, None, 2)),
        at_max=out.take(slice(1, None, 2)),
        fields_deg=st.fields_deg,
        compensator=spec.compensator.type,
        lens_name=lens.name,
        g_object_distance=None if st.g is None else st.g.object_distance,
    )
