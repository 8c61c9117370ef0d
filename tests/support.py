"""Helpers shared by several test modules (not a test module: pytest collects test_*.py only).
Import as ``from support import ...`` (pytest puts tests/ on sys.path)."""

from __future__ import annotations

import contextlib
import importlib
import io
import sys
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path
from types import ModuleType

import pytest

from raytrace import AIR, Aperture, Field, Lens, Surface, fixed_index, model_glass
from raytrace.optimize import DesignSpec, Operand, Variable, read_spec

ROOT = Path(__file__).resolve().parents[1]  # the repository
TEST_DATA = ROOT / "tests" / "data"
CORPUS = TEST_DATA / "corpus"  # published lens files; tests/data/corpus/SOURCES.md names each
BENCHMARKS = ROOT / "benchmarks"


def benchmark_module(name: str, needs: str | None = None) -> ModuleType:
    """The harness module ``benchmarks/<name>.py`` (``referees``, ``optiland_adapter``, ...);
    the calling test is skipped when ``needs``, the referee library it drives, is not
    installed."""
    if needs is not None:
        pytest.importorskip(needs)
    if str(BENCHMARKS) not in sys.path:
        sys.path.insert(0, str(BENCHMARKS))
    return importlib.import_module(name)


def run_cli(argv: list[str]) -> tuple[int, str, str]:
    """``orthoscope`` with ``argv``, in process: (exit status, stdout, stderr)."""
    from orthoscope.cli import main

    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        rc = main(argv)
    return rc, out.getvalue(), err.getvalue()


def interrupt_after(calls: int) -> Callable[[int, int], None]:
    """A ``progress(done, total)`` callback that raises KeyboardInterrupt on its ``calls``-th
    call: a run interrupted after ``calls`` chunks."""
    seen: list[int] = []

    def progress(done: int, total: int) -> None:
        seen.append(done)
        if len(seen) == calls:
            raise KeyboardInterrupt

    return progress


def with_model_glasses(lens: Lens) -> Lens:
    """``lens`` with every catalog glass replaced by the nd/vd model glass of its printed nd and
    vd (how the native lens files give the same glasses)."""
    return replace(
        lens,
        surfaces=tuple(
            replace(s, material=model_glass(s.material.nd, s.material.vd))
            if s.material.kind == "catalog"
            else s
            for s in lens.surfaces
        ),
    )


class Hang(BaseException):
    """A call that ran past its :func:`time_limit` (not an Exception: no reader may swallow it)."""


def time_limit(seconds: float):
    """Raise :class:`Hang` in the block after ``seconds`` (POSIX main thread; no limit
    otherwise): benchmarks/corpus.py's time limit."""
    return benchmark_module("corpus").time_limit(seconds, Hang(f"took more than {seconds} s"))


def read_spec_text(tmp_path: Path, text: str) -> DesignSpec:
    """Read a design spec written as TOML text (into ``tmp_path / "s.toml"``)."""
    p = tmp_path / "s.toml"
    p.write_text(text, encoding="utf-8")
    return read_spec(p)


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


def cooke_split_spec(max_evaluations: int) -> DesignSpec:
    """The Cooke triplet's six curvatures against EFL 50 mm and the least RMS spot on axis: the
    element-splitting problem of the optimizer tests."""
    return replace(
        singlet_spec(),
        start="cooke-triplet-f4",
        variables=tuple(Variable("curvature", k) for k in range(1, 7)),
        operands=(
            Operand("efl", 50.0, 100.0),
            Operand("rms_spot", 0.0, 1000.0, {"field": 0.0, "plane": "best"}),
        ),
        max_evaluations=max_evaluations,
    )


def cooke_multimodal_spec_text(max_evaluations: int, tail: str = "") -> str:
    """The TOML text of the multimodal Cooke problem of the optimizer tests: the six curvatures
    against the EFL and three RMS spots (0, 14 and 20 degrees); ``tail``: more TOML after it (a
    ``[global]`` table)."""
    return (
        f'name = "cooke-multimodal"\nstart = "cooke-triplet-f4"\nmax_evaluations = '
        f"{max_evaluations}\nvariables = [\n"
        + "".join(f'  {{ kind = "curvature", surface = {i} }},\n' for i in range(1, 7))
        + "]\noperands = [\n"
        '  { type = "efl", target = 50.0, weight = 10 },\n'
        + "".join(
            f'  {{ type = "rms_spot", field = {f}, plane = "file", aperture = {a}, '
            "weight = 100 },\n"
            for f, a in ((0, 1.0), (14, 1.0), (20, 0.8))
        )
        + "]\n"
        + tail
    )


#: the sensor of the camera-model tests (px): odd and non-square
CAMERA_W, CAMERA_H = 3001, 1999

#: the OpenCV distortion terms of the camera-model tests, every one nonzero (a model order's
#: subset: ``distortion.camera.OPENCV_ORDERS[n]``)
OPENCV_TERMS = dict(
    k1=-0.08,
    k2=0.02,
    p1=4e-4,
    p2=-6e-4,
    k3=-0.003,
    k4=0.004,
    k5=-0.002,
    k6=0.001,
    s1=3e-4,
    s2=-2e-4,
    s3=-4e-4,
    s4=1e-4,
    tau_x=0.012,
    tau_y=-0.008,
)


