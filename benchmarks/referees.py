"""Geometry referees: real chief rays of decentered, tilted and folded lenses against ray-optics
and optiland (issue 15, "Done when": ≤ 1e-9 mm on a 2-D field grid).

    python benchmarks/referees.py                 # every corpus file with placements or mirrors
    python benchmarks/referees.py FILE [FILE ...] # these files
    python benchmarks/referees.py --json          # machine-readable

For each lens file, orthoscope reads it and aims real chief rays on a 3 × 3 grid of field
angles (object at infinity: direction tangents tan αx, tan αy) or object points (finite object),
unclipped, with :func:`raytrace.trace.chief2d.chief_rays_2d`; the chief rays' points on the
lens's image surface (x, y in the image surface's own frame) are compared with the same rays of
each referee. The referees aim their own chief rays: a 2-D root solve (scipy ``root``, then a
few Newton steps with finite differences) of the ray's point on the stop surface, in the stop
surface's own frame, to (0, 0); their rays start on the plane 1 mm before the first surface
(object at infinity) or at the object point.

* **ray-optics 0.9.8** (``rayoptics.codev.cmdproc.read_lens``, ``rayoptics.zemax.zmxread
  .read_lens_file``; ``raytr.raytrace.trace_raw`` on ``seq_model.path``; never
  ``rayoptics.environment``, which pulls in a GUI): it implements CODE V's decenter types (DEC,
  DAR, BEN, REV) and is the referee for the .seq files. For .zmx files its coordinate breaks
  need two corrections, applied here and stated in the output (:func:`fix_zemax_tilts`):
  ray-optics 0.9.8 reads OpticStudio's tilts about x and y with CODE V's left-handed sign, and an
  order flag ≠ 0 as the *reverse* of the same values; OpticStudio's tilts are right-handed (the
  corpus file optiland/one_mirror_up_45deg.zmx, authored in OpticStudio, folds "up" to +y) and
  order 1 means tilt z, y, x, then decenter — which is ray-optics' reverse of the negated
  values. ray-optics ignores the surface tilt/decenter tab (``SCBD``); where a file has one on
  the image surface, the referee's final ray is compared after moving it into our image frame.
* **optiland 0.6.3** (``optiland.fileio.load_zemax_file``): it folds coordinate breaks into each
  surface's coordinate system with the rotation ``Rz Ry Rx`` — exact for the corpus files, whose
  breaks turn about one axis at a time — and records global coordinates, which are turned into
  the stop's and the image surface's own frames here. It ignores ``SCBD`` (as above).

Importable: :func:`ours_grid`, :func:`rayoptics_grid`, :func:`optiland_grid` (used by
tests/test_geometry_referees.py).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import warnings
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
CORPUS = ROOT / "tests" / "data" / "corpus"
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

#: corpus files with decenters, tilts, coordinate breaks or mirrors that the referees read, and
#: the half-width of the 3 × 3 field grid (degrees; mm of object height for a finite object)
RAYOPTICS_FILES = {
    "rayoptics/dar_test.seq": 0.05,
    "rayoptics/dec_rev_tilt_test.seq": 0.05,
    "rayoptics/dec_test.seq": 2.0,
    "rayoptics/dec_tilt_test.seq": 3.0,
    "rayoptics/folded_lenses.seq": 2.0,
    "rayoptics/tilt_test.seq": 0.05,
    "rayoptics/threemir.seq": 2.0,
    "rayoptics/mangin.seq": 0.3,
    "rayoptics/paraboloid.seq": 0.05,
    "rayoptics/rc_f16.seq": 0.3,
    "rayoptics/questar35.seq": 0.25,
    "rayoptics/achroMangin_ok.seq": 1.0,
    "optiland/one_mirror_up_45deg.zmx": 2.0,
    "rayoptics/HoO-V2C18Ex66.zmx": 1.0,
    "pyzdde/ConcentricSpheres.zmx": 1.0,
    "rayoptics/US08011793-1.zmx": 1.0,
    "rayoptics/zmax_37992.zmx": 0.1,
}
OPTILAND_FILES = {
    "optiland/one_mirror_up_45deg.zmx": 2.0,
    "optiland/simple_fold_mirror_up.zmx": 2.0,
    "rayoptics/HoO-V2C18Ex66.zmx": 1.0,
    "pyzdde/ConcentricSpheres.zmx": 1.0,
    "rayoptics/US08011793-1.zmx": 1.0,
    "rayoptics/zmax_37992.zmx": 0.1,
}
START_GAP = 1.0  # mm: referee rays (object at infinity) start this far before the first surface


def _no_gui() -> None:
    for m in ("PySide6", "PyQt5", "PyQt6", "qtpy", "qtconsole", "ipywidgets"):
        sys.modules.setdefault(m, None)  # type: ignore[arg-type]


def grid(half: float, n: int = 3) -> tuple[np.ndarray, np.ndarray]:
    """(X, Y) meshgrid of n × n values in [−half, half]."""
    g = np.linspace(-half, half, n)
    return np.meshgrid(g, g)


def ours_grid(lens, X: np.ndarray, Y: np.ndarray) -> np.ndarray:
    """orthoscope's chief-ray points (…, 2) on the lens's image surface (its own x, y), mm."""
    from raytrace.trace.chief2d import chief_rays_2d

    if math.isinf(lens.object_distance):
        cr = chief_rays_2d(lens, X, Y, clip=False)
    else:
        cr = chief_rays_2d(lens, object_x_mm=X, object_y_mm=Y, clip=False)
    if not np.all(cr.ok):
        raise RuntimeError(f"{lens.name}: {np.count_nonzero(~cr.ok)} chief rays failed")
    return cr.positions_at(lens.image_z)


def _newton_polish(f, u: np.ndarray, steps: int = 6) -> np.ndarray:
    for _ in range(steps):
        r = f(u)
        J = np.empty((2, 2))
        h = 1e-7 * max(1.0, float(np.max(np.abs(u))))
        for k in range(2):
            du = np.zeros(2)
            du[k] = h
            J[:, k] = (f(u + du) - r) / h
        try:
            u = u - np.linalg.solve(J, r)
        except np.linalg.LinAlgError:
            break
    return u


def _to_image_frame(lens, p: np.ndarray, d: np.ndarray) -> np.ndarray:
    """A global ray (point, direction) moved into ``lens``'s image frame and transferred to the
    image surface: its (x, y) there."""
    from raytrace.frames import surface_frames

    fr = surface_frames(lens)
    R, o = np.asarray(fr.image_rotation), np.asarray(fr.image_origin)
    q, e = R.T @ (p - o), R.T @ d
    t = (lens.image_z - q[2]) / e[2]
    return (q + t * e)[:2]


# ------------------------------------------------------------------------------ ray-optics
def fix_zemax_tilts(opm) -> None:
    """Give ray-optics 0.9.8 OpticStudio's coordinate-break moves (module docstring): negate
    the x and y tilts (its CODE V handedness), and turn an order flag ≠ 0 ('reverse' in
    ray-optics) into the reverse of the negated values."""
    for ifc in opm["seq_model"].ifcs:
        if getattr(ifc, "z_type", None) == "COORDBRK" and ifc.decenter is not None:
            d = ifc.decenter
            d.euler[0] = -d.euler[0]
            d.euler[1] = -d.euler[1]
            if d.dtype == "reverse":
                d.euler[:] = -d.euler
                d.dec[:] = -d.dec
            d.update()
    opm.update_model()


def rayoptics_open(path: str | Path):
    """(opt_model, scale to mm) of a .seq / .zmx file read by ray-optics (Zemax tilts fixed)."""
    _no_gui()
    from rayoptics.codev.cmdproc import read_lens as read_seq
    from rayoptics.zemax.zmxread import read_lens_file

    p = Path(path)
    zmx = p.suffix.lower() == ".zmx"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        opm, _ = (read_lens_file if zmx else read_seq)(p)
    if zmx:
        fix_zemax_tilts(opm)
    dims = str(opm["system_spec"].dimensions).lower()
    scale = 25.4 if dims.startswith("in") else 10.0 if dims.startswith("cm") else 1.0
    return opm, scale


def _field_point(infinite: bool, x, y, scale: float = 1.0) -> tuple[float, float]:
    """A field point of :func:`grid` as the referee takes it: the direction tangents
    tan(x), tan(y) of field angles in degrees (object at infinity), or the object point
    (x, y) mm in the referee's length unit (``scale`` mm per unit)."""
    if infinite:
        return math.tan(math.radians(x)), math.tan(math.radians(y))
    return x / scale, y / scale


