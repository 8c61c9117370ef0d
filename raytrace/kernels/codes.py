"""Codes shared by the numba kernels and the Python layer (no numba import here).

Status codes (one per ray; every ray gets one, a failed ray has NaN coordinates and the 1-based
number of the surface where it failed): ``STATUS_OK`` 0, ``STATUS_MISSED`` 1 (the ray misses the
surface or meets only its far branch, or travels away from it), ``STATUS_TIR`` 2 (total internal
reflection), ``STATUS_CLIPPED`` 3 (outside the semi-diameter, when clipping is on),
``STATUS_AIM_FAILED`` 4 (chief-ray aiming did not converge).

Surface kind codes (:func:`raytrace.packing.pack`): ``KIND_PLANE`` 0, ``KIND_QUADRIC`` 1 (sphere
or conic, closed-form intersection), ``KIND_ASPHERE`` 2 (even asphere, Newton iteration).
"""

STATUS_OK = 0
STATUS_MISSED = 1
STATUS_TIR = 2
STATUS_CLIPPED = 3
STATUS_AIM_FAILED = 4

#: status code -> the name used in tables and JSON
STATUS_NAMES = {
    STATUS_OK: "ok",
    STATUS_MISSED: "missed",
    STATUS_TIR: "tir",
    STATUS_CLIPPED: "clipped",
    STATUS_AIM_FAILED: "aim_failed",
}

KIND_PLANE = 0
KIND_QUADRIC = 1
KIND_ASPHERE = 2
