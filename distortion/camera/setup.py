"""A camera built around a lens: the sensor, the focus setting and the object plane
(:class:`CameraSetup`), read from a small TOML file (:func:`read_camera_setup`), and what it
means for one lens once resolved (:class:`CameraGeometry`).

Vocabulary (docs/design.md, "Vocabulary"; :mod:`raytrace.paraxial.conjugates`)
    **Object plane** — at most one of ``object_distance`` (mm from the object plane to the first
    vertex, a positive magnitude; ``inf``; an image scale ``"12x"``; a string may carry a unit,
    ``"5m"``), ``object_s`` (Pestrecov's signed s, mm from H, negative) and ``object_scale``
    (N of "N×"). Default: the lens file's object.

    **Focus setting** — where the sensor sits. Either the *focused object* — at most one of
    ``focus`` (in ``object_distance``'s words: mm from the first vertex, ``inf``, ``"12x"``,
    ``"2m"``), ``focus_s`` (signed, mm from H) and ``focus_scale`` (N) — or the *image
    distance* given directly — one of ``s_prime`` (mm from H'), ``from_last_vertex`` (mm from the
    last vertex) and ``defocus`` (mm from the Gaussian image plane of the object). Default:
    focused on the object.

Focusing model (unit focusing, as :mod:`distortion.variation.traced`): the whole lens moves; a
focus setting puts the sensor in the Gaussian image plane of the focused object, at that fixed
distance from the last vertex, for every object plane. Focus is a mechanical setting, so it is
computed at the lens's **reference wavelength**; a trace at another wavelength images into the
same plane (its focal shift and lateral colour then show in the model).

Projection centre: the **paraxial entrance pupil E0 at the reference wavelength**. For an object
at infinity the ideal direction of a field is the object-space chief ray's direction and needs no
centre; for a finite object it is the direction from E0 to the object point
(:mod:`distortion.camera.traced`). The real entrance pupil moves with the field (pupil
aberration); :func:`distortion.telecentricity.pupil_analysis` measures that shift, and the
traced camera reports it.

TOML camera spec (``read_camera_setup``; every key is checked, a misspelt one is refused with the
nearest valid name)::

    # orthoscope camera spec
    [sensor]                        # any two of size, pixels, pitch_um (all three: checked)
    size = "36x24"                  # mm, width x height
    pixels = "6000x4000"            # columns x rows
    # pitch_um = 6                  # micrometres
    principal_point_offset_mm = [0.0, 0.0]   # where the lens axis meets the sensor, from its
                                             # centre, mm, x right, y up

    [object]                        # at most one; leave the table out for the lens file's object
    distance = "5m"                 # or s = -5000 (mm from H), or scale = 12

    [focus]                         # at most one; leave it out to focus on the object
    distance = "2m"                 # focused object: distance / s / scale
    # from_last_vertex = 40.2       # or the image plane: s_prime / from_last_vertex / defocus

    [trace]
    wavelength = 587.5618           # nm (or "0.5876um"); default the lens's reference wavelength
    grid = [25, 17]                 # chief rays over the sensor: columns x rows
    clip = true                     # apply the lens's semi-diameters

Units: mm, nm; distances may carry a unit in strings (``"2m"``, ``"150cm"``).
"""

from __future__ import annotations

import difflib
import math
import os
import re
from collections.abc import Callable
from dataclasses import dataclass, fields, replace
from pathlib import Path

from raytrace.trace.results import object_words
from raytrace.units import UnitError, image_scale, length_mm, plane_distance_mm, wavelength_nm

from ..errors import DataError, read_text
from .sensor import Sensor

#: chief rays over the sensor (columns, rows) unless a setup says otherwise
DEFAULT_GRID = (25, 17)
#: the largest grid a setup accepts (points per axis)
MAX_GRID = 401

_OBJECT_KEYS = ("object_distance", "object_s", "object_scale")
_FOCUS_OBJECT_KEYS = ("focus", "focus_s", "focus_scale")
_PLANE_KEYS = ("s_prime", "from_last_vertex", "defocus")


def _given(obj, keys) -> list[str]:
    return [k for k in keys if getattr(obj, k) is not None]


