"""Map an orthoscope :class:`raytrace.lens.Lens` onto an optiland ``Optic`` (optional dependency).

Conventions mapped (optiland 0.6):
- surfaces: optiland index 0 is the object surface, 1..n our surfaces 1..n, n+1 the image surface;
  the first lens vertex sits at z = 0 in both programs, light toward +z;
- radius = 1/c ("inf" for a plane), conic k as is; even aspheres: optiland's
  ``coefficients[i]`` multiplies r^(2i+2), ours ``asph[m]`` multiplies r^(2m+4), so
  optiland coefficients = [0, A4, A6, ...];
- glass: :class:`optiland.materials.IdealMaterial` with OUR index at the trace wavelength
  (fixed index, no dispersion model), so both programs refract with the same numbers;
- asphere intersection tolerance: optiland's default (1e-6 mm on the sag residual) is tightened
  to ``NEWTON_TOL`` so that both programs solve the same intersection;
- semi-diameters: not transferred (the benchmark lenses are unclipped, and real rays are traced
  unclipped in both); aperture: EPD from our paraxial result; field: angle, max from the lens.

``import optiland`` costs several seconds; everything is imported lazily.
"""

from __future__ import annotations

import math

import numpy as np

NEWTON_TOL = 1e-15  # mm, optiland asphere intersection tolerance used here (default 1e-6)


def available() -> tuple[bool, str]:
    """(True, version) when optiland imports, else (False, reason)."""
    try:
        import optiland  # noqa: F401
    except Exception as e:  # noqa: BLE001 - any import failure means "absent"
        return False, f"{type(e).__name__}: {e}"
    from importlib.metadata import PackageNotFoundError, version

    try:
        return True, version("optiland")
    except PackageNotFoundError:
        return True, "unknown"


def surface_group(op):
    """The optic's ``SurfaceGroup``: ``op.surfaces`` where it is one, else ``op.surface_group``
    (the older name, deprecated in optiland 0.6)."""
    group = getattr(op, "surfaces", None)
    return group if hasattr(group, "trace") else op.surface_group


def build_optic(lens, wavelength_nm: float | None = None):
    """optiland ``Optic`` equivalent to ``lens`` at ``wavelength_nm`` (default the lens's)."""
    from optiland.materials import IdealMaterial
    from optiland.optic import Optic

    from raytrace.packing import pack
    from raytrace.paraxial import paraxial

    wl = lens.wavelength if wavelength_nm is None else wavelength_nm
    p = pack(lens, wl)
    op = Optic()
    # optiland deprecates Optic.add_surface / add_field / set_field_type / add_wavelength for
    # op.surfaces.add / op.fields.add / op.fields.set_type / op.wavelengths.add (the old names
    # warn, and go in 0.7); the old ones serve older versions
    group, fields = surface_group(op), getattr(op, "fields", None)
    add_surface = group.add if hasattr(group, "add") else op.add_surface
    new_fields = hasattr(fields, "add") and hasattr(fields, "set_type")
    add_field = fields.add if new_fields else op.add_field
    set_field_type = fields.set_type if new_fields else op.set_field_type
    add_wavelength = getattr(getattr(op, "wavelengths", None), "add", op.add_wavelength)
    add_surface(index=0, thickness=np.inf if not math.isfinite(lens.object_distance)
                else lens.object_distance)  # fmt: skip
    ns = p.n_surfaces
    for j, s in enumerate(lens.surfaces):
        radius = np.inf if s.curvature == 0.0 else 1.0 / s.curvature
        n_after = float(p.n_out[j])
        mat = "air" if n_after == 1.0 else IdealMaterial(n=n_after)
        kw = dict(
            index=j + 1,
            radius=radius,
            thickness=float(s.thickness) if j < ns - 1 else float(p.z_image - p.zv[-1]),
            material=mat,
            is_stop=bool(s.stop),
            conic=float(s.conic),
        )
        if any(a != 0.0 for a in s.aspheric):
            kw["surface_type"] = "even_asphere"
            kw["coefficients"] = [0.0, *[float(a) for a in s.aspheric]]
        add_surface(**kw)
    add_surface(index=ns + 1)
    # optiland's even-asphere Newton stops at |sag residual| < tol, 1e-6 mm by default: image
    # heights then differ by ~5e-7 mm. Tighten it so both programs solve the same intersection.
    for s in group.surfaces:
        if hasattr(s.geometry, "tol"):
            s.geometry.tol = NEWTON_TOL
    par = paraxial(lens, lens.object_distance, wl)
    op.set_aperture(aperture_type="EPD", value=float(par.epd))
    set_field_type(field_type="angle")
    add_field(y=0.0)
    add_field(y=float(lens.field.value) if lens.field.kind == "angle" else 20.0)
    add_wavelength(value=wl / 1000.0, is_primary=True)
    return op


def trace_bulk(op, x, y, z, L, M, N, wavelength_nm: float):
    """Trace explicit rays (ours: start anywhere before the first vertex) through every surface of
    ``op`` up to its image surface, without per-surface records. Returns (x, y) on the image."""
    from optiland.rays import RealRays

    n = x.shape[0]
    rays = RealRays(x.copy(), y.copy(), z.copy(), L.copy(), M.copy(), N.copy(),
                    np.ones(n), np.full(n, wavelength_nm / 1000.0))  # fmt: skip
    surface_group(op).trace(rays, skip=1, record=False)
    return np.asarray(rays.x), np.asarray(rays.y)


def distortion_curve(op, num_points: int):
    """optiland's Distortion analysis (primary wavelength, f-tan) — the timed comparison."""
    from optiland.analysis import Distortion

    return Distortion(op, wavelengths="primary", num_points=num_points)
