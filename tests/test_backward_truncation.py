"""Two classes of silently wrong results (issue 10, "hardening"; docs/design.md, "Errors and
files"):

1. A ray that could reach a surface only by travelling backwards (overlapping surfaces with no
   semi-diameters to catch them) gets its own status, ``backward`` (raytrace.kernels.codes
   STATUS_BACKWARD), on every kernel path: the vectorised bulk trace (quadric and asphere
   passes, serial and parallel), the flagged per-ray path, ray paths and chief-ray aiming.
   The references are analytic: where a ray parallel to the axis at height h meets a sphere of
   radius R set a gap g behind a plane, it travels backwards exactly when the sag
   R - sqrt(R^2 - h^2) exceeds g (concave side first), i.e. for h > sqrt(R^2 - (R - g)^2).
2. A truncated lens file is an error, never a shorter lens: every real .zmx / .seq / .len file in
   tests/data cut after any line either reads as the same lens or raises one PrescriptionError
   (hypothesis draws the cut; an exhaustive sweep over every line runs in the same test file for
   a few files). What each format's check relies on, and what it cannot see, is in the readers'
   ``check_complete`` docstrings and lenses/INTEROP.md ("Truncated files").
"""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from raytrace.errors import OrthoscopeError, PrescriptionError
from raytrace.files.codev import loads_seq
from raytrace.files.oslo import loads_len
from raytrace.files.zemax import loads_zmx
from raytrace.kernels.codes import (
    STATUS_BACKWARD,
    STATUS_NAMES,
    STATUS_OK,
    status_message,
)
from raytrace.lens import Aperture, Field, Lens, Surface
from raytrace.materials import fixed_index
from raytrace.trace import chief_rays, ray_paths, trace_rays

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT / "tests" / "data"
GLASS = fixed_index(1.5)

R3 = 20.0  # |radius| of the concave third surface, mm
GAP = 0.5  # air gap from the plate's back face to its vertex, mm
H_BACK = math.sqrt(R3**2 - (R3 - GAP) ** 2)  # analytic onset of backward travel: 4.4441 mm


def _overlap(gap: float = GAP, aspheric: tuple[float, ...] = ()) -> Lens:
    """A plane-parallel plate (stop on its front face), then a plano-concave element whose
    sphere of radius -R3 (concave toward the light) lies a gap behind the plate; no
    semi-diameters, so nothing but the trace sees the overlap of the sphere's rim with the
    plate."""
    s = (
        Surface(0.0, 5.0, GLASS, stop=True),
        Surface(0.0, gap),
        Surface(-1.0 / R3, 3.0, GLASS, aspheric=aspheric),
        Surface(0.0, 40.0),
    )
    return Lens("overlap", s, Aperture("epd", 10.0), Field("angle", 5.0))


def _parallel(h: np.ndarray):
    z = np.zeros_like(h)
    return (z, h, z - 1.0), (z, z, z + 1.0)


HEIGHTS = np.array([0.0, 1.0, 3.0, 4.4, 4.49, 4.6, 5.0, 6.0])
EXPECT = np.where(HEIGHTS > H_BACK, STATUS_BACKWARD, STATUS_OK)


@pytest.mark.parametrize("threads", [1, None])
@pytest.mark.parametrize("clip", [True, False])
def test_backward_rays_are_flagged_at_the_analytic_height(threads, clip):
    rb = trace_rays(_overlap(), *_parallel(HEIGHTS), clip=clip, threads=threads)
    np.testing.assert_array_equal(rb.status, EXPECT)
    assert np.all(rb.surface[EXPECT == STATUS_BACKWARD] == 3)
    assert np.all(np.isnan(rb.y[EXPECT == STATUS_BACKWARD]))
    assert np.all(np.isfinite(rb.y[EXPECT == STATUS_OK]))


def test_backward_on_the_parallel_kernel():
    # a batch above PARALLEL_THRESHOLD runs trace_batch_parallel
    h = np.linspace(0.0, 6.0, 40001)
    rb = trace_rays(_overlap(), *_parallel(h))
    far = np.abs(h - H_BACK) > 1e-6
    expect = np.where(h > H_BACK, STATUS_BACKWARD, STATUS_OK)
    np.testing.assert_array_equal(rb.status[far], expect[far])


def test_backward_on_the_asphere_pass_and_ray_paths():
    # a tiny r^4 term sends surface 3 through the Newton (asphere) passes; the onset moves by
    # far less than the distance of these heights from it (sag change 1e-9 * 5^4 < 1e-6 mm)
    lens = _overlap(aspheric=(1e-9,))
    h = np.array([0.0, 2.0, 4.0, 4.8, 5.5])
    expect = np.where(h > H_BACK, STATUS_BACKWARD, STATUS_OK)
    np.testing.assert_array_equal(trace_rays(lens, *_parallel(h)).status, expect)
    np.testing.assert_array_equal(ray_paths(lens, *_parallel(h)).status, expect)


