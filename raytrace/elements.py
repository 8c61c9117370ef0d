"""Editing a lens element by element: split an element in two, or insert a new element into an
air space. Pure functions returning a new :class:`~raytrace.lens.Lens`; the optimizer's
``--split`` / ``--insert`` (:mod:`raytrace.optimize.elements`) renumber a design spec to match.

Surfaces are numbered from 1 as everywhere (``Lens.surfaces[k - 1]``); an *element* is a surface
``k`` followed by glass (the medium after it is not air) and surface ``k + 1`` with air after it.
Both edits add two surfaces; ``surface_map`` tells where an old surface number lands.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Callable
from dataclasses import replace

from .errors import LensError
from .lens import Lens, Surface
from .materials import AIR, Material
from .units import number_problem

#: the air gap (mm) between the two halves of a split element, and around an inserted one
DEFAULT_GAP = 0.1


def surface_map(surface: int) -> Callable[[int], int]:
    """Where an old surface number lands after two surfaces are added behind ``surface``
    (:func:`split_element` of the element starting at ``surface``; :func:`insert_element`
    after ``surface``): numbers up to ``surface`` stay, the later ones move by two."""
    return lambda j: j if j <= surface else j + 2


def elements(lens: Lens) -> tuple[int, ...]:
    """The first surfaces (1-based) of the lens's single elements in air that
    :func:`split_element` accepts: air in front, glass after the surface, air after the next,
    both surfaces centred and refracting."""
    out = []
    for k in range(1, lens.n_surfaces):
        try:
            _element(lens, k)
        except LensError:
            continue
        out.append(k)
    return tuple(out)


def _surface_number(lens: Lens, surface, what: str) -> int:
    if isinstance(surface, bool) or not isinstance(surface, int):
        raise LensError(
            f"{lens.name}: {what} must be a surface number (an integer), got {surface!r}"
        )
    return surface


def _element(lens: Lens, surface: int) -> tuple[Surface, Surface]:
    n = lens.n_surfaces
    surface = _surface_number(lens, surface, "the element to split")
    if not 1 <= surface < n:
        raise LensError(f"{lens.name}: no element starts at surface {surface} (1..{n - 1})")
    front, back = lens.surfaces[surface - 1], lens.surfaces[surface]
    before = lens.object_material if surface == 1 else lens.surfaces[surface - 2].material
    if not before.is_air or front.material.is_air or not back.material.is_air:
        raise LensError(
            f"{lens.name}: surfaces {surface}-{surface + 1} are not a single element in air "
            "(air before the first, glass after it, air after the second; a cemented group "
            "cannot be split); name an element's first surface"
        )
    for s in (front, back):
        if s.is_placed or s.mirror or s.coordinate_break:
            raise LensError(
                f"{lens.name}: surfaces {surface}-{surface + 1}: only a centred refracting "
                "element can be split"
            )
    return front, back


def split_element(lens: Lens, surface: int, *, gap: float = DEFAULT_GAP) -> Lens:
    """Split the element whose first surface is ``surface`` into two of the same glass.

    The element is cut along a sphere of the mean curvature c_m = (c1 + c2)/2 and the halves
    moved ``gap`` mm apart: the first half keeps the front surface and gets c_m behind it, the
    second gets c_m in front and keeps the back surface, each half ``t/2`` thick. For a thin
    element each half then has half the power, (n − 1)(c1 − c2)/2, and the air meniscus between
    them (equal curvatures) has next to none, so the split lens is close to the original: a
    start for an optimizer, which then uses the new surfaces' freedom. The new surfaces are
    spherical (the outer ones keep their conic / aspheric terms) and get the larger
    semi-diameter of the element's two; a stop on either surface stays where it was.

    Parameters
    ----------
    lens : Lens
    surface : int
        The element's first surface (1-based): glass after it, air after the next.
    gap : float
        Air between the halves, mm (> 0).

    Returns
    -------
    Lens
        Two more surfaces; old surface ``j`` is ``surface_map(surface)(j)``.
    """
    if not (isinstance(gap, (int, float)) and math.isfinite(gap) and gap > 0):
        raise LensError(f"{lens.name}: the gap of a split must be a positive length (mm)")
    front, back = _element(lens, surface)
    c_mid = 0.5 * (front.curvature + back.curvature)
    half = 0.5 * front.thickness
    sd = max(front.semi_diameter, back.semi_diameter)
    first = replace(front, thickness=half, line=None)
    cut1 = Surface(c_mid, gap, AIR, semi_diameter=sd)
    cut2 = Surface(c_mid, half, front.material, semi_diameter=sd)
    s = lens.surfaces
    new = s[: surface - 1] + (first, cut1, cut2) + s[surface:]
    note = (
        f"element {surface}-{surface + 1} split in two (cut at c = {c_mid:.6g}/mm, gap {gap:g} mm)"
    )
    return _resolved(replace(lens, surfaces=new, notes=_with_note(lens.notes, note), path=None))


def _kind(value) -> str:
    """What a value that ``float()`` reads but that is no number is, for a message."""
    return "text, not a number" if isinstance(value, str) else "not a number"


def insert_element(
    lens: Lens,
    after: int,
    material: Material,
    *,
    thickness: float = 2.0,
    gap: float | None = None,
) -> Lens:
    """Insert a plane-parallel plate of ``material`` into the air space after surface ``after``.

    The plate (zero power: two flat surfaces, ``thickness`` mm) sits in the middle of the air
    space, or ``gap`` mm behind surface ``after``; the air behind it is shortened by ``gap +
    thickness``, so every later vertex stays where it was (an image plane that was a Gaussian
    solve is solved again: the plate moves the focus by t (1 − 1/n)). Its semi-diameter is the
    larger of its neighbours'. An optimizer then bends it into a lens.

    Parameters
    ----------
    lens : Lens
    after : int
        The surface (1-based) with air after it; the image solve's last space counts.
    material : Material
        The new element's glass.
    thickness : float
        Centre thickness of the plate, mm (> 0).
    gap : float, optional
        Air in front of the plate, mm (> 0); default: the middle of the space. The air space
        must be longer than ``gap + thickness``.

    Returns
    -------
    Lens
        Two more surfaces; old surface ``j`` is ``surface_map(after)(j)``.
    """
    n = lens.n_surfaces
    after = _surface_number(lens, after, "the surface to insert after")
    if not 1 <= after <= n:
        raise LensError(f"{lens.name}: no surface {after} to insert after (1..{n})")
    s0 = lens.surfaces[after - 1]
    if s0.mirror or s0.coordinate_break:
        what = "a mirror" if s0.mirror else "a coordinate break"
        raise LensError(
            f"{lens.name}: surface {after} is {what}; insert the element after a refracting "
            "surface with air behind it"
        )
    if not s0.material.is_air:
        raise LensError(f"{lens.name}: the space after surface {after} is not air")
    if material.is_air:
        raise LensError(f"{lens.name}: an inserted element needs a glass, not air")
    for v, what in ((thickness, "thickness"), (gap, "gap")):
        if v is not None and not (isinstance(v, numbers.Real) and not isinstance(v, bool)):
            raise LensError(
                f"{lens.name}: the inserted element's {what} must be a length in mm (a positive "
                f"number), got {v!r} ({number_problem(v) or _kind(v)})"
            )
    if gap is None:
        gap = 0.5 * (s0.thickness - thickness)
    for v, what in ((thickness, "thickness"), (gap, "gap")):
        if not (math.isfinite(v) and v > 0):  # real numbers (checked above), numpy's too
            raise LensError(
                f"{lens.name}: the inserted element's {what} must be positive (mm); the air "
                f"space after surface {after} is {s0.thickness:g} mm"
            )
    rest = s0.thickness - gap - thickness
    if not rest > 0.0:
        raise LensError(
            f"{lens.name}: the air space after surface {after} is {s0.thickness:g} mm: too short "
            f"for an element {thickness:g} mm thick {gap:g} mm behind the surface"
        )
    s = lens.surfaces
    sd = max(s0.semi_diameter, s[after].semi_diameter if after < n else s0.semi_diameter)
    plate1 = Surface(0.0, thickness, material, semi_diameter=sd)
    plate2 = Surface(0.0, rest, AIR, semi_diameter=sd)
    new = s[: after - 1] + (replace(s0, thickness=gap, line=None), plate1, plate2) + s[after:]
    note = f"element of {material.name or 'glass'} inserted after surface {after}"
    return _resolved(replace(lens, surfaces=new, notes=_with_note(lens.notes, note), path=None))


def _resolved(lens: Lens) -> Lens:
    """An image plane that was a Gaussian solve is solved again for the edited lens."""
    if lens.image_solve != "gaussian":
        return lens
    from .paraxial import gaussian_solved

    return gaussian_solved(lens)


def _with_note(notes: str, note: str) -> str:
    return f"{notes} {note}." if notes else f"{note[0].upper()}{note[1:]}."
