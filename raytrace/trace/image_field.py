"""Fields given in image space (Zemax ``FTYP 2`` / ``FTYP 3``, CODE V ``YIM`` / ``YRI``) turned
into the object-space field that produces them.

* **paraxial image height** h' (OpticStudio "Paraxial Image Height", CODE V ``YIM``): the height
  of the paraxial chief ray in the paraxial image plane. Object at infinity: ``h' = n f tan α``
  (f the effective focal length, n the object-space index), so ``α = atan(h' / (n |f|))``;
  finite object: ``h' = |m0| y`` with m0 the Gaussian magnification (Pestrecov Eq. 5), so
  ``y = h' / |m0|``. A lens that is not centred uses its centred lens ``lens.nominal()``.
* **real image height** h' (OpticStudio "Real Image Height", CODE V ``YRI``): the height of the
  real chief ray (aimed at the centre of the real stop, unclipped) on the lens's own image
  surface (``z = Lens.image_z`` in the image frame, :mod:`raytrace.frames`). Solved for α (or
  the object height y) by a secant iteration started from the paraxial value, bracketed and
  bisected where the secant leaves the bracket, to ``|Δh'| ≤ 1e-12 × max(1 mm, |h'|)``. The
  meridional aim is used for a lens symmetric about its y-z plane, else the 2-D aim with x = 0.

Units: mm, degrees. Both return a :class:`raytrace.lens.Field` whose ``value`` is the
object-space field and whose ``given`` keeps the image-space specification.
"""

from __future__ import annotations

import math

from ..errors import LensError, TraceError
from ..lens import IMAGE_FIELDS, Field, Lens

#: relative tolerance of the real-image-height solve (× max(1 mm, |h'|))
REAL_HEIGHT_TOL = 1e-12
_MAXIT = 100


def paraxial_field(lens: Lens, height: float) -> float:
    """Object-space field (degrees for an object at infinity, mm otherwise) whose paraxial chief
    ray reaches ``height`` mm in the paraxial image plane (module docstring)."""
    from ..paraxial import paraxial

    par = paraxial(lens.nominal())
    h = abs(float(height))
    if par.infinite:
        return math.degrees(math.atan(h / (abs(par.n_object) * abs(par.efl))))
    if par.m0 == 0.0 or not math.isfinite(par.m0):
        raise LensError(f"{lens.name}: the Gaussian magnification is {par.m0}: no object height")
    return h / abs(par.m0)


def _symmetric_in_x(lens: Lens) -> bool:
    """True when the lens is symmetric about its y-z plane (decenters in y, tilts about x)."""
    from ..frames import Placement

    def ok(p) -> bool:
        if not isinstance(p, Placement):
            return True
        return p.decenter[0] == 0.0 and p.tilt[1] == 0.0 and p.tilt[2] == 0.0

    if not ok(lens.image_placement):
        return False
    return all(
        ok(s.placement) and ok(s.after) and (s.aperture is None or s.aperture.x0 == 0.0)
        for s in lens.surfaces
    )


def real_image_height(lens: Lens, field: float, kind: str) -> float:
    """Height (mm, y in the image frame) of the real chief ray of the meridional ``field``
    (degrees for ``kind="angle"``, mm for ``"height"``) on the lens's image surface; NaN when it
    cannot be traced."""
    import numpy as np

    from .chief import aim
    from .chief2d import aim_2d

    od = lens.object_distance
    if _symmetric_in_x(lens):
        cr = aim(lens, np.array([float(field)]), kind, od, clip=False)
        return float(cr.heights_at(lens.image_z)[0])
    cr = aim_2d(lens, np.array([0.0]), np.array([float(field)]), kind, od, clip=False)
    return float(cr.positions_at(lens.image_z)[0, 1])


def real_field(lens: Lens, height: float) -> float:
    """Object-space field (degrees or mm, ≥ 0) whose real chief ray reaches ``|height|`` mm on
    the image surface (module docstring; an inverted image is measured as −y)."""
    kind = "angle" if math.isinf(lens.object_distance) else "height"
    target = abs(float(height))
    tol = REAL_HEIGHT_TOL * max(1.0, target)
    if target == 0.0:
        return 0.0
    f0 = paraxial_field(lens, target)
    h0 = real_image_height(lens, f0, kind)
    if not math.isfinite(h0):
        raise TraceError(f"{lens.name}: the chief ray of the paraxial field {f0:.6g} fails")
    sign = 1.0 if h0 >= 0.0 else -1.0

    def g(f: float) -> float:
        return sign * real_image_height(lens, f, kind) - target

    a, ga = f0, sign * h0 - target
    b = f0 * (1.0 + 1e-3)
    gb = g(b)
    lo = hi = None
    for _ in range(_MAXIT):
        if not math.isfinite(gb):
            b = 0.5 * (a + b)
            gb = g(b)
            continue
        if abs(gb) <= tol:
            return b
        for f, gf in ((a, ga), (b, gb)):
            if gf < 0.0 and (lo is None or f > lo):
                lo = f
            if gf > 0.0 and (hi is None or f < hi):
                hi = f
        fn = b - gb * (b - a) / (gb - ga) if gb != ga else b * (1.0 + 1e-3)
        if lo is not None and hi is not None and not (min(lo, hi) < fn < max(lo, hi)):
            fn = 0.5 * (lo + hi)
        if kind == "angle":
            fn = min(max(fn, 0.0), 89.999999)
        a, ga, b, gb = b, gb, fn, g(fn)
    raise TraceError(
        f"{lens.name}: no field reaches the real image height {height:g} mm "
        f"(best {b:.6g} {'deg' if kind == 'angle' else 'mm'}, off by {gb:.3g} mm)"
    )


def field_for_image_height(lens: Lens, height: float, kind: str) -> Field:
    """The object-space :class:`Field` of an image-space field specification ``kind``
    (``"paraxial_image_height"`` or ``"real_image_height"``) of ``height`` mm, with ``given``
    set (module docstring)."""
    if kind not in IMAGE_FIELDS:
        raise ValueError(f"kind must be one of {IMAGE_FIELDS}, got {kind!r}")
    h = float(height)
    if kind == "paraxial_image_height":
        value = paraxial_field(lens, h)
    else:
        value = real_field(lens, h)
    fk = "angle" if math.isinf(lens.object_distance) else "height"
    if fk == "angle" and not value < 90.0:
        raise LensError(f"{lens.name}: the image height {h:g} mm needs a field beyond 90 degrees")
    return Field(fk, float(value), (), (kind, h))