def test_negative_air_gap_fails_chief_rays_with_backward():
    # the element's surface 3 mm *before* the plate's back face: every ray would travel backwards
    lens = _overlap(gap=-3.0)
    cr = chief_rays(lens, fields_deg=[0.0, 2.0, 5.0])
    assert cr.status_names == ["backward"] * 3


def test_a_correct_lens_coincident_surfaces_and_virtual_dummies_stay_ok():
    # the same parts with a positive gap large enough; two refracting planes at zero distance
    # (coincident surfaces, t = 0 within round-off: a cemented interface); and a dummy surface
    # in air reached backwards (a stop drawn 4 mm behind the next element, then a thickness of
    # -4 back to it: the source programs trace such dummies virtually, and the path between the
    # surfaces that act, 1 mm, is forward)
    ok = _overlap(gap=5.0)
    assert np.all(trace_rays(ok, *_parallel(HEIGHTS)).status == STATUS_OK)
    s = (
        Surface(0.0, 0.0, GLASS, stop=True),
        Surface(0.0, 5.0, fixed_index(1.6)),
        Surface(-1.0 / 50.0, 45.0),
    )
    lens = Lens("coincident", s, Aperture("epd", 10.0), Field("angle", 5.0))
    assert np.all(trace_rays(lens, *_parallel(HEIGHTS)).status == STATUS_OK)
    s = (
        Surface(1.0 / 50.0, 3.0, GLASS),
        Surface(0.0, 5.0),
        Surface(0.0, -4.0, stop=True),  # dummy in air, 4 mm behind the next vertex
        Surface(0.0, 3.0, GLASS),
        Surface(0.0, 40.0),
    )
    lens = Lens("virtual-dummy", s, Aperture("epd", 10.0), Field("angle", 5.0))
    rb = trace_rays(lens, *_parallel(HEIGHTS))
    assert np.all(rb.status == STATUS_OK)
    cr = chief_rays(lens, fields_deg=[0.0, 5.0])
    assert cr.status_names == ["ok", "ok"]
    # the same dummy with the next element 1 mm *before* the back face of the first: backward
    s = s[:2] + (Surface(0.0, -6.0, stop=True),) + s[3:]
    bad = Lens("overlap-through-dummy", s, Aperture("epd", 10.0), Field("angle", 5.0))
    rb = trace_rays(bad, *_parallel(HEIGHTS))
    assert np.all(rb.status == STATUS_BACKWARD) and np.all(rb.surface == 4)


def test_first_surface_concave_is_not_backward():
    # a ray is a line that may start anywhere before the first surface: rays launched on the
    # vertex plane of a concave first surface meet it behind their start point, legitimately
    s = (Surface(-1.0 / 30.0, 4.0, GLASS, stop=True), Surface(0.0, 40.0))
    lens = Lens("concave-first", s, Aperture("epd", 10.0), Field("angle", 5.0))
    h = np.array([0.0, 3.0, 6.0])
    z = np.zeros_like(h)
    assert np.all(trace_rays(lens, (z, h, z), (z, z, z + 1.0)).status == STATUS_OK)


def test_mirror_reverses_legitimately_and_a_wrong_sign_gap_is_backward():
    # after a mirror the light travels toward -z: the surface after it 50 mm *before* it
    # (thickness -50, as Zemax and CODE V write it) is reached forwards; +50 would need the ray to
    # go backwards
    def folded(t: float) -> Lens:
        s = (
            Surface(-1.0 / 200.0, t, mirror=True, stop=True),
            Surface(0.0, -5.0, GLASS),  # a window after the mirror (thickness negative)
            Surface(0.0, -10.0),
        )
        return Lens("mirror", s, Aperture("epd", 20.0), Field("angle", 0.0))

    h = np.array([0.0, 5.0, 9.0])
    z = np.zeros_like(h)
    rays = ((z, h, z - 1.0), (z, z, z + 1.0))
    assert np.all(trace_rays(folded(-50.0), *rays).status == STATUS_OK)
    bad = trace_rays(folded(50.0), *rays)
    assert np.all(bad.status == STATUS_BACKWARD) and np.all(bad.surface == 2)


def test_status_tables_and_message_name_the_new_code():
    assert STATUS_NAMES[STATUS_BACKWARD] == "backward"
    assert len(set(STATUS_NAMES)) == len(STATUS_NAMES) == max(STATUS_NAMES) + 1  # bincount-safe
    msg = status_message(STATUS_BACKWARD, 3)
    assert msg == (
        "ray travels backwards to surface 3: surfaces overlap; check thicknesses / semi-diameters"
    )


