"""Compensators: the image plane of each perturbed instance (raytrace.tolerance.spec names them;
Pestrecov 1958 §V: where the image plane lies changes the distortion, so the choice is part of
the spec).

* ``"paraxial-refocus"``: the paraxial image of the object by the instance's centred part
  (:func:`raytrace.tolerance.paraxial_batch`; decenters and tilts move focus in second order);
* ``"best-focus"``: the plane of least RMS spot radius (about the spot's centroid) of a bundle
  of real rays from the axial object point filling the nominal entrance pupil (hexapolar rings);
  with ray positions ``a_r + z s_r`` (s the slopes dx/dz, dy/dz) the RMS is least at
  ``z* = −Σ (a_r − ā)·(s_r − s̄) / Σ |s_r − s̄|²``, exactly, per instance;
* ``"fixed-sensor"``: nothing is adjusted: the surface after the last thickness, which moves with
  the thickness changes (OpticStudio with no compensator).

All planes are absolute z in the image frame (mm from the nominal first vertex).
"""

from __future__ import annotations

import math

import numpy as np

from raytrace.kernels.codes import STATUS_OK
from raytrace.tolerance import InstanceArrays, ParaxialBatch, trace_instances


def pupil_bundle(par, object_distance: float, rings: int) -> np.ndarray:
    """Start rays (6, R) (x, y, z, L, M, N) from the axial object point through hexapolar rings
    of the paraxial entrance pupil ``par`` (a :class:`raytrace.paraxial.ParaxialResult` of the
    nominal lens): the centre plus 6k points on ring k = 1..``rings`` at radius k/rings · EPD/2.
    For an object at infinity the rays are parallel to the axis, starting on z = 0."""
    xs, ys = [0.0], [0.0]
    for k in range(1, rings + 1):
        r = 0.5 * par.epd * k / rings
        phi = 2.0 * np.pi * np.arange(6 * k) / (6 * k)
        xs += list(r * np.cos(phi))
        ys += list(r * np.sin(phi))
    x = np.array(xs)
    y = np.array(ys)
    R = x.size
    out = np.zeros((6, R))
    if math.isinf(object_distance):
        out[0], out[1] = x, y
        out[5] = 1.0
    else:
        z0 = -float(object_distance)
        dz = par.z_E0 - z0
        norm = np.sqrt(x * x + y * y + dz * dz)
        out[2] = z0
        out[3], out[4], out[5] = x / norm, y / norm, dz / norm
    return out


def best_focus_planes(last: np.ndarray, status: np.ndarray) -> np.ndarray:
    """The plane of least RMS spot radius per instance (module docstring) from final segments
    ``last`` (I, 6, R) and ``status`` (I, R); NaN where fewer than 3 rays arrive."""
    good = status == STATUS_OK
    w = good.astype(float)
    n = w.sum(axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        sx = np.where(good, last[:, 3] / last[:, 5], 0.0)
        sy = np.where(good, last[:, 4] / last[:, 5], 0.0)
        ax = np.where(good, last[:, 0] - last[:, 2] * sx, 0.0)
        ay = np.where(good, last[:, 1] - last[:, 2] * sy, 0.0)
        mx = lambda v: (v.sum(axis=1) / n)[:, None]  # noqa: E731
        axc, ayc = (ax - mx(ax)) * w, (ay - mx(ay)) * w
        sxc, syc = (sx - mx(sx)) * w, (sy - mx(sy)) * w
        z = -(axc * sxc + ayc * syc).sum(axis=1) / (sxc * sxc + syc * syc).sum(axis=1)
    return np.where(n >= 3, z, np.nan)


def image_planes(
    kind: str,
    arrays: InstanceArrays,
    par: ParaxialBatch,
    bundle: np.ndarray | None,
    *,
    parallel: bool = True,
) -> np.ndarray:
    """The image plane z (I,) of every instance for the compensator ``kind`` (module
    docstring); ``bundle`` the start rays of :func:`pupil_bundle` (best focus only)."""
    if kind == "paraxial-refocus":
        return np.array(par.z_image, dtype=float)
    if kind == "fixed-sensor":
        return np.array(arrays.image_z_stack, dtype=float)
    if kind == "best-focus":
        last, status = trace_instances(arrays, bundle, parallel=parallel)
        return best_focus_planes(last, status)
    raise ValueError(f"unknown compensator {kind!r}")
