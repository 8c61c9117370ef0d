"""Splitting or adding an element in a design: the lens edit (:mod:`raytrace.elements`) together
with the spec renumbered to match, so a run can go on with one element more.

Every surface number of the spec (variables, pick-ups and sources, operands' ``surface`` and
``last``) is carried to the edited lens by :func:`raytrace.elements.surface_map`, and the new
surfaces get variables like their neighbours': a split element's halves both keep the element's
curvature, thickness and glass freedom (the cut surfaces are free within the union of the
element's curvature bounds, the gap a thickness variable above the spec's smallest air
bound); an inserted element's two curvatures are free and its thickness is a variable above the
spec's smallest glass bound.
"""

from __future__ import annotations

import math
from dataclasses import replace

from ..elements import DEFAULT_GAP, insert_element, split_element, surface_map
from ..lens import Lens
from ..materials import Material
from .spec import DesignSpec, Operand, Variable


def _renumbered(spec: DesignSpec, where) -> DesignSpec:
    def op(o: Operand) -> Operand:
        p = dict(o.params)
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


def _smallest_bound(lens: Lens, spec: DesignSpec, glass: bool, default: float) -> float:
    """The smallest lower bound of the spec's thickness variables on glass (or air) spaces."""
    lows = [
        v.lower
        for v in spec.variables
        if v.kind == "thickness"
        and v.surface < lens.n_surfaces
        and lens.surfaces[v.surface - 1].material.is_air != glass
        and math.isfinite(v.lower)
    ]
    return min(lows) if lows else default


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
        Air between the halves, mm.

    Returns
    -------
    (Lens, DesignSpec)
        The lens with two surfaces more and the spec for it: the element's variables of
        curvature, thickness, index / Abbe number and glass also on the new half (surface + 2,
        the same bounds), the two cut surfaces free in curvature (within the union of the
        element's curvature bounds) when either element surface was, the gap a thickness
        variable (from the spec's smallest air bound, else ``gap``) when the element's
        thickness was. The element's centre and edge thickness operands are repeated on the
        second half, and the gap gets the spec's smallest air edge rule (``min``) at the
        element's edge heights.
    """
    new_lens = split_element(lens, surface, gap=gap)
    k = surface
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
                air_low = _smallest_bound(lens, spec, glass=False, default=gap)
                added.append(Variable("thickness", k + 1, min(air_low, gap), math.inf))
    # the element's own rules hold for both halves: its centre / edge thickness operands are
    # repeated on the second half, and the gap gets the spec's air edge rule at the same height
    rules = [
        o
        for o in out.operands
        if o.type in ("center_thickness", "edge_thickness") and o.params["surface"] == k
    ]
    air_edges = [
        o.params["min"]
        for o in spec.operands
        if o.type == "edge_thickness"
        and "min" in o.params
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
        out, variables=out.variables + tuple(added), operands=out.operands + tuple(extra)
    )


def insert_design(
    lens: Lens,
    spec: DesignSpec,
    after: int,
    material: Material,
    *,
    thickness: float = 2.0,
    gap: float = DEFAULT_GAP,
) -> tuple[Lens, DesignSpec]:
    """Insert a plate of ``material`` after surface ``after``
    (:func:`raytrace.elements.insert_element`) and renumber ``spec`` to match: the new
    element's two curvatures free, its thickness a variable from the spec's smallest glass
    bound (else ``thickness``); when the air space it was put in was a thickness variable, the
    air behind the new element takes that variable (its bounds) and the gap in front of it one
    from the spec's smallest air bound (else ``gap``)."""
    new_lens = insert_element(lens, after, material, thickness=thickness, gap=gap)
    out = _renumbered(spec, surface_map(after))
    a = after
    glass_low = _smallest_bound(lens, spec, glass=True, default=thickness)
    air_low = _smallest_bound(lens, spec, glass=False, default=gap)
    keep, added = (
        [],
        [
            Variable("curvature", a + 1),
            Variable("curvature", a + 2),
            Variable("thickness", a + 1, min(glass_low, thickness), math.inf),
        ],
    )
    for v in out.variables:
        if v.kind == "thickness" and v.surface == a:  # the space now behind the new element
            added += [replace(v, surface=a + 2), Variable("thickness", a, min(air_low, gap))]
        else:
            keep.append(v)
    return new_lens, replace(out, variables=tuple(keep) + tuple(added))