# ---- truncated files -------------------------------------------------------------------------
LOADERS = {".zmx": loads_zmx, ".seq": loads_seq, ".len": loads_len}
REAL = sorted(p for p in DATA.rglob("*") if p.is_file() and p.suffix.lower() in LOADERS)


def _text(p: Path) -> str:
    b = p.read_bytes()
    if b[:2] in (b"\xff\xfe", b"\xfe\xff"):
        return b.decode("utf-16")
    return b.decode("utf-8", errors="replace")


def _load(text: str, suffix: str):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return LOADERS[suffix](text)


def _full(p: Path):
    try:
        return _load(_text(p), p.suffix.lower())
    except OrthoscopeError:
        return None  # refused as a whole (a glass, a surface type): its cuts must be refused too


_FULL = {p: _full(p) for p in REAL}


def _check_cut(p: Path, k: int) -> str:
    """Cut ``p`` after its line k (1-based) and check the outcome; returns 'same' / 'error'."""
    lines = _text(p).split("\n")
    cut = "\n".join(lines[:k]) + "\n"
    try:
        lens = _load(cut, p.suffix.lower())
    except PrescriptionError as e:
        assert str(e).count("\n") == 0 and str(e).strip()
        return "error"
    full = _FULL[p]
    rel = p.relative_to(DATA)
    assert full is not None, f"{rel} cut after line {k} reads, the whole file does not"
    assert lens == full, (
        f"{rel} cut after line {k} of {len(lines)} reads as a different lens "
        f"({len(lens.surfaces)} surfaces, the file has {len(full.surfaces)})"
    )
    return "same"


def test_real_files_are_present_and_complete_ones_are_not_called_truncated():
    assert {p.suffix.lower() for p in REAL} == {".zmx", ".seq", ".len"}
    for p in REAL:
        try:
            _load(_text(p), p.suffix.lower())
        except PrescriptionError as e:
            assert "truncated" not in str(e) or p.name == "test.seq", f"{p}: {e}"
            # rayoptics/test.seq is a parser-test fragment: no SI, no field, no GO


@settings(
    max_examples=300,
    deadline=None,
    derandomize=True,
    suppress_health_check=[HealthCheck.too_slow],
)
@given(data=st.data())
def test_a_truncated_real_file_is_the_same_lens_or_an_error(data):
    p = data.draw(st.sampled_from(REAL), label="file")
    n = len(_text(p).split("\n"))
    k = data.draw(st.integers(min_value=1, max_value=max(1, n - 1)), label="cut after line")
    _check_cut(p, k)


SWEEP = [
    "cooke-triplet-f4.zmx",
    "cooke-triplet-f4.seq",
    "corpus/pyzdde/ConcentricSpheres.zmx",  # mirrors of thickness 0: cut after their DISZ 0
    "corpus/optiland/simple_fold_mirror_up.zmx",
    "corpus/optiland/lens1.zmx",  # no sections after the surfaces
    "corpus/rayoptics/threemir.seq",  # no GO; system data after SI (XAN before YAN)
    "corpus/rayoptics/dec_test.seq",
    "corpus/optiland/test_petzval.len",
    "corpus/optiland/cox3_07.len",
]


@pytest.mark.parametrize("name", SWEEP)
def test_every_cut_of_selected_files(name):
    p = DATA / name
    n = len(_text(p).split("\n"))
    outcomes = [_check_cut(p, k) for k in range(1, n)]
    assert "error" in outcomes  # the cuts inside the lens are refused


@pytest.mark.parametrize(
    "suffix, text, words",
    [
        (".len", 'LEN NEW "x" 50 3\nEBR 5\nAIR\nTH 1e20\nNXT\nGLA N-BK7\nRD 50\nTH 5\n', "END"),
        (
            ".len",
            'LEN NEW "x" 50 2\nEBR 5\nAIR\nTH 1e20\nNXT\nGLA N-BK7\nRD 50\nTH 5\nNXT\nAIR\n'
            "TH 40\nAP 5\nAST\nNXT\nAIR\nTH 0\nEND 5\n",
            "END declares 5",
        ),
        (".seq", "EPD 10\nWL 587.6\nYAN 0 5\nSO 0 1e20\nS 50 5 N-BK7\nS 0 45 &\n", "'&'"),
        (".seq", "EPD 10\nWL 587.6\nYAN 0 5\nSO 0 1e20\nS 50 5 N-BK7\nSTO\nS 0 45\n", "SI"),
    ],
)
def test_handmade_truncations_name_what_is_missing(suffix, text, words):
    with pytest.raises(PrescriptionError) as e:
        _load(text, suffix)
    assert words in str(e.value) and "truncated" in str(e.value)
