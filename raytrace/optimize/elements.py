"""Splitting or adding an element in a design: the lens edit (:mod:`raytrace.elements`) together
with the spec renumbered to match, so a run can go on with one element more.

Every surface number of the spec (variables, pick-ups and sources, operands' ``surface`` and
``last``) is carried to the edited lens by :func:`raytrace.elements.surface_map`, and the new
surfaces get variables and rules like their neighbours' (:func:`split_design`,
:func:`insert_design`). The spec is checked against the start lens first, so its errors speak of
the surfaces the user wrote.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, replace

from ..elements import DEFAULT_GAP, elements, insert_element, split_element, surface_map
from ..lens import Lens
from ..materials import Material
from .solver import EVAL_FAILURES, OptimizationResult, check_spec, optimize
from .spec import DesignSpec, Operand, Pickup, SpecError, Variable


def _renumbered(spec: DesignSpec, where) -> DesignSpec:
    def op(o: Operand) -> Operand:
        p = dict(o.params)
        if o.type == "element_power" and "last" not in p:
            p["last"] = int(p["surface"]) + 1  # the element it meant, written out
        for k in ("surface", "last"):
            if k in p:
                p[k] = where(int(p[k]))
        return replace(o, params=p)

    return replace(
        spec,
        variables=tuple(replace(v, surface=where(v.surface)) for v in spec.variables),
        pickups=tuple(
            replace(pk, surface=where(pk.surface), source=where(pk.source)) for pk in spec.pickups
        ),
        operands=tuple(op(o) for o in spec.operands),
    )


#: the lower bound of an inserted element's thickness when the spec bounds no glass thickness
MIN_GLASS = 0.5


def _smallest_bound(lens: Lens, spec: DesignSpec, glass: bool) -> float | None:
    """The smallest lower bound of the spec's thickness variables on glass (or air) spaces,
    None when it has none."""
    lows = [
        v.lower
        for v in spec.variables
        if v.kind == "thickness"
        and v.surface < lens.n_surfaces
        and lens.surfaces[v.surface - 1].material.is_air != glass
        and math.isfinite(v.lower)
    ]
    return min(lows) if lows else None


def _min_rule(o: Operand) -> bool:
    """A shop rule: a bound with a minimum only (no target, no maximum)."""
    return "min" in o.params and "max" not in o.params


def split_design(
    lens: Lens, spec: DesignSpec, surface: int, *, gap: float = DEFAULT_GAP
) -> tuple[Lens, DesignSpec]:
    """Split the element at ``surface`` of ``lens`` (:func:`raytrace.elements.split_element`)
    and renumber ``spec`` to match.

    Parameters
    ----------
    lens, spec
        The start lens and its design spec.
    surface : int
        The element's first surface (1-based, numbering of ``lens``).
    gap : float
        Air between the halves, mm; raised to the spec's smallest air-thickness bound.

    Returns
    -------
    (Lens, DesignSpec)
        The lens with two surfaces more and the spec for it:

        - the element's variables of curvature, thickness, index, Abbe number and glass are
          repeated on the second half (surface + 2, the same bounds; a half below a glass
          thickness bound starts at the bound, which changes the lens), the two cut surfaces are
          free in curvature within the union of the element's curvature bounds when either
          element surface was, and the gap is a thickness variable above the spec's smallest
          air bound when the element's thickness was;
        - pick-ups onto the element go to both halves (a thickness pick-up at half its factor
          and offset);
        - the element's minimum rules (``center_thickness`` / ``edge_thickness`` with ``min``
          only) are repeated on the second half, and the gap gets the spec's smallest air edge
          ``min`` at the element's edge heights; targets and maxima on the element's thickness
          stay on the first half.

    Raises
    ------
    SpecError
        The spec does not fit the lens, or the element's thickness is the source of a pick-up
        (after the split the element has two).
    """
    check_spec(lens, spec, need_continuous=False)
    k = surface
    if any(p.kind == "thickness" and p.source == k for p in spec.pickups):
        raise SpecError(
            f"the thickness of surface {k} is the source of a pick-up: split in two, the "
            "element has two thicknesses; change the pick-up first"
        )
    air_low = _smallest_bound(lens, spec, glass=False)
    gap = max(gap, air_low) if air_low is not None else gap
    new_lens = split_element(lens, k, gap=gap)
    out = _renumbered(spec, surface_map(k))
    added: list[Variable] = []
    curv = [v for v in spec.variables if v.kind == "curvature" and v.surface in (k, k + 1)]
    if curv:
        lo, hi = min(v.lower for v in curv), max(v.upper for v in curv)
        added += [Variable("curvature", k + 1, lo, hi), Variable("curvature", k + 2, lo, hi)]
    for v in spec.variables:
        if v.surface == k and v.kind in ("thickness", "index", "abbe", "glass"):
            added.append(replace(v, surface=k + 2))
            if v.kind == "thickness":
                added.append(Variable("thickness", k + 1, gap if air_low is None else air_low))
    pickups: list[Pickup] = []
    for p in out.pickups:
        if p.surface != k:
            pickups.append(p)
        elif p.kind == "thickness":  # the element's thickness, shared by its halves
            half = replace(p, factor=0.5 * p.factor, offset=0.5 * p.offset)
            pickups += [half, replace(half, surface=k + 2)]
        else:
            pickups += [p, replace(p, surface=k + 2)]
    rules = [
        o
        for o in out.operands
        if o.type in ("center_thickness", "edge_thickness")
        and o.params["surface"] == k
        and _min_rule(o)
    ]
    air_edges = [
        o.params["min"]
        for o in spec.operands
        if o.type == "edge_thickness"
        and _min_rule(o)
        and o.params["surface"] < lens.n_surfaces
        and lens.surfaces[o.params["surface"] - 1].material.is_air
    ]
    extra = [replace(o, params={**o.params, "surface": k + 2}) for o in rules]
    if air_edges:
        extra += [
            replace(o, params={**o.params, "surface": k + 1, "min": min(air_edges)})
            for o in rules
            if o.type == "edge_thickness"
        ]
    return new_lens, replace(
        out,
        variables=out.variables + tuple(added),
        pickups=tuple(pickups),
        operands=out.operands + tuple(extra),
    )


def insert_design(
    lens: Lens,
    spec: DesignSpec,
    after: int,
    material: Material,
    *,
    thickness: float = 2.0,
    gap: float | None = None,
) -> tuple[Lens, DesignSpec]:
    """Insert a plate of ``material`` after surface ``after``
    (:func:`raytrace.elements.insert_element`; in the middle of the air space unless ``gap``)
    and renumber ``spec`` to match.

    The new element's two curvatures are free and its thickness (raised to the spec's smallest
    glass-thickness bound) is a variable above that bound (else above :data:`MIN_GLASS`); when
    the air space it went into was a thickness variable, the air behind the new element takes
    that variable (its bounds) and the air in front of it one above the spec's smallest air
    bound (else above :data:`raytrace.elements.DEFAULT_GAP`).

    Parameters
    ----------
    lens : Lens
    spec : DesignSpec
        A design spec of ``lens``.
    after : int
        The surface (1-based) with air after it.
    material : Material
        The new element's glass (not air).
    thickness : float
        Centre thickness of the plate in mm (> 0; default 2.0).
    gap : float, optional
        Air in front of the plate in mm (> 0); default the middle of the air space.

    Returns
    -------
    (Lens, DesignSpec)
        The lens with two more surfaces (``after`` + 1 and ``after`` + 2) and the spec
        renumbered, with the new variables.

    Raises
    ------
    SpecError
        The spec does not fit the lens.
    LensError
        No such surface, a mirror or coordinate break, glass after the surface, an air
        ``material``, a thickness or gap that is not positive, or an air space too short.
    """
    check_spec(lens, spec, need_continuous=False)
    glass_low = _smallest_bound(lens, spec, glass=True)
    air_low = _smallest_bound(lens, spec, glass=False)
    if glass_low is not None:
        thickness = max(thickness, glass_low)
    new_lens = insert_element(lens, after, material, thickness=thickness, gap=gap)
    out = _renumbered(spec, surface_map(after))
    a = after
    keep, added = (
        [],
        [
            Variable("curvature", a + 1),
            Variable("curvature", a + 2),
            Variable("thickness", a + 1, MIN_GLASS if glass_low is None else glass_low),
        ],
    )
    for v in out.variables:
        if v.kind == "thickness" and v.surface == a:  # the space now behind the new element
            front = DEFAULT_GAP if air_low is None else air_low
            added += [replace(v, surface=a + 2), Variable("thickness", a, front)]
        else:
            keep.append(v)
    return new_lens, replace(out, variables=tuple(keep) + tuple(added))


@dataclass(frozen=True)
class SplitTrial:
    """One element of :func:`scan_splits`: its first ``surface`` (start-lens numbering), the
    local run's ``result`` on the lens with that element split (None when the split was refused
    or the run failed: ``error`` says why). ``stopped``: ``"interrupted"`` when a Ctrl-C ended
    the scan in this trial (its ``result`` is then the best design it evaluated, or None when
    it had evaluated none), else empty."""

    surface: int
    result: OptimizationResult | None
    error: str = ""
    stopped: str = ""

    @property
    def merit(self) -> float:
        """The run's merit (its method's), inf when there is none."""
        return math.inf if self.result is None else self.result.merit


def scan_splits(
    lens: Lens,
    spec: DesignSpec,
    *,
    progress: Callable[[SplitTrial], None] | None = None,
) -> tuple[SplitTrial, ...]:
    """Where to split: every single element of ``lens`` split in turn (:func:`split_design`)
    and the spec's local run (its ``method``) from each; ``progress(trial)`` after each.

    Returns
    -------
    tuple of SplitTrial
        One per element (:func:`raytrace.elements.elements`), in surface order; the best is
        ``min(trials, key=lambda t: t.merit)``. The runs are deterministic: the same lens and
        spec give the same trials. A Ctrl-C ends the scan: the trial it came in is the last,
        with ``stopped == "interrupted"`` (its result the best design its run evaluated, or None
        when none was); one before any run finished evaluating propagates.
    """
    check_spec(lens, spec, need_continuous=False)
    out: list[SplitTrial] = []
    for k in elements(lens):
        try:
            try:
                l2, s2 = split_design(lens, spec, k)
                res = optimize(l2, s2)
                t = SplitTrial(k, res, stopped=res.stopped)
            except (SpecError, *EVAL_FAILURES) as e:
                t = SplitTrial(k, None, str(e))
            out.append(t)
            if progress is not None:
                progress(t)
        except KeyboardInterrupt:  # between two runs, or before this one evaluated anything
            if not any(o.result is not None for o in out):
                raise  # nothing finished to keep
            if not out or out[-1].surface != k:
                out.append(SplitTrial(k, None, "interrupted", stopped="interrupted"))
            else:
                out[-1] = replace(out[-1], stopped="interrupted")
            break
        if t.stopped:  # Ctrl-C inside the run: no more elements
            break
    return tuple(out)