@dataclass(frozen=True)
class CameraSetup:
    """A sensor behind a lens, focused somewhere, looking at an object plane.

    Attributes
    ----------
    sensor : Sensor
        The sensor (size, pixels, principal-point offset).
    object_distance, object_s, object_scale
        The object plane (at most one; module docstring). Default: the lens file's object.
    focus, focus_s, focus_scale
        The focused object (at most one): mm from the first vertex (``inf``, ``"12x"``,
        ``"2m"``), signed mm from H, or an image scale N.
    s_prime, from_last_vertex, defocus
        Or the image plane directly (mm from H', from the last vertex, from the Gaussian plane of
        the object). At most one focus keyword in all; none: focused on the object.
    wavelength : float or str, optional
        nm; default the lens's reference wavelength.
    grid : (int, int)
        Columns × rows of the chief rays traced over the sensor (their image points form a
        regular pixel grid, corners included).
    clip : bool
        Apply the lens's semi-diameters to the chief rays.
    """

    sensor: Sensor
    object_distance: float | str | None = None
    object_s: float | str | None = None
    object_scale: float | str | None = None
    focus: float | str | None = None
    focus_s: float | str | None = None
    focus_scale: float | str | None = None
    s_prime: float | str | None = None
    from_last_vertex: float | str | None = None
    defocus: float | str | None = None
    wavelength: float | str | None = None
    grid: tuple[int, int] = DEFAULT_GRID
    clip: bool = True

    def __post_init__(self) -> None:
        if not isinstance(self.sensor, Sensor):
            raise DataError(
                "CameraSetup: sensor must be a Sensor (Sensor.from_spec(size='36x24', "
                "pixels='6000x4000'))"
            )
        obj = _given(self, _OBJECT_KEYS)
        if len(obj) > 1:
            raise DataError(f"CameraSetup: give the object one way, not {' and '.join(obj)}")
        foc = _given(self, _FOCUS_OBJECT_KEYS + _PLANE_KEYS)
        if len(foc) > 1:
            raise DataError(
                f"CameraSetup: give the focus one way, not {' and '.join(foc)} (a focused "
                "object: focus / focus_s / focus_scale; or an image plane: s_prime / "
                "from_last_vertex / defocus)"
            )
        g = tuple(self.grid) if not isinstance(self.grid, int) else (self.grid, self.grid)
        if len(g) != 2 or not all(float(v) == int(v) and 2 <= int(v) <= MAX_GRID for v in g):
            raise DataError(
                f"CameraSetup: grid={self.grid!r}; give (columns, rows), each 2..{MAX_GRID}"
            )
        object.__setattr__(self, "grid", (int(g[0]), int(g[1])))
        object.__setattr__(self, "clip", bool(self.clip))

    def replace(self, **changes) -> CameraSetup:
        """A copy with some fields changed (a new object or focus keyword replaces the old
        one of its kind)."""
        for group in (_OBJECT_KEYS, _FOCUS_OBJECT_KEYS + _PLANE_KEYS):
            if any(k in changes and changes[k] is not None for k in group):
                for k in group:
                    changes.setdefault(k, None)
        return replace(self, **changes)

    # ---- resolution for one lens ------------------------------------------------------------
    def resolve(self, lens) -> CameraGeometry:
        """The object plane, image plane and projection centre of this setup for ``lens``
        (:class:`CameraGeometry`)."""
        return resolve_setup(lens, self)

    def describe_focus(self) -> str:
        """The focus setting as typed, in the vocabulary's words."""
        for k in _FOCUS_OBJECT_KEYS + _PLANE_KEYS:
            v = getattr(self, k)
            if v is not None:
                return f"{k} = {v}"
        return "focused on the object"