def rayoptics_grid(path, lens, X: np.ndarray, Y: np.ndarray) -> tuple[np.ndarray, float]:
    """ray-optics' chief-ray points (…, 2) on the image surface (mm) and the largest stop
    residual of its aim (mm), for the fields of :func:`ours_grid`."""
    import rayoptics.optical.model_constants as mc
    from rayoptics.raytr import raytrace as rt
    from scipy.optimize import root

    opm, scale = rayoptics_open(path)
    sm = opm["seq_model"]
    # the referee's own number for our wavelength (µm in a .zmx file → nm may round)
    wvls = list(opm["optical_spec"]["wvls"].wavelengths)
    wvl = min(wvls, key=lambda w: abs(w - lens.wavelength))
    if abs(wvl - lens.wavelength) > 1e-6:
        raise ValueError(f"ray-optics has no wavelength {lens.wavelength} nm (it has {wvls})")
    path_ = [list(e) for e in sm.path(wvl)]
    infinite = math.isinf(lens.object_distance)
    if infinite:
        rot, _ = path_[0][mc.Tfrm]
        path_[0][mc.Tfrm] = (rot, np.array([0.0, 0.0, START_GAP / scale]))
    stop = sm.stop_surface if sm.stop_surface is not None else 1
    last = len(sm.ifcs) - 1
    image_tab = Path(path).suffix.lower() == ".zmx" and lens.image_placement is not None
    focus_shift = float(opm["optical_spec"]["focus"].focus_shift)
    out = np.empty(X.shape + (2,))
    worst = 0.0
    for i in np.ndindex(X.shape):
        tx, ty = _field_point(infinite, X[i], Y[i], scale)

        def run(u, tx=tx, ty=ty):
            if infinite:
                d = np.array([tx, ty, 1.0])
                p0 = np.array([u[0], u[1], 0.0])
            else:
                d = np.array([u[0], u[1], 1.0])
                p0 = np.array([tx, ty, 0.0])
            ray, _, _ = rt.trace_raw(
                iter([tuple(e) for e in path_]), p0, d / np.linalg.norm(d), wvl,
                first_surf=1, last_surf=last - 1,
            )  # fmt: skip
            return ray

        def f(u, run=run):
            return np.asarray(run(u)[stop][mc.p][:2], dtype=float)

        u = root(f, np.zeros(2), method="hybr", options={"xtol": 1e-15}).x
        u = _newton_polish(f, u)
        worst = max(worst, float(np.max(np.abs(f(u)))) * scale)
        ray = run(u)
        if image_tab:
            # ray-optics has no image-surface tilt: take its ray after the last interface that
            # acts (not a coordinate break) into our image frame
            from rayoptics.elem.transform import compute_global_coords

            k = max(j for j in range(1, last) if sm.ifcs[j].interact_mode != "phantom")
            R, t = compute_global_coords(sm, glo=1)[k]
            p = (R @ ray[k][mc.p] + t) * scale
            d = R @ ray[k][mc.d]
            out[i] = _to_image_frame(lens, p, d)
        else:
            # the referee's focus shift (a CODE V image-surface thickness: our image plane is
            # moved by it, ray-optics keeps its image surface and defocuses by it; on a
            # decentered image surface our reader does not apply it, and says so)
            p = np.asarray(ray[-1][mc.p], dtype=float)
            d = np.asarray(ray[-1][mc.d], dtype=float)
            if focus_shift and lens.image_placement is None:
                p = p + d * (focus_shift / d[2])
            out[i] = p[:2] * scale
    return out, worst


