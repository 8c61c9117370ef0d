"""The numba kernel cache (docs/design.md, "Performance"): a cache that cannot be written falls
back to the user cache folder or to uncached compilation with one warning, never an error; the
cache stamp covers every kernel module, so inlined code is never stale."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

from raytrace.files.library import load_lens
from raytrace.trace import chief_rays

ROOT = Path(__file__).resolve().parents[1]

CHILD = """
import warnings
warnings.simplefilter("always")
from raytrace.files.library import load_lens
from raytrace.trace import chief_rays
cr = chief_rays(load_lens("topogon-us2031792-fig1"), [0.0, 7.0])
print("HEIGHT", repr(float(cr.heights_at(cr.z_last[0] + 51.9415)[1])))
"""

# The same chief ray (7 deg) through the one-kernel ray_paths, from the start the aim found in
# the test process (argv): the uncached child then compiles one small kernel (about 8 s cold)
# instead of the aim kernel and everything it inlines (about 50 s), and the flat surface added
# at the image plane (51.9415 mm after the last vertex) gives its height there.
CHILD_PATHS = """
import dataclasses, sys, warnings
warnings.simplefilter("always")
from raytrace.files.library import load_lens
from raytrace.lens import Surface
from raytrace.trace import ray_paths
lens = load_lens("topogon-us2031792-fig1")
image = Surface(curvature=0.0, thickness=0.0, material=lens.surfaces[-1].material)
lens = dataclasses.replace(lens, surfaces=lens.surfaces + (image,))
y, z, m, n = map(float, sys.argv[1:])
rp = ray_paths(lens, [[0.0, y, z]], [[0.0, m, n]])
print("HEIGHT", repr(float(rp.y[0, -1])))
"""


def test_unwritable_cache_falls_back_to_uncached_with_one_warning(tmp_path):
    # a private copy of the packages whose __pycache__ folders cannot be created (a file of that
    # name blocks the directory even for root), and a home / XDG cache inside /proc, where no
    # one can create folders: no cache location is writable.
    for pkg in ("raytrace", "distortion", "orthoscope"):
        shutil.copytree(ROOT / pkg, tmp_path / pkg, ignore=shutil.ignore_patterns("__pycache__"))
    shutil.copytree(ROOT / "lenses", tmp_path / "orthoscope_lenses")
    for d in (tmp_path / "raytrace").rglob("*"):
        if d.is_dir():
            (d / "__pycache__").write_text("not a folder")
    (tmp_path / "raytrace" / "__pycache__").write_text("not a folder")
    env = {
        k: v
        for k, v in os.environ.items()
        if not k.startswith("NUMBA_CACHE") and k not in ("HOME", "XDG_CACHE_HOME")
    }
    env.update(HOME="/proc/no-home", XDG_CACHE_HOME="/proc/no-cache", PYTHONPATH=str(tmp_path))
    cr = chief_rays(load_lens("topogon-us2031792-fig1"), [7.0])
    start = [repr(float(a[0])) for a in (cr.y_start, cr.z_start, cr.M_start, cr.N_start)]
    r = subprocess.run(
        [sys.executable, "-c", CHILD_PATHS, *start],
        cwd=tmp_path,
        env=env,
        capture_output=True,
        text=True,
    )
    assert r.returncode == 0, r.stderr
    warned = [ln for ln in r.stderr.splitlines() if "KernelCacheWarning" in ln]
    assert len(warned) == 1, r.stderr
    assert "NUMBA_CACHE_DIR" in warned[0]
    # the uncached kernel gives the published chief-ray height (US 2,031,792: 8.1121 mm at 7 deg,
    # see tests/test_trace.py)
    h = float(r.stdout.split("HEIGHT")[1])
    assert abs(h - 8.1121) < 6e-4


def test_an_unwritable_numba_cache_dir_is_named(tmp_path):
    # numba passes over a NUMBA_CACHE_DIR it cannot write without a word (and the no-cache
    # warning then told the user to set the variable they had set): one warning names it and
    # where the cache went instead
    blocker = tmp_path / "not-a-folder"
    blocker.write_text("a file")
    env = {k: v for k, v in os.environ.items() if not k.startswith("NUMBA_CACHE")}
    env["NUMBA_CACHE_DIR"] = str(blocker)
    r = subprocess.run(
        [sys.executable, "-c", CHILD], cwd=tmp_path, env=env, capture_output=True, text=True
    )
    assert r.returncode == 0, r.stderr
    warned = [ln for ln in r.stderr.splitlines() if "KernelCacheWarning" in ln]
    assert len(warned) == 1, r.stderr
    assert f"NUMBA_CACHE_DIR ({blocker}) is not a writable folder" in warned[0]
    assert "instead" in warned[0]


def test_cache_stamp_covers_every_kernel_module():
    from raytrace.kernels.jit import KERNEL_STAMP

    names = {n for n, *_ in KERNEL_STAMP}
    assert names == {p.name for p in (ROOT / "raytrace" / "kernels").glob("*.py")}


def test_compile_notice_when_a_kernel_compiles_and_only_then(monkeypatch, capsys):
    """The "compiling" line comes with numba's compile event (a cache miss) of a project kernel,
    once per run: `report` after `distortion` compiled its own kernels for 30 s in silence (the
    old notice looked at the cache of two kernels only). A cache hit fires no event, a compile
    of someone else's function says nothing, and an uncached run (its KernelCacheWarning said
    so) says nothing more."""
    from types import SimpleNamespace

    from numba.core import event

    import raytrace.kernels.jit as jit
    from orthoscope import cli
    from raytrace.kernels import aim

    ours = SimpleNamespace(py_func=aim.aim_chief.py_func)
    other = SimpleNamespace(py_func=lambda: None)

    def compile_(d):
        with event.trigger_event("numba:compile", data={"dispatcher": d}):
            pass

    for uncached, events, expect in (
        (False, [other], 0),
        (False, [ours, ours], 1),
        (False, [other, ours], 1),
        (True, [ours], 0),
        (False, [], 0),
    ):
        monkeypatch.setattr(jit, "_warned", uncached)
        cli._compile_notice()
        for d in events:
            compile_(d)
        err = capsys.readouterr().err
        assert err.count(cli.COMPILE_NOTICE) == expect, (uncached, events, err)
    assert sum(type(ls).__name__ == "Notice" for ls in event._registered["numba:compile"]) == 1
    # after a run of main(), library use in the same process (a notebook, the next test) that
    # compiles a kernel hears nothing from the command line
    assert cli.main(["lenses"]) == 0
    capsys.readouterr()
    compile_(ours)
    assert cli.COMPILE_NOTICE not in capsys.readouterr().err
    assert not any(type(f).__name__ == "_BeforeMatplotlib" for f in sys.meta_path)


def _array_types(sig):
    """The array types in a numba signature, tuples of arrays included."""
    from numba.core import types

    for t in sig:
        if isinstance(t, types.BaseTuple):
            yield from _array_types(t.types)
        elif isinstance(t, types.Array):
            yield t


def test_kernels_see_one_type_per_argument():
    """numba compiles a kernel once for each set of argument types, and a read-only array or a
    literal argument is another type: each would compile the big kernels again (the cold compile
    of the test suite had doubled this way). The packed lens arrays are writeable whether the
    indices come from the read-only cache (one wavelength) or not (several), read-only ray inputs
    are copied, and the called kernels get no literal arguments."""
    import numpy as np
    from numba.core import types

    from raytrace.files.library import load_lens
    from raytrace.kernels import aim, aim2d, bulk, paths
    from raytrace.packing import pack
    from raytrace.trace import chief_rays, chief_rays_2d, trace_rays
    from raytrace.trace.rays import ray_paths

    lens = load_lens("cooke-triplet-f4")
    for p in (pack(lens), pack(lens, wavelengths=(486.1, 587.6, 656.3))):
        for a in p.arrays + p.lens_arrays:
            assert a.flags.writeable and a.flags.c_contiguous
    ro = np.zeros(4)
    ro.flags.writeable = False
    rays = trace_rays(lens, (ro, ro, ro - 1.0), (ro, ro, ro + 1.0))
    assert rays.ok.all()
    ray_paths(lens, (ro, ro, ro - 1.0), (ro, ro, ro + 1.0))
    chief_rays(lens, [0.0, 10.0])
    chief_rays(lens, [0.0, 10.0], wavelengths="lens")
    chief_rays_2d(lens, [0.0, 5.0], [0.0, 5.0])
    # a kernel lists the signatures it was loaded or compiled for in this process; a called
    # kernel (_trace_lens, _general_rows) only those compiled here (not when its caller came
    # from the cache). None may hold a read-only array or a literal.
    kernels = (aim.aim_chief, aim2d.aim_chief_2d, aim2d._trace_lens, bulk.trace_batch_serial,
               bulk._general_rows, paths.trace_paths)  # fmt: skip
    for k in kernels:
        for sig in k.signatures:
            assert not any(isinstance(t, types.Literal) for t in sig), (k, sig)
            assert all(t.mutable for t in _array_types(sig)), (k, sig)