@dataclass(frozen=True)
class CameraGeometry:
    """A :class:`CameraSetup` resolved for one lens (mm, absolute z from the first vertex).

    Attributes
    ----------
    lens_name : str
    object_distance : float
        mm from the object plane to the first vertex (inf).
    object_s : float
        Pestrecov's s of the object (mm from H; −inf at infinity).
    focus_object_distance : float or None
        The focused object's distance from the first vertex (mm; inf), or None when the image
        plane was given directly.
    focus : str
        How the focus was given (``"focused on the object"``, ``"focus = 2m"``, ...).
    z_image, from_last_vertex, s_prime, defocus : float
        The image (sensor) plane: absolute z; from the last vertex; from H'; from the Gaussian
        plane of the object — all at the reference wavelength.
    wavelength, reference_wavelength : float
        The traced wavelength and the lens's reference wavelength (nm).
    z_projection_centre : float
        The paraxial entrance pupil E0 at the reference wavelength (absolute z, mm): the
        projection centre of the ideal directions.
    camera_constant : float
        Paraxial principal distance c (mm) of the sensor plane: ``F0 = p0'/m_e`` for an object at
        infinity, ``M0·p0`` for a finite one (Pestrecov Eq. 8, at the traced wavelength) — the
        focal length a distortion-free camera model would have, c / pitch in pixels.
    efl : float
        Effective focal length at the reference wavelength (mm).
    magnification : float
        Gaussian magnification m0 of the object at the reference wavelength (0 at infinity).
    """

    lens_name: str
    object_distance: float
    object_s: float
    focus_object_distance: float | None
    focus: str
    z_image: float
    from_last_vertex: float
    s_prime: float
    defocus: float
    wavelength: float
    reference_wavelength: float
    z_projection_centre: float
    camera_constant: float
    efl: float
    magnification: float

    @property
    def infinite(self) -> bool:
        return math.isinf(self.object_distance)

    @property
    def projection_centre(self) -> str:
        """One line stating the projection centre, for every output."""
        return (
            f"projection centre: paraxial entrance pupil E0 at {self.reference_wavelength:g} nm "
            f"(reference wavelength), z = {self.z_projection_centre:.6g} mm from the first vertex"
            + (" (direction of the object at infinity: independent of the centre)"
               if self.infinite else "")
        )  # fmt: skip

    @property
    def object_label(self) -> str:
        """The object plane in a repr: ``inf``, or its distance from the first vertex (mm)."""
        return object_words(self.object_distance)

    def __repr__(self) -> str:
        return (
            f"CameraGeometry({self.lens_name!r}, object {self.object_label}, {self.focus}, "
            f"sensor plane {self.from_last_vertex:.6g} mm from the last vertex (defocus "
            f"{self.defocus:+.4g} mm), c = {self.camera_constant:.6g} mm, {self.wavelength:g} nm)"
        )


def _object_value(value, what: str):
    """An object / focus distance keyword: a number (mm), 'inf', 'Nx', or a length with a
    unit ('2m') → what resolve_object_distance takes."""
    if value is None or not isinstance(value, str):
        return value
    t = value.strip().lower()
    if t in ("inf", "infinity") or t.endswith(("x", "×")):
        return t
    return _in_units(length_mm, t, what, allow_inf=True)


def _in_units(
    convert: Callable[..., float], value: float | str | None, what: str, **options: bool
) -> float | None:
    """A setup value through one of :mod:`raytrace.units`' parsers, its refusal a DataError.

    Parameters
    ----------
    convert : callable
        :func:`~raytrace.units.length_mm` or :func:`~raytrace.units.plane_distance_mm` (→ mm),
        :func:`~raytrace.units.image_scale` (→ N, dimensionless) or
        :func:`~raytrace.units.wavelength_nm` (→ nm).
    value : float, str or None
        The value as given: a number in the parser's default unit, or a string with a unit
        (``"2m"``, ``"12x"``, ``"0.5876um"``). None: not given.
    what : str
        The keyword's name, for the message.
    **options : bool
        Passed on to ``convert`` (``allow_inf=True`` for a distance that may be infinite).

    Returns
    -------
    float or None
        The value in the parser's unit (mm, N or nm); None when ``value`` is None.

    Raises
    ------
    DataError
        The parser's UnitError, with its message.
    """
    if value is None:
        return None
    try:
        return convert(value, what, **options)
    except UnitError as e:
        raise DataError(str(e)) from None


def _resolve_object(lens, distance, s, scale, wavelength, keys: tuple[str, str, str]) -> float:
    """The object distance of one of the setup's object keyword triples ``keys``
    (:data:`_OBJECT_KEYS` or :data:`_FOCUS_OBJECT_KEYS`), a refusal naming the keyword given."""
    from raytrace.errors import TraceError
    from raytrace.paraxial import resolve_object_distance

    key_distance, key_s, key_scale = keys
    try:
        return resolve_object_distance(
            lens,
            object_distance=_object_value(distance, key_distance),
            object_s=_in_units(length_mm, s, key_s),
            object_scale=_in_units(image_scale, scale, key_scale),
            wavelength=wavelength,
        )
    except TraceError as e:  # the words of resolve_object_distance: the object_* keywords
        own = dict(zip(_OBJECT_KEYS, keys, strict=True))
        msg = re.sub(r"\b(object_distance|object_s|object_scale)\b", lambda m: own[m[1]], str(e))
        raise DataError(f"{lens.name}: {msg}") from None


