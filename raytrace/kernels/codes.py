"""Codes shared by the numba kernels and the Python layer (no numba import here).

Status codes (one per ray; every ray gets one, a failed ray has NaN coordinates and the 1-based
number of the surface where it failed): ``STATUS_OK`` 0, ``STATUS_MISSED`` 1 (the ray misses the
surface or meets only its far branch, or travels away from it), ``STATUS_TIR`` 2 (total internal
reflection), ``STATUS_CLIPPED`` 3 (outside the semi-diameter, when clipping is on),
``STATUS_AIM_FAILED`` 4 (chief-ray aiming did not converge), ``STATUS_BACKWARD`` 5 (the ray
would have to travel against its direction to reach the surface: the surface lies behind the
point where the ray met the previous one, so the two overlap; see :mod:`.surface`).

Surface kind codes (:func:`raytrace.packing.pack`): ``KIND_PLANE`` 0, ``KIND_QUADRIC`` 1 (sphere
or conic, closed-form intersection), ``KIND_ASPHERE`` 2 (even asphere, Newton iteration),
``KIND_QBFS`` 4 and ``KIND_QCON`` 5 (Forbes Q-type aspheres, :mod:`raytrace.qtype`; Newton
iteration, traced by the scalar :func:`raytrace.kernels.surface.surface_step` only: packing
flags them ``F_SCALAR``). 3 is the tolerancing kernels' irregular surface
(:data:`raytrace.kernels.instances.KIND_IRREGULAR`).
"""

STATUS_OK = 0
STATUS_MISSED = 1
STATUS_TIR = 2
STATUS_CLIPPED = 3
STATUS_AIM_FAILED = 4
STATUS_BACKWARD = 5

#: status code -> the name used in tables and JSON
STATUS_NAMES = {
    STATUS_OK: "ok",
    STATUS_MISSED: "missed",
    STATUS_TIR: "tir",
    STATUS_CLIPPED: "clipped",
    STATUS_AIM_FAILED: "aim_failed",
    STATUS_BACKWARD: "backward",
}

#: status code -> what it means for a person, with the fix (``{surface}``: the 1-based surface)
STATUS_HELP = {
    STATUS_OK: "traced",
    STATUS_MISSED: "ray misses surface {surface} (or meets only its far branch)",
    STATUS_TIR: "total internal reflection at surface {surface}",
    STATUS_CLIPPED: "ray clipped by the semi-diameter or clear aperture of surface {surface}",
    STATUS_AIM_FAILED: "chief-ray aiming did not converge",
    STATUS_BACKWARD: (
        "ray travels backwards to surface {surface}: surfaces overlap; "
        "check thicknesses / semi-diameters"
    ),
}


def status_message(status: int, surface: int = 0) -> str:
    """One line for a ray's status: what happened and where (``surface`` 1-based, 0 unknown).

    >>> status_message(STATUS_BACKWARD, 3)
    'ray travels backwards to surface 3: surfaces overlap; check thicknesses / semi-diameters'
    """
    text = STATUS_HELP.get(int(status), f"status {int(status)}")
    where = str(int(surface)) if surface else "?"
    return text.format(surface=where)


KIND_PLANE = 0
KIND_QUADRIC = 1
KIND_ASPHERE = 2
KIND_QBFS = 4
KIND_QCON = 5

# ---- per-surface placement table ``geo`` (:func:`raytrace.packing.pack`, float64, one row per
# packed surface, NGEO columns; :mod:`raytrace.frames` for the frames). Column offsets:
G_ZV = 0  #: nominal vertex z (mm): the vertex is at (0, 0, zv) in the surface's axis frame
G_FLAGS = 1  #: surface flags (F_* below, as a float)
G_REL = 2  #: 9 values: M (row-major) of p_j = M p_prev + t, from the previous traced axis frame
G_RELT = 11  #: 3 values: t
G_ABS = 14  #: 9 values: rotation of the axis frame in global coordinates (row-major)
G_ABST = 23  #: 3 values: origin of the axis frame in global coordinates
G_AP = 26  #: 5 values: clear-aperture shape code (1 circle, 2 rectangle, 3 ellipse), hx, hy, x0, y0
G_LENS = 31  #: lens flags (L_* below), row 0 only
NGEO = 32

F_FRAME = 1  #: transform the ray into this surface's axis frame first
F_MIRROR = 2  #: reflect instead of refracting
F_SKIP = 4  #: not traced (a coordinate break, or the image-frame pseudo-surface at the end)
F_APERTURE = 8  #: clip with the clear aperture of columns G_AP..G_AP+4 too
F_GENERAL = 16  #: rays may meet the surface travelling toward -z (mirrors, tilts)
#: traced ray by ray by :func:`raytrace.kernels.surface.surface_step` in the bulk trace too (a
#: surface kind without a vectorised pass: the Q-type aspheres)
F_SCALAR = 32

L_SYMMETRIC = 1  #: rotationally symmetric lens: a negative meridional field mirrors a positive one
L_COAXIAL = 2  #: no surface has a flag: the kernels run the coaxial code only