def fisheye_camera(fx: float, fy: float):
    """An OpenCV fisheye camera on the CAMERA_W x CAMERA_H sensor: focal lengths ``fx``, ``fy``
    (px), principal point (1523.4, 987.6) px, alpha 0.002, k1..k4 = 0.03, -0.006, 0.001, -1e-4."""
    from distortion.camera import CameraModel

    return CameraModel.create(
        "opencv_fisheye",
        CAMERA_W,
        CAMERA_H,
        fx=fx,
        fy=fy,
        cx=1523.4,
        cy=987.6,
        alpha=0.002,
        k1=0.03,
        k2=-0.006,
        k3=0.001,
        k4=-1e-4,
    )


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


def default_sigint() -> None:
    """``preexec_fn`` of a child that must see Ctrl-C: SIGINT back to its default disposition.
    A test run started as a background job (``cmd &`` in a non-interactive shell) ignores
    SIGINT, and a Python child would inherit that and never raise KeyboardInterrupt."""
    import signal

    signal.signal(signal.SIGINT, signal.SIG_DFL)


@contextlib.contextmanager
def ctrl_c_child(argv: list[str], *, cwd, group: bool = False, **popen):
    """``python -m orthoscope ARGV`` as a child that sees Ctrl-C (its default SIGINT disposition),
    its stderr piped; with ``group``, in a session (process group) of its own. ``popen``: more
    keywords of :class:`subprocess.Popen`. A child still running when the block ends is killed,
    with its group where it has one: a long run left behind would slow the rest."""
    import os
    import signal
    import subprocess

    p = subprocess.Popen(
        [sys.executable, "-m", "orthoscope", *argv],
        cwd=cwd,
        stderr=subprocess.PIPE,
        start_new_session=group,
        preexec_fn=default_sigint,
        **popen,
    )
    try:
        yield p
    finally:
        if p.poll() is None:
            if group:
                os.killpg(p.pid, signal.SIGKILL)
            else:
                p.kill()
            p.wait()


def interrupt_group(argv: list[str], *, cwd, ready: Callable[[str], bool]):
    """A real Ctrl-C in a terminal: ``python -m orthoscope ARGV`` in a session of its own (its
    default SIGINT disposition, unbuffered), its stderr read line by line until ``ready(line)``,
    then SIGINT to the whole process group (the command and any worker processes) and up to 60 s
    to end. Returns (the stderr lines read before the signal, exit status, stdout, the rest of
    stderr); a child still running then is killed with its group."""
    import os
    import signal
    import subprocess

    env = dict(os.environ, PYTHONUNBUFFERED="1")
    before: list[str] = []
    with ctrl_c_child(argv, cwd=cwd, group=True, stdout=subprocess.PIPE, text=True, env=env) as p:
        while True:
            line = p.stderr.readline()
            assert line, "the command ended before it could be interrupted: " + "".join(before)
            before.append(line)
            if ready(line):
                break
        os.killpg(p.pid, signal.SIGINT)
        out, err = p.communicate(timeout=60)
    return before, p.returncode, out, err


def rim_footprints(lens: Lens, par, beams, n_rim: int):
    """The largest real-ray height (mm) on each surface over rim beams: for each ``(field,
    fraction)`` of ``beams`` (field a nominal angle in degrees), ``n_rim`` rays through the rim of
    the paraxial entrance pupil of ``par`` (:func:`raytrace.paraxial.paraxial`) scaled by
    ``fraction`` (the vignetting), from the object point p0 tan(field) for a finite object, as a
    parallel beam for an object at infinity. Every ray must pass (asserted): a clear
    semi-diameter is a footprint of rays that reach the image."""
    import math

    import numpy as np

    from raytrace.trace import STATUS_OK, ray_paths

    th = np.linspace(0.0, 2.0 * np.pi, n_rim, endpoint=False)
    foot = np.zeros(len(lens.surfaces))
    for field, frac in beams:
        px, py = 0.5 * par.epd * frac * np.cos(th), 0.5 * par.epd * frac * np.sin(th)
        t = math.tan(math.radians(field))
        if par.infinite:  # a parallel beam, started well before the first vertex
            d = np.tile(np.array([0.0, t, 1.0]) / math.hypot(1.0, t), (n_rim, 1)).T
            back = -(2.0 * par.epd + 1.0) / d[2]
            start = (px + back * d[0], py + back * d[1], par.z_E0 + back * d[2])
        else:  # from the object point, nominal angle: object height p0 tan(alpha)
            y_obj = par.p0 * t
            d = np.stack([px, py - y_obj, np.full_like(px, par.z_E0 - par.z_object)])
            d /= np.linalg.norm(d, axis=0)
            start = (np.zeros_like(px), np.full_like(px, y_obj), np.full_like(px, par.z_object))
        paths = ray_paths(lens, start, tuple(d))
        assert np.all(paths.status == STATUS_OK), f"{lens.name}: a ray of the {field} deg beam"
        foot = np.maximum(foot, np.hypot(paths.x, paths.y).max(axis=0))
    return foot