def nominal_lens(lens):
    """The centred lens whose first-order data a decentered or tilted lens is designed around
    (``Lens.nominal()`` where the lens has surface placements; the lens itself otherwise)."""
    centred = getattr(lens, "is_centred", True)
    if callable(centred):
        centred = centred()
    return lens if centred else lens.nominal()


def resolve_setup(lens, setup: CameraSetup) -> CameraGeometry:
    """Resolve ``setup`` for ``lens`` (module docstring): object plane, sensor plane (unit
    focusing at the reference wavelength), projection centre and the paraxial camera constant.
    Raises DataError for a focus or object the lens cannot image. A decentered or tilted lens
    takes these first-order quantities from its centred design (:func:`nominal_lens`)."""
    from raytrace.paraxial import paraxial, pestrecov_constants

    lens = nominal_lens(lens)

    wl_ref = float(lens.wavelength)
    wl = (
        wl_ref
        if setup.wavelength is None
        else _in_units(wavelength_nm, setup.wavelength, "wavelength")
    )
    od = _resolve_object(
        lens, setup.object_distance, setup.object_s, setup.object_scale, wl_ref, _OBJECT_KEYS
    )
    par_ref = paraxial(lens, od, wl_ref)
    focus_od: float | None = None
    if any(getattr(setup, k) is not None for k in _FOCUS_OBJECT_KEYS):
        focus_od = _resolve_object(
            lens, setup.focus, setup.focus_s, setup.focus_scale, wl_ref, _FOCUS_OBJECT_KEYS
        )
        flv = paraxial(lens, focus_od, wl_ref).gaussian_image_distance
        what = f"focused at {setup.describe_focus()}"
    elif any(getattr(setup, k) is not None for k in _PLANE_KEYS):
        kind = next(k for k in _PLANE_KEYS if getattr(setup, k) is not None)
        v = _in_units(plane_distance_mm, getattr(setup, kind), kind)
        z = {
            "s_prime": par_ref.z_from_s_prime,
            "from_last_vertex": par_ref.z_from_last_vertex,
            "defocus": par_ref.z_from_defocus,
        }[kind](v)
        flv = float(z) - par_ref.z_last
        what = f"sensor at {kind} = {v:g} mm"
    else:
        focus_od = od
        flv = par_ref.gaussian_image_distance
        what = "focused on the object"
    if not (math.isfinite(flv) and flv > 0):
        hint = ""
        f = setup.focus
        if focus_od is not None and isinstance(f, int | float) and not isinstance(f, bool):
            hint = f" (focus={f:g} is mm from the first vertex: for metres write focus='{f:g}m')"
        raise DataError(
            f"{lens.name} {what}: the sensor plane would lie {flv:g} mm from the last vertex; it "
            f"must be a finite distance behind the lens (a real image){hint}"
        )
    z = par_ref.z_from_last_vertex(flv)
    par = par_ref if wl == wl_ref else paraxial(lens, od, wl)
    k0 = pestrecov_constants(par, float(par.s_prime_of(z))).scale
    c = k0 if par.infinite else k0 * par.p0
    if not (math.isfinite(c) and c > 0):
        raise DataError(
            f"{lens.name}: the paraxial camera constant in the sensor plane is {c:g} mm; a camera "
            "model needs a real, positive principal distance (an upright or virtual image is "
            "not a camera)"
        )
    par_inf = paraxial(lens, math.inf, wl_ref)
    return CameraGeometry(
        lens_name=lens.name,
        object_distance=float(od),
        object_s=float(par_ref.s),
        focus_object_distance=None if focus_od is None else float(focus_od),
        focus=what,
        z_image=float(z),
        from_last_vertex=float(flv),
        s_prime=float(par_ref.s_prime_of(z)),
        defocus=float(z - par_ref.z_gauss),
        wavelength=float(wl),
        reference_wavelength=wl_ref,
        z_projection_centre=float(par_ref.z_E0),
        camera_constant=float(c),
        efl=float(par_inf.efl),
        magnification=float(par_ref.m0),
    )


# ---- the TOML camera spec ---------------------------------------------------------------------
_TOML = {
    "sensor": ("size", "pixels", "pitch_um", "principal_point_offset_mm"),
    "object": ("distance", "s", "scale"),
    "focus": ("distance", "s", "scale", "s_prime", "from_last_vertex", "defocus"),
    "trace": ("wavelength", "grid", "clip"),
}