# ------------------------------------------------------------------------------ optiland
def optiland_open(path: str | Path):
    from optiland.fileio import load_codev_file, load_zemax_file

    p = Path(path)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return (load_zemax_file if p.suffix.lower() == ".zmx" else load_codev_file)(str(p))


def _cs(srf) -> tuple[np.ndarray, np.ndarray]:
    t, R = srf.geometry.cs.get_effective_transform()
    return np.asarray(R, dtype=float), np.asarray(t, dtype=float)


def optiland_grid(op, lens, X: np.ndarray, Y: np.ndarray) -> tuple[np.ndarray, float]:
    """optiland's chief-ray points (…, 2) on ``lens``'s image surface (mm) and its largest stop
    residual (mm), for the fields of :func:`ours_grid`. ``op``: an optiland ``Optic``."""
    from optiland.rays import RealRays
    from scipy.optimize import root

    sg = op.surfaces
    for s in sg.surfaces:
        if hasattr(s.geometry, "tol"):
            s.geometry.tol = 1e-15  # tighten the asphere intersection (default 1e-6 mm)
    stop = sg.stop_index
    Rs, ts = _cs(sg.surfaces[stop])
    infinite = math.isinf(lens.object_distance)
    obj = float(sg.surfaces[0].thickness)
    wl_um = lens.wavelength / 1000.0
    out = np.empty(X.shape + (2,))
    worst = 0.0
    for i in np.ndindex(X.shape):
        tx, ty = _field_point(infinite, X[i], Y[i])

        def run(u, tx=tx, ty=ty):
            if infinite:
                d = np.array([tx, ty, 1.0])
                p = np.array([u[0], u[1], -START_GAP])
            else:
                d = np.array([u[0], u[1], 1.0])
                p = np.array([tx, ty, -obj])
            d = d / np.linalg.norm(d)
            r = RealRays(*[np.array([v]) for v in (*p, *d)], np.ones(1), np.full(1, wl_um))
            sg.trace(r, skip=1, record=True)
            return sg

        def f(u, run=run):
            g = run(u)
            k = stop - 1
            pg = np.array([float(g.x[k][0]), float(g.y[k][0]), float(g.z[k][0])])
            return (Rs.T @ (pg - ts))[:2]

        u = root(f, np.zeros(2), method="hybr", options={"xtol": 1e-15}).x
        u = _newton_polish(f, u)
        worst = max(worst, float(np.max(np.abs(f(u)))))
        g = run(u)
        # the ray after the last surface before the image (global), moved into our image frame:
        # no grazing intersection where optiland's image plane is not tilted like the file's
        k = -2
        p = np.array([float(g.x[k][0]), float(g.y[k][0]), float(g.z[k][0])])
        d = np.array([float(g.L[k][0]), float(g.M[k][0]), float(g.N[k][0])])
        out[i] = _to_image_frame(lens, p, d)
    return out, worst


