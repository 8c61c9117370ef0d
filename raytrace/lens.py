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
    wavelength:      design wavelength, nm.
    image_solve:     ``"gaussian"`` when the last thickness was solved to put the image plane at the
        paraxial (Gaussian) image of the file's object; ``None`` when it was given as a number.
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

    def __post_init__(self) -> None:
        validate(self)

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
    if not (math.isfinite(lens.wavelength) and 200.0 <= lens.wavelength <= 20000.0):
        raise LensError(f"{lens.name}: wavelength must be in nm (200-20000), got {lens.wavelength}")
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
