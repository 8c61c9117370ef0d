"""The validated, immutable lens model (packed into arrays for the kernels by :mod:`.packing`).

Conventions (docs/design.md, "Conventions"): millimetres; light travels toward +z; a radius is positive when its
centre of curvature lies after the vertex; ``thickness`` is the axial distance from a surface's
vertex to the next vertex (for the last surface: to the image plane the file defines). The first
vertex is at z = 0. ``Surface.material`` is the medium *after* the surface; the object space is
air unless ``Lens.object_material`` says otherwise.

Surface sag (even asphere, which contains the plane, sphere and conic as special cases)::

    z(r) = c r² / (1 + sqrt(1 - (1 + k) c² r²)) + A4 r⁴ + A6 r⁶ + ...

with ``c`` the curvature (1/mm), ``k`` the conic constant and ``aspheric = (A4, A6, ...)``.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field, replace

import numpy as np

from .errors import LensError
from .kernels.codes import KIND_ASPHERE, KIND_PLANE, KIND_QUADRIC
from .materials import AIR, LAMBDA_D, Material

@dataclass(frozen=True)
class Surface:
    """One refracting surface.

    curvature:     1/R in 1/mm (0 for a plane); positive when the centre lies after the vertex.
    thickness:     axial distance to the next vertex (mm); for the last surface, to the image plane.
    material:      the medium after the surface.
    semi_diameter: clear semi-aperture (mm); ``math.inf`` when not limited.
    stop:          True for the aperture stop (exactly one surface per lens).
    conic:         conic constant k (0 sphere, -1 paraboloid).
    aspheric:      even-asphere coefficients (A4, A6, A8, ...) of r⁴, r⁶, r⁸, ... (mm^(1-2j)).
    label:         optional name (e.g. "STO"); listings number surfaces from 1.
    line:          the line of the source file that defined it (for messages), if any.
    """

    curvature: float
    thickness: float
    material: Material = AIR
    semi_diameter: float = math.inf
    stop: bool = False
    conic: float = 0.0
    aspheric: tuple[float, ...] = ()
    label: str = ""
    line: int | None = field(default=None, compare=False)

    @property
    def radius(self) -> float:
        """Radius of curvature (mm); ``math.inf`` for a plane."""
        return math.inf if self.curvature == 0.0 else 1.0 / self.curvature

    @property
    def kind(self) -> int:
        if any(a != 0.0 for a in self.aspheric):
            return KIND_ASPHERE
        if self.curvature == 0.0:
            return KIND_PLANE
        return KIND_QUADRIC

    def __repr__(self) -> str:
        r = "inf" if self.curvature == 0.0 else f"{1.0 / self.curvature:.6g}"
        parts = [f"r={r}", f"t={self.thickness:.6g}", self.material.describe()]
        if math.isfinite(self.semi_diameter):
            parts.append(f"sd={self.semi_diameter:.6g}")
        if self.conic:
            parts.append(f"k={self.conic:.6g}")
        if any(self.aspheric):
            parts.append(f"asph={len(self.aspheric)} terms")
        if self.stop:
            parts.append("stop")
        return f"Surface({', '.join(parts)})"

    def sag(self, r: float | np.ndarray) -> float | np.ndarray:
        """Surface sag z(r) in mm (see module docstring); NaN where the quadric is undefined."""
        r2 = np.asarray(r, dtype=float) ** 2
        c, k = self.curvature, self.conic
        with np.errstate(invalid="ignore"):
            z = c * r2 / (1.0 + np.sqrt(1.0 - (1.0 + k) * c * c * r2))
        p = r2 * r2
        for a in self.aspheric:
            z = z + a * p
            p = p * r2
        return z


@dataclass(frozen=True)
class Aperture:
    """System aperture: ``kind`` is ``"fnumber"`` (infinite-conjugate f/number, EPD = EFL/N),
    ``"epd"`` (entrance-pupil diameter, mm) or ``"na"`` (object-space numerical aperture
    n·sin U of the axial marginal ray; finite objects only)."""

    kind: str
    value: float

    def __post_init__(self) -> None:
        if self.kind not in ("fnumber", "epd", "na"):
            raise ValueError(f"unknown aperture kind {self.kind!r}")


@dataclass(frozen=True)
class Field:
    """Field of view: ``kind`` ``"angle"`` (max half-field angle in degrees, the chief-ray slope
    angle α in object space) or ``"height"`` (max object height in mm, finite objects)."""

    kind: str
    value: float

    def __post_init__(self) -> None:
        if self.kind not in ("angle", "height"):
            raise ValueError(f"unknown field kind {self.kind!r}")


@dataclass(frozen=True)
class Lens:
    """A validated centred lens.

    object_distance: axial distance (mm) from the object plane to the first vertex, a *positive
        magnitude* for a real object on the left; ``math.inf`` for an object at infinity.
        (Pestrecov's signed ``s`` is measured from H and is negative: see ``raytrace.paraxial``.)
    wavelength:      the reference (primary) wavelength, nm: paraxial data, solves and every
        single-wavelength call use it unless told otherwise (``Lens.reference_wavelength``).
    image_solve:     ``"gaussian"`` when the last thickness was solved to put the image plane at the
        paraxial (Gaussian) image of the file's object (at the reference wavelength); ``None``
        when it was given as a number.
    wavelengths:     the lens's wavelengths (nm; .zmx ``WAVM``, .seq ``WL``), the reference among
        them; ``()`` means ``(wavelength,)``. weights: one per wavelength (``()`` → all 1).
    temperature_c, pressure_atm: the system environment (.zmx ``ENVD``): catalog glasses are
        evaluated relative to the air at these conditions through Schott's dn/dT model
        (:func:`raytrace.glass.thermal.index_at`); ``None`` = each catalog material at its own
        reference conditions (the vendor catalogs: 20 °C, 1 atm). Model glasses and fixed indices
        are not changed.
    """

    name: str
    surfaces: tuple[Surface, ...]
    aperture: Aperture
    field: Field
    object_distance: float = math.inf
    wavelength: float = LAMBDA_D
    source: str = ""
    notes: str = ""
    units: str = "mm"
    object_material: Material = AIR
    image_solve: str | None = None
    path: str | None = field(default=None, compare=False)
    wavelengths: tuple[float, ...] = ()
    weights: tuple[float, ...] = ()
    temperature_c: float | None = None
    pressure_atm: float | None = None

    def __post_init__(self) -> None:
        _normalize_wavelengths(self)
        validate(self)

    def __repr__(self) -> str:
        ap = {"fnumber": "f/{:g}", "epd": "EPD {:g} mm", "na": "NA {:g}"}[self.aperture.kind]
        fld = "{:g} deg" if self.field.kind == "angle" else "{:g} mm"
        obj = (
            "object at infinity"
            if math.isinf(self.object_distance)
            else f"object {self.object_distance:g} mm"
        )
        return (
            f"Lens({self.name!r}: {self.n_surfaces} surfaces, stop {self.stop_index + 1}, "
            f"{ap.format(self.aperture.value)}, field {fld.format(self.field.value)}, {obj})"
        )

    def __str__(self) -> str:
        from .listing import format_prescription

        return format_prescription(self)

    def _repr_html_(self) -> str:
        from .listing import html_prescription

        return html_prescription(self)

    @property
    def stop_index(self) -> int:
        """0-based index of the stop surface."""
        return next(i for i, s in enumerate(self.surfaces) if s.stop)

    @property
    def n_surfaces(self) -> int:
        return len(self.surfaces)

    @property
    def vertex_z(self) -> np.ndarray:
        """Vertex positions (mm), first vertex at 0."""
        t = [0.0] + [s.thickness for s in self.surfaces[:-1]]
        return np.cumsum(t)

    @property
    def length(self) -> float:
        """First to last vertex (mm)."""
        return float(sum(s.thickness for s in self.surfaces[:-1]))

    @property
    def image_z(self) -> float:
        """z of the image plane the file defines (last vertex + last thickness)."""
        return self.length + self.surfaces[-1].thickness

    @property
    def image_material(self) -> Material:
        return self.surfaces[-1].material

    @property
    def reference_wavelength(self) -> float:
        """The reference (primary) wavelength, nm (= ``wavelength``)."""
        return self.wavelength

    @property
    def environment(self) -> tuple[float, float] | None:
        """(temperature °C, pressure atm) the lens states, or None (catalog conditions)."""
        if self.temperature_c is None and self.pressure_atm is None:
            return None
        t = 20.0 if self.temperature_c is None else float(self.temperature_c)
        p = 1.0 if self.pressure_atm is None else float(self.pressure_atm)
        return t, p

    def with_wavelengths(
        self,
        wavelengths,
        weights=None,
        reference: float | None = None,
    ) -> Lens:
        """A copy with other wavelengths (nm), weights (default all 1) and reference wavelength
        (default: the current reference if it is among them, else the first)."""
        wl = tuple(float(w) for w in np.atleast_1d(np.asarray(wavelengths, dtype=float)))
        if not wl:
            raise LensError(f"{self.name}: give at least one wavelength")
        ref = reference
        if ref is None:
            ref = self.wavelength if self.wavelength in wl else wl[0]
        w = () if weights is None else tuple(float(x) for x in weights)
        return replace(self, wavelengths=wl, weights=w, wavelength=float(ref))

    def _out_of_range(self, m: Material, wl: np.ndarray, j: int, env) -> np.ndarray:
        """The index of a catalog glass evaluated outside its data range, with the material's
        warning (or strict error) repeated with the lens file and surface in front."""
        import warnings

        from .materials import OutOfRangeError, OutOfRangeWarning

        where = f"{self.path or self.name}: " + ("object space" if j == 0 else f"surface {j}")
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", OutOfRangeWarning)
            try:
                n = _index(m, wl, env)
            except OutOfRangeError as e:
                raise OutOfRangeError(f"{where}: {e}") from None
        for w in caught:
            if issubclass(w.category, OutOfRangeWarning):
                warnings.warn(f"{where}: {w.message}", OutOfRangeWarning, stacklevel=4)
            else:
                warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
        return n

    def indices(self, wavelengths=None) -> np.ndarray:
        """Refractive indices at ``wavelengths`` (nm; a number or a sequence; default the
        reference wavelength): array (n_wavelengths, n_surfaces + 1) — column 0 the object space,
        column j + 1 the medium after surface j. The one place indices of a lens are computed
        (packing and paraxial optics use it). Catalog glasses are relative to the air of the
        lens's environment (``temperature_c``, ``pressure_atm``; see the class docstring)."""
        if wavelengths is None:
            key: tuple[float, ...] = (self.wavelength,)
        elif isinstance(wavelengths, float | int):
            key = (float(wavelengths),)
        else:
            key = tuple(float(w) for w in np.atleast_1d(np.asarray(wavelengths, dtype=float)))
        lo, hi = _catalog_span(self)
        if all(lo <= w <= hi for w in key):
            return _indices(self, key)
        return _indices.__wrapped__(self, key)  # out of a glass's range: warn every time

    def with_image_distance(self, thickness: float) -> Lens:
        """A copy whose last thickness (last vertex to image plane) is ``thickness``."""
        s = list(self.surfaces)
        s[-1] = replace(s[-1], thickness=float(thickness))
        return replace(self, surfaces=tuple(s), image_solve=None)

    def with_object_distance(self, distance: float) -> Lens:
        """A copy with another object distance (positive magnitude from the first vertex; inf)."""
        return replace(self, object_distance=float(distance))

    def scaled(self, factor: float) -> Lens:
        """All lengths multiplied by ``factor`` (curvatures divided; aspheric terms scaled so the
        sag scales too). Field heights and EPD scale; angles and f-numbers do not."""
        if not (math.isfinite(factor) and factor > 0.0):
            raise LensError(f"scale factor must be positive and finite, got {factor}")
        surfaces = tuple(
            replace(
                s,
                curvature=s.curvature / factor,
                thickness=s.thickness * factor,
                semi_diameter=s.semi_diameter * factor,
                aspheric=tuple(a * factor ** (1 - 2 * (j + 2)) for j, a in enumerate(s.aspheric)),
            )
            for s in self.surfaces
        )
        ap = self.aperture
        if ap.kind == "epd":
            ap = Aperture("epd", ap.value * factor)
        fld = self.field
        if fld.kind == "height":
            fld = Field("height", fld.value * factor)
        return replace(
            self,
            surfaces=surfaces,
            aperture=ap,
            field=fld,
            object_distance=self.object_distance * factor,
        )


@functools.lru_cache(maxsize=512)
def _catalog_span(lens: Lens) -> tuple[float, float]:
    """The wavelength span (nm) inside every catalog glass's data range (cached per lens)."""
    lo, hi = 0.0, math.inf
    for m in (lens.object_material, *(s.material for s in lens.surfaces)):
        if m.kind == "catalog":
            lo, hi = max(lo, m.wavelength_range_nm[0]), min(hi, m.wavelength_range_nm[1])
    return lo, hi


@functools.lru_cache(maxsize=512)
def _indices(lens: Lens, wavelengths: tuple[float, ...]) -> np.ndarray:
    """:meth:`Lens.indices` for a tuple of wavelengths (nm), cached per lens (read-only)."""
    from .units import wavelength_nm

    wl = np.array([wavelength_nm(w) for w in wavelengths])
    env = lens.environment
    mats = [lens.object_material, *(s.material for s in lens.surfaces)]
    out = np.empty((wl.size, len(mats)))
    done: dict[Material, np.ndarray] = {}
    for j, m in enumerate(mats):
        n = done.get(m)
        if n is None:
            if m.kind == "catalog" and not m.in_range(wl):
                n = lens._out_of_range(m, wl, j, env)
            else:
                n = _index(m, wl, env)
            done[m] = n
        out[:, j] = n
    out.flags.writeable = False
    return out


def _index(m: Material, wl: np.ndarray, env: tuple[float, float] | None) -> np.ndarray:
    """Index of ``m`` at ``wl`` (nm), relative to the air of ``env`` (°C, atm) when given."""
    if env is not None and m.kind == "catalog":
        from .glass.thermal import index_at

        return np.asarray(index_at(m, wl, env[0], env[1]), dtype=float)
    return np.asarray(m.index(wl), dtype=float)


def _normalize_wavelengths(lens: Lens) -> None:
    """``wavelengths=()`` → ``(wavelength,)``; ``weights=()`` → all 1; numbers as floats."""
    wl = tuple(float(w) for w in lens.wavelengths) or (float(lens.wavelength),)
    w = tuple(float(x) for x in lens.weights) or (1.0,) * len(wl)
    object.__setattr__(lens, "wavelengths", wl)
    object.__setattr__(lens, "weights", w)


def validate(lens: Lens) -> None:
    """Check what a lens needs to be traceable; raise :class:`LensError` naming the surface."""
    if not lens.surfaces:
        raise LensError(f"{lens.name}: the lens has no surfaces")
    stops = [i for i, s in enumerate(lens.surfaces) if s.stop]
    if len(stops) != 1:
        which = ", ".join(str(i + 1) for i in stops) if stops else "none"
        raise LensError(f"{lens.name}: exactly one surface must be the stop (found: {which})")
    for i, s in enumerate(lens.surfaces, start=1):
        for name in ("curvature", "thickness", "conic"):
            v = getattr(s, name)
            if not math.isfinite(v):
                raise LensError(f"{lens.name}: surface {i}: {name} must be finite, got {v}")
        if any(not math.isfinite(a) for a in s.aspheric):
            raise LensError(f"{lens.name}: surface {i}: aspheric coefficients must be finite")
        if not (s.semi_diameter > 0.0):
            raise LensError(
                f"{lens.name}: surface {i}: semi-diameter must be positive, got {s.semi_diameter}"
            )
        if i < len(lens.surfaces) and s.thickness < 0.0 and not s.material.is_air:
            raise LensError(
                f"{lens.name}: surface {i}: glass thickness must not be negative, got {s.thickness}"
            )
    if not (lens.object_distance > 0.0):
        raise LensError(
            f"{lens.name}: object distance must be positive (a magnitude from the object plane to "
            f"the first vertex) or inf, got {lens.object_distance}"
        )
    from .units import UnitError, wavelength_nm

    try:
        for w in (lens.wavelength, *lens.wavelengths):
            wavelength_nm(w)
    except UnitError as e:
        raise LensError(f"{lens.name}: {e}") from None
    if lens.wavelength not in lens.wavelengths:
        raise LensError(
            f"{lens.name}: the reference wavelength {lens.wavelength:g} nm is not among the "
            f"wavelengths {', '.join(f'{w:g}' for w in lens.wavelengths)} nm; use "
            "lens.with_wavelengths(...) to change them together"
        )
    if len(lens.weights) != len(lens.wavelengths) or not all(
        math.isfinite(w) and w >= 0.0 for w in lens.weights
    ):
        raise LensError(
            f"{lens.name}: give one non-negative weight per wavelength "
            f"({len(lens.wavelengths)} wavelengths, {len(lens.weights)} weights)"
        )
    for what in ("temperature_c", "pressure_atm"):
        v = getattr(lens, what)
        if v is not None and not math.isfinite(v):
            raise LensError(f"{lens.name}: {what} must be a finite number or None, got {v}")
    if lens.pressure_atm is not None and lens.pressure_atm < 0.0:
        raise LensError(f"{lens.name}: pressure_atm must not be negative, got {lens.pressure_atm}")
    if not (math.isfinite(lens.aperture.value) and lens.aperture.value > 0.0):
        raise LensError(f"{lens.name}: aperture {lens.aperture.kind} must be positive")
    if lens.aperture.kind == "na" and not math.isfinite(lens.object_distance):
        raise LensError(f"{lens.name}: an object-space NA needs a finite object distance")
    if not (math.isfinite(lens.field.value) and lens.field.value >= 0.0):
        raise LensError(f"{lens.name}: field {lens.field.kind} must be a non-negative number")
    if lens.field.kind == "angle" and lens.field.value >= 90.0:
        raise LensError(f"{lens.name}: field angle must be below 90 degrees")
    if lens.field.kind == "height" and not math.isfinite(lens.object_distance):
        raise LensError(f"{lens.name}: an object-height field needs a finite object distance")
    check_physical(lens)


def check_file_lens(lens: Lens) -> None:
    """What a lens FILE may not hold, whatever its format (every reader calls this after building
    the lens; a lens built in Python may be an idealisation, such as a thin lens of zero
    thickness): glass of zero or negative centre thickness. Raises :class:`LensError` naming the
    surface."""
    for i, s in enumerate(lens.surfaces[:-1], start=1):
        if s.thickness <= 0.0 and not s.material.is_air:
            raise LensError(
                f"{lens.name}: surface {i}: the glass after it has thickness {s.thickness:g} mm; "
                "give its centre thickness (a positive number of mm)"
            )


def check_physical(lens: Lens) -> None:
    """What no lens may be, however it was made (checked on construction): a refractive index
    below 1, a semi-diameter beyond the surface's sag (|sd| ≥ |R| for a sphere), and consecutive
    surfaces that cross inside their semi-diameters. Raises :class:`LensError` naming the surface
    (1-based) and the fix."""
    n = len(lens.surfaces)
    for i, s in enumerate(lens.surfaces, start=1):
        m = s.material
        if m.kind in ("index", "model") and m.nd < 1.0:
            raise LensError(
                f"{lens.name}: surface {i}: refractive index {m.nd:g} is below 1; give the index "
                "of the medium after the surface (air is 1)"
            )
        if math.isfinite(s.semi_diameter) and s.curvature != 0.0:
            if 1.0 - (1.0 + s.conic) * (s.curvature * s.semi_diameter) ** 2 <= 0.0:
                raise LensError(
                    f"{lens.name}: surface {i}: semi-diameter {s.semi_diameter:g} mm reaches "
                    f"beyond the surface (radius {s.radius:g} mm, conic {s.conic:g}); reduce sd"
                )
    for i in range(n - 1):
        a, b = lens.surfaces[i], lens.surfaces[i + 1]
        if not (math.isfinite(a.semi_diameter) and math.isfinite(b.semi_diameter)):
            continue
        h = np.linspace(0.0, min(a.semi_diameter, b.semi_diameter), 33)
        gap = a.thickness + b.sag(h) - a.sag(h)
        j = int(np.argmin(gap))
        if gap[j] < 0.0:
            raise LensError(
                f"{lens.name}: surface {i + 1}: surfaces {i + 1} and {i + 2} cross inside their "
                f"semi-diameters (axial gap {gap[j]:.6g} mm at height {h[j]:.6g} mm); increase "
                "the thickness or reduce the semi-diameters"
            )