def _unknown(key: str, choices, where: str) -> str:
    near = difflib.get_close_matches(key, list(choices), n=1, cutoff=0.6)
    hint = f"; did you mean {near[0]!r}?" if near else f" (keys: {', '.join(choices)})"
    return f"{where}: unknown key {key!r}{hint}"


def camera_setup_from_dict(doc: dict, where: str = "camera spec") -> CameraSetup:
    """A :class:`CameraSetup` from the tables of a TOML camera spec (module docstring)."""
    problems = []
    for k, v in doc.items():
        if k not in _TOML:
            problems.append(_unknown(k, _TOML, where))
        elif not isinstance(v, dict):
            problems.append(f"{where}: [{k}] must be a table")
        else:
            problems += [_unknown(kk, _TOML[k], f"{where} [{k}]") for kk in v if kk not in _TOML[k]]
    if "sensor" not in doc:
        problems.append(f"{where}: no [sensor] table; give size and pixels (or pitch_um)")
    if problems:
        raise DataError("; ".join(problems))
    s = doc["sensor"]
    try:
        sensor = Sensor.from_spec(
            size=s.get("size"),
            pixels=s.get("pixels"),
            pitch_um=s.get("pitch_um"),
            principal_point_offset_mm=s.get("principal_point_offset_mm", (0.0, 0.0)),
        )
    except DataError as e:
        raise DataError(f"{where} [sensor]: {e}") from None
    o, f, t = doc.get("object", {}), doc.get("focus", {}), doc.get("trace", {})
    kw = {
        "object_distance": o.get("distance"),
        "object_s": o.get("s"),
        "object_scale": o.get("scale"),
        "focus": f.get("distance"),
        "focus_s": f.get("s"),
        "focus_scale": f.get("scale"),
        "s_prime": f.get("s_prime"),
        "from_last_vertex": f.get("from_last_vertex"),
        "defocus": f.get("defocus"),
        "wavelength": t.get("wavelength"),
    }
    if "grid" in t:
        kw["grid"] = t["grid"]
    if "clip" in t:
        if not isinstance(t["clip"], bool):
            raise DataError(f"{where} [trace]: clip must be true or false")
        kw["clip"] = t["clip"]
    try:
        return CameraSetup(sensor, **kw)
    except DataError as e:
        raise DataError(f"{where}: {e}") from None


def read_camera_setup(path: str | os.PathLike) -> CameraSetup:
    """Read a TOML camera spec (module docstring) into a :class:`CameraSetup`.

    Parameters
    ----------
    path : str or os.PathLike
        The TOML file: ``[sensor]`` (``size``, ``pixels`` or ``pitch_um``,
        ``principal_point_offset_mm``) and optionally ``[object]``, ``[focus]`` and ``[trace]``
        in the words of the module docstring (mm, ``inf``, ``"2m"``, ``"12x"``; nm).

    Returns
    -------
    CameraSetup

    Raises
    ------
    DataError
        An unreadable file, invalid TOML, unknown tables or keys (with the nearest valid one), no
        ``[sensor]`` table, or values the setup refuses.
    """
    import tomllib

    p = Path(path)
    text = read_text(p, "a camera spec")
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        raise DataError(f"{p}: not valid TOML: {e}") from None
    except RecursionError:
        raise DataError(f"{p}: nested too deeply to be a camera spec") from None
    return camera_setup_from_dict(doc, str(p))


def make_setup(sensor, setup_kw: dict | None = None) -> CameraSetup:
    """A :class:`CameraSetup` from a Sensor, a CameraSetup or a TOML camera spec path, with the
    keywords of ``setup_kw`` that are not None applied (they replace what a setup holds)."""
    kw = {k: v for k, v in (setup_kw or {}).items() if v is not None}
    if isinstance(sensor, CameraSetup):
        return sensor.replace(**kw) if kw else sensor
    if isinstance(sensor, str | os.PathLike) and str(sensor).lower().endswith(".toml"):
        base = read_camera_setup(sensor)
        return base.replace(**kw) if kw else base
    if isinstance(sensor, Sensor):
        return CameraSetup(sensor, **kw)
    raise DataError(
        "sensor: give a Sensor (Sensor.from_spec(size='36x24', pixels='6000x4000')), a "
        f"CameraSetup or a camera spec .toml path, not {type(sensor).__name__}"
    )


def setup_fields() -> tuple[str, ...]:
    """The names of :class:`CameraSetup`'s fields (for keyword forwarding)."""
    return tuple(f.name for f in fields(CameraSetup))