# ------------------------------------------------------------------------------ script
def compare(rel: str, which: str) -> dict:
    from raytrace.files import read_lens_file

    path = CORPUS / rel
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        lens = read_lens_file(path)
    half = (RAYOPTICS_FILES if which == "rayoptics" else OPTILAND_FILES).get(rel, 1.0)
    X, Y = grid(half)
    ours = ours_grid(lens, X, Y)
    if which == "rayoptics":
        theirs, res = rayoptics_grid(path, lens, X, Y)
    else:
        theirs, res = optiland_grid(optiland_open(path), lens, X, Y)
    return {
        "file": rel,
        "referee": which,
        "grid_half": half,
        "max_diff_mm": float(np.max(np.abs(ours - theirs))),
        "referee_stop_residual_mm": res,
    }


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("files", nargs="*", help="corpus-relative paths (default: the built-in lists)")
    ap.add_argument("--json", action="store_true")
    args = ap.parse_args(argv)
    jobs = []
    if args.files:
        for f in args.files:
            jobs += [(f, "rayoptics"), (f, "optiland")]
    else:
        jobs = [(f, "rayoptics") for f in RAYOPTICS_FILES] + [
            (f, "optiland") for f in OPTILAND_FILES
        ]
    rows = []
    for f, which in jobs:
        try:
            rows.append(compare(f, which))
        except Exception as e:  # noqa: BLE001 - a referee that cannot read a file is reported
            rows.append({"file": f, "referee": which, "error": f"{type(e).__name__}: {e}"[:200]})
    if args.json:
        print(json.dumps(rows, indent=1))
        return 0
    print(f"{'file':42s} {'referee':10s} {'grid':>6s} {'max |ours - ref| mm':>20s} {'ref aim':>9s}")
    for r in rows:
        if "error" in r:
            print(f"{r['file']:42s} {r['referee']:10s} {'':6s} {'ERROR: ' + r['error']}")
        else:
            print(
                f"{r['file']:42s} {r['referee']:10s} {r['grid_half']:6g} "
                f"{r['max_diff_mm']:20.3e} {r['referee_stop_residual_mm']:9.1e}"
            )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
