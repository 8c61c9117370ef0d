"""Helpers shared by several test modules (not a test module: pytest collects test_*.py only).
Import as ``from support import ...`` (pytest puts tests/ on sys.path)."""

from __future__ import annotations

import signal
from contextlib import contextmanager

from raytrace import AIR, Aperture, Field, Lens, Surface, fixed_index
from raytrace.optimize import DesignSpec, Operand, Variable


class Hang(BaseException):
    """A call that ran past its :func:`time_limit` (not an Exception: no reader may swallow it)."""


@contextmanager
def time_limit(seconds: float):
    """Raise :class:`Hang` in the block after ``seconds`` (POSIX main thread; no limit
    otherwise)."""
    if not hasattr(signal, "setitimer"):
        yield
        return

    def handler(signum, frame):
        raise Hang(f"took more than {seconds} s")

    try:
        old = signal.signal(signal.SIGALRM, handler)
    except ValueError:  # not in the main thread
        yield
        return
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)


def singlet(n=1.5, f=100.0, t=0.3, fnum=20.0) -> Lens:
    """An equiconvex thin singlet of index ``n`` and focal length ≈ ``f`` mm (the last thickness
    ``f``), stop on its first surface, F/``fnum``, 1° field: the optimizer tests' start."""
    c = 1.0 / (2.0 * (n - 1.0) * f)  # equiconvex start
    return Lens(
        "singlet",
        (Surface(c, t, fixed_index(n), stop=True), Surface(-c, f, AIR)),
        Aperture("fnumber", fnum),
        Field("angle", 1.0),
        image_solve=None,
    )


def singlet_spec(**settings) -> DesignSpec:
    """Bend :func:`singlet` (both curvatures free) for the least RMS spot on axis at EFL 100 mm
    (the Coddington-shape problem); ``settings``: further DesignSpec fields (``search=``)."""
    return DesignSpec(
        start="(built in test)",
        variables=(Variable("curvature", 1), Variable("curvature", 2)),
        operands=(
            Operand("efl", 100.0, 100.0),
            Operand("rms_spot", 0.0, 1000.0, {"field": 0.0, "plane": "best"}),
        ),
        max_evaluations=400,
        **settings,
    )


#: the sensor of the camera-model tests (px): odd and non-square
CAMERA_W, CAMERA_H = 3001, 1999


def metashape_camera():
    """A Metashape camera on the CAMERA_W x CAMERA_H sensor, every term nonzero."""
    from distortion.camera import CameraModel

    return CameraModel.create(
        "metashape",
        CAMERA_W,
        CAMERA_H,
        f=3200.0,
        cx=23.4,
        cy=-11.7,
        b1=12.0,
        b2=1.5,
        k1=-0.08,
        k2=0.02,
        k3=-0.003,
        k4=2e-4,
        p1=-6e-4,
        p2=4e-4,
        p3=0.1,
        p4=-0.1,
    )


def australis_camera():
    """An Australis (Fraser 1997) camera on the CAMERA_W x CAMERA_H sensor, every term nonzero."""
    from distortion.camera import CameraModel

    return CameraModel.create(
        "australis",
        CAMERA_W,
        CAMERA_H,
        pixel_size_mm=(0.0078, 0.0079),
        c=25.0,
        xp=0.05,
        yp=-0.04,
        K1=8e-5,
        K2=-6e-8,
        K3=7e-11,
        P1=1e-5,
        P2=-2e-5,
        b1=1e-4,
        b2=-5e-5,
    )
