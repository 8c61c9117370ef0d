"""The validated, immutable lens model (packed into arrays for the kernels by :mod:`.packing`).

Conventions (docs/design.md, "Conventions"): millimetres; light travels toward +z; a radius is
positive when its centre of curvature lies after the vertex; ``thickness`` is the axial distance
from a surface's vertex to the next vertex (for the last surface: to the image plane the file
defines). The first vertex is at z = 0. ``Surface.material`` is the medium *after* the surface;
the object space is air unless ``Lens.object_material`` says otherwise.

Surface sag (even asphere, which contains the plane, sphere and conic as special cases)::

    z(r) = c r² / (1 + sqrt(1 - (1 + k) c² r²)) + A4 r⁴ + A6 r⁶ + ...

with ``c`` the curvature (1/mm), ``k`` the conic constant and ``aspheric = (A4, A6, ...)``. A
Forbes Q-type surface (``Surface.qtype``, :mod:`.qtype`) adds its polynomial departure to the
base conic (c, k) instead; its paraxial curvature is ``Surface.vertex_curvature``.
"""

from __future__ import annotations

import functools
import math
import os
from dataclasses import dataclass, field, fields, replace

import numpy as np

from .errors import LensError
from .frames import AFTER_MODES, Placement
from .kernels.codes import KIND_ASPHERE, KIND_PLANE, KIND_QBFS, KIND_QCON, KIND_QUADRIC
from .materials import AIR, LAMBDA_D, Material
from .qtype import QType, departure, vertex_curvature
from .units import real_number

#: shapes of a :class:`ClearAperture`
APERTURE_SHAPES = ("circle", "rectangle", "ellipse")


@dataclass(frozen=True)
class ClearAperture:
    """A hard clear aperture of a surface (rays outside it are vignetted, status CLIPPED), in
    the surface's own frame (:mod:`raytrace.frames`), in addition to ``Surface.semi_diameter``.

    shape:          ``"circle"`` (radius ``half_x``; ``half_y`` equal to it), ``"rectangle"``
                    (half-widths ``half_x``, ``half_y``; Zemax ``SQAP``, CODE V ``REX``/``REY``)
                    or ``"ellipse"`` (semi-axes; Zemax ``ELAP``, CODE V ``ELX``/``ELY``).
    half_x, half_y: mm (> 0).
    x0, y0:         the aperture's centre in the surface frame, mm (Zemax ``OBDC``, CODE V
                    ``ADX``/``ADY``): an off-axis section of a parent surface.
    """

    shape: str
    half_x: float
    half_y: float
    x0: float = 0.0
    y0: float = 0.0

    def __post_init__(self) -> None:
        if self.shape not in APERTURE_SHAPES:
            raise ValueError(
                f"clear aperture shape must be one of {', '.join(APERTURE_SHAPES)}, "
                f"got {self.shape!r}"
            )
        for name in ("half_x", "half_y", "x0", "y0"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(v):
                raise ValueError(f"clear aperture {name} must be a finite number, got {v!r}")
            object.__setattr__(self, name, float(v) + 0.0)
        if not (self.half_x > 0.0 and self.half_y > 0.0):
            raise ValueError(
                f"clear aperture half-widths must be positive, got {self.half_x}, {self.half_y}"
            )
        if self.shape == "circle" and self.half_x != self.half_y:
            raise ValueError("a circular clear aperture has half_x == half_y (its radius)")

    @property
    def code(self) -> int:
        """1 circle, 2 rectangle, 3 ellipse (the kernels' code)."""
        return APERTURE_SHAPES.index(self.shape) + 1

    def contains(self, x, y):
        """Whether local points (x, y) lie inside (on the edge counts as inside)."""
        u = (np.asarray(x, dtype=float) - self.x0) / self.half_x
        v = (np.asarray(y, dtype=float) - self.y0) / self.half_y
        if self.shape == "rectangle":
            return (np.abs(u) <= 1.0) & (np.abs(v) <= 1.0)
        return u * u + v * v <= 1.0

    @property
    def reach(self) -> float:
        """Largest distance of an aperture point from the vertex (mm)."""
        if self.shape == "rectangle":
            return math.hypot(abs(self.x0) + self.half_x, abs(self.y0) + self.half_y)
        return math.hypot(self.x0, self.y0) + max(self.half_x, self.half_y)

    def describe(self) -> str:
        off = f" at ({self.x0:g}, {self.y0:g})" if (self.x0 or self.y0) else ""
        if self.shape == "circle":
            return f"circle r {self.half_x:g}{off}"
        return f"{self.shape} {self.half_x:g} x {self.half_y:g}{off}"


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

    Placement and mirrors (:mod:`raytrace.frames` states every convention and its source):

    placement:     :class:`~raytrace.frames.Placement` moving the surface's frame from the frame
                   the light arrives in (decenter, then tilts; or tilts, then decenter); None =
                   on the axis.
    after:         the frame the thickness runs in after the surface: ``"stay"`` (the surface's
                   frame; Zemax coordinate break, CODE V basic decenter), ``"return"`` (the
                   arrival frame; CODE V ``DAR``, Zemax tilt/decenter *reverse*), ``"bend"``
                   (the placement's rotation once more; CODE V ``BEN``) or a Placement (Zemax
                   tilt/decenter after the surface; CODE V ``REV`` is ``placement=None`` with the
                   inverse move here).
    mirror:        a reflecting surface (Zemax ``GLAS MIRROR``, CODE V ``REFL``): ``material``
                   is the medium the light returns into (the one before the mirror); thicknesses
                   after an odd number of mirrors are negative, as in both programs.
    coordinate_break: a Zemax ``COORDBRK``: not traced, only its placement and thickness count
                   (curvature 0, no aperture, the medium continues).
    aperture:      an extra hard :class:`ClearAperture` (rectangle, ellipse, off-axis circle) in
                   the surface frame; None = only ``semi_diameter``.
    qtype:         Forbes Q-type terms (:class:`raytrace.qtype.QType`: Qbfs or Qcon, ρ_max, a_m;
                   Zemax ``QED_TYPE``) added to the base conic ``curvature`` / ``conic``; None =
                   none. Not together with ``aspheric``.
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
    placement: Placement | None = None
    after: Placement | str = "stay"
    mirror: bool = False
    coordinate_break: bool = False
    aperture: ClearAperture | None = None
    qtype: QType | None = None

    def __post_init__(self) -> None:
        if (
            self.placement is None
            and self.after == "stay"
            and self.aperture is None
            and self.mirror is False
            and self.coordinate_break is False
            and self.qtype is None
        ):
            return  # a surface on the axis (the common case): nothing to check
        if self.qtype is not None and not isinstance(self.qtype, QType):
            raise ValueError(f"qtype must be a QType or None, got {type(self.qtype).__name__}")
        p = self.placement
        if p is not None and not isinstance(p, Placement):
            raise ValueError(f"placement must be a Placement or None, got {type(p).__name__}")
        if p is not None and p.is_identity:
            object.__setattr__(self, "placement", None)
        a = self.after
        if isinstance(a, Placement):
            if a.is_identity:
                object.__setattr__(self, "after", "stay")
        elif a not in AFTER_MODES:
            raise ValueError(
                f"after must be one of {', '.join(AFTER_MODES)} or a Placement, got {a!r}"
            )
        if self.aperture is not None and not isinstance(self.aperture, ClearAperture):
            raise ValueError(
                f"aperture must be a ClearAperture or None, got {type(self.aperture).__name__}"
            )
        for name in ("mirror", "coordinate_break"):
            if not isinstance(getattr(self, name), bool):
                raise ValueError(f"{name} must be True or False, got {getattr(self, name)!r}")

    @property
    def is_placed(self) -> bool:
        """True when the surface moves the frame: a placement, or a move after it (``"return"``
        and ``"bend"`` without a placement change nothing)."""
        return self.placement is not None or isinstance(self.after, Placement)

    @property
    def radius(self) -> float:
        """Radius of curvature (mm); ``math.inf`` for a plane."""
        return math.inf if self.curvature == 0.0 else 1.0 / self.curvature

    @property
    def vertex_curvature(self) -> float:
        """The paraxial curvature at the vertex (1/mm): ``curvature``, except for a Qbfs surface
        (:func:`raytrace.qtype.vertex_curvature`)."""
        if self.qtype is None:
            return self.curvature
        return vertex_curvature(self.qtype, self.curvature)

    @property
    def kind(self) -> int:
        """The kernels' surface kind (:mod:`raytrace.kernels.codes`); a Q-type surface whose
        terms are all 0 is its base conic (KIND_QUADRIC / KIND_PLANE)."""
        q = self.qtype
        if q is not None and not q.is_zero:
            return KIND_QBFS if q.form == "qbfs" else KIND_QCON
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
        if self.qtype is not None:
            parts.append(f"{self.qtype.form} {len(self.qtype.terms)} terms")
        if self.stop:
            parts.append("stop")
        if self.mirror:
            parts.append("mirror")
        if self.coordinate_break:
            parts.append("coordinate break")
        if self.placement is not None:
            parts.append(self.placement.describe())
        if self.after != "stay":
            a = self.after
            parts.append("after " + (a.describe() if isinstance(a, Placement) else a))
        if self.aperture is not None:
            parts.append("aperture " + self.aperture.describe())
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
        if self.qtype is not None and not self.qtype.is_zero:
            z = z + departure(self.qtype, c, k, r)
        return z


#: aperture kinds (:class:`Aperture`) and how listings show them
APERTURE_KINDS = {
    "fnumber": "f/{:g}",
    "epd": "EPD {:g} mm",
    "na": "NA {:g}",
    "float": "float by stop size (stop semi-diameter {:g} mm)",
    "working_fnumber": "working f/{:g}",
    "cone_angle": "object cone angle {:g} deg",
}


@dataclass(frozen=True)
class Aperture:
    """System aperture (the one conversion to an entrance-pupil diameter is
    :func:`raytrace.paraxial.firstorder.entrance_pupil_diameter`):

    - ``"fnumber"``: infinite-conjugate f/number N, EPD = EFL/N (Zemax ``FNUM x 0`` image-space
      F/#, CODE V ``FNO``);
    - ``"epd"``: entrance-pupil diameter, mm (Zemax ``ENPD``, CODE V ``EPD``);
    - ``"na"``: object-space numerical aperture n·sin U of the axial marginal ray, finite objects
      (Zemax ``OBNA x 0``, CODE V ``NAO``);
    - ``"float"``: float by stop size (Zemax ``FLOA``): the pupil is as large as the stop lets
      the paraxial marginal ray be; ``value`` is the stop's semi-diameter (mm);
    - ``"working_fnumber"``: paraxial working F/# ``1/(2 |n' u'|)`` of the axial marginal ray in
      image space (Zemax ``FNUM x 1``, "Paraxial Working F/#");
    - ``"cone_angle"``: object cone angle, the half angle U (degrees) of the axial marginal ray in
      object space, finite objects (Zemax ``OBNA x 1``, "Object Cone Angle").
    """

    kind: str
    value: float

    def __post_init__(self) -> None:
        if self.kind not in APERTURE_KINDS:
            raise ValueError(f"unknown aperture kind {self.kind!r}")
        v = real_number(self.value, f"aperture {self.kind}", "a number", error=ValueError)
        object.__setattr__(self, "value", v)  # a bool or a complex number is refused

    def describe(self) -> str:
        """E.g. ``f/4``, ``EPD 10 mm``, ``NA 0.1``."""
        return APERTURE_KINDS[self.kind].format(self.value)


#: image-space field specifications a reader turns into an object-space field
IMAGE_FIELDS = ("paraxial_image_height", "real_image_height")


@dataclass(frozen=True)
class Field:
    """Field of view: ``kind`` ``"angle"`` (max half-field angle in degrees, the chief-ray slope
    angle α in object space) or ``"height"`` (max object height in mm, finite objects).

    points: the field points of the file, ``(x, y)`` pairs in the field's unit (degrees: the
        direction tangents' angles αx, αy of :func:`raytrace.trace.chief_rays_2d`; mm: object
        coordinates); ``()`` when only the maximum is known. ``value`` is the largest radial one.
    given:  when the file gave the field in image space (Zemax ``FTYP 2/3``, CODE V ``YIM`` /
        ``YRI``): ``(kind, height_mm)`` with kind ``"paraxial_image_height"`` or
        ``"real_image_height"`` — ``value`` is then the object-space field that gives that image
        height (paraxial chief ray in the paraxial image plane, or the real chief ray on the
        file's image surface, :func:`raytrace.trace.field_for_image_height`), so that every
        consumer sees an object-space field, and writers can write the original back.
    """

    kind: str
    value: float
    points: tuple[tuple[float, float], ...] = ()
    given: tuple[str, float] | None = None

    def __post_init__(self) -> None:
        if self.kind not in ("angle", "height"):
            raise ValueError(f"unknown field kind {self.kind!r}")
        v = real_number(self.value, f"field {self.kind}", "a number", error=ValueError)
        object.__setattr__(self, "value", v)  # a bool or a complex number is refused
        pts = tuple((float(a) + 0.0, float(b) + 0.0) for a, b in self.points)
        if not all(math.isfinite(v) for p in pts for v in p):
            raise ValueError("field points must be finite numbers")
        object.__setattr__(self, "points", pts)
        if self.given is not None:
            k, v = self.given
            if k not in IMAGE_FIELDS or not math.isfinite(float(v)):
                raise ValueError(f"given: expected (one of {IMAGE_FIELDS}, mm), got {self.given!r}")
            object.__setattr__(self, "given", (k, float(v)))

    def describe(self) -> str:
        """E.g. ``20 deg``, ``5 mm``, ``21.6 mm real image height (20.3 deg)``."""
        unit = "deg" if self.kind == "angle" else "mm"
        if self.given is None:
            return f"{self.value:g} {unit}"
        k, v = self.given
        return f"{v:g} mm {k.replace('_', ' ')} ({self.value:.6g} {unit})"


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
    image_placement: decenter / tilt of the image surface (:class:`raytrace.frames.Placement`),
        None = perpendicular to the axis the light leaves the last surface on. Final ray segments
        are reported in the image frame (:mod:`raytrace.frames`): image planes are ``z = const``
        there, and for a centred lens it is the global frame.

    Surfaces may be decentered, tilted, coordinate breaks and mirrors (``Surface.placement``,
    ``after``, ``mirror``, ``coordinate_break``; :mod:`raytrace.frames`). A lens with none of
    them (or only mirrors on the axis) is *centred* (:attr:`is_centred`): first-order optics
    (:mod:`raytrace.paraxial`) need that; :meth:`nominal` is the lens without its moves.
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
    image_placement: Placement | None = None

    def __post_init__(self) -> None:
        _normalize_wavelengths(self)
        p = self.image_placement
        if p is not None and not isinstance(p, Placement):
            raise LensError(
                f"{self.name}: image_placement must be a Placement or None, got {type(p).__name__}"
            )
        if p is not None and p.is_identity:
            object.__setattr__(self, "image_placement", None)
        validate(self)

    def __hash__(self) -> int:
        """The hash ``dataclass`` would generate (the compared fields), computed once: a lens
        keys several caches (packing, indices, the aim set-up), and hashing every surface again
        on each call cost about 10 µs per chief-ray call. Not pickled (``str`` hashes differ
        between processes)."""
        h = self.__dict__.get("_hash")
        if h is None:
            h = hash(tuple(getattr(self, f.name) for f in fields(self) if f.compare))
            object.__setattr__(self, "_hash", h)
        return h

    def __getstate__(self) -> dict:
        state = dict(self.__dict__)
        state.pop("_hash", None)
        return state

    def __repr__(self) -> str:
        obj = (
            "object at infinity"
            if math.isinf(self.object_distance)
            else f"object {self.object_distance:g} mm"
        )
        return (
            f"Lens({self.name!r}: {self.n_surfaces} surfaces, stop {self.stop_index + 1}, "
            f"{self.aperture.describe()}, field {self.field.describe()}, {obj})"
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
    def is_centred(self) -> bool:
        """True when no surface (nor the image surface) is decentered or tilted and no clear
        aperture is off the axis: the lens is rotationally symmetric about the z axis (mirrors on
        the axis allowed; rectangular apertures do not count, they only vignette)."""
        return self.image_placement is None and not any(
            s.is_placed or (s.aperture is not None and (s.aperture.x0 or s.aperture.y0))
            for s in self.surfaces
        )

    @property
    def has_mirrors(self) -> bool:
        """True when any surface reflects."""
        return any(s.mirror for s in self.surfaces)

    @property
    def image_direction(self) -> float:
        """+1, or −1 after an odd number of mirrors: the sign of the image-space axis direction
        along z (and of a real image distance from the last vertex)."""
        return -1.0 if sum(s.mirror for s in self.surfaces) % 2 else 1.0

    def first_placed(self) -> int | None:
        """1-based number of the first surface that is decentered or tilted (0 for the image
        surface), or None for a centred lens."""
        for i, s in enumerate(self.surfaces, start=1):
            if s.is_placed or (s.aperture is not None and (s.aperture.x0 or s.aperture.y0)):
                return i
        return 0 if self.image_placement is not None else None

    def nominal(self) -> Lens:
        """The lens with every decenter and tilt removed (placements, moves after surfaces,
        the image surface's placement and aperture offsets): the centred system the moves are
        applied to. Mirrors, coordinate-break surfaces (now doing nothing) and thicknesses stay,
        so the surface numbers are the same."""
        if self.is_centred:
            return self
        ss = tuple(
            replace(
                s,
                placement=None,
                after="stay",
                aperture=None if s.aperture is None else replace(s.aperture, x0=0.0, y0=0.0),
            )
            for s in self.surfaces
        )
        return replace(self, surfaces=ss, image_placement=None)

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
        """The index of a catalog glass evaluated outside its data range (a model glass outside
        :data:`~raytrace.materials.MODEL_RANGE_NM`), with the material's warning (or strict
        error) repeated with the lens file and surface in front."""
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

    def _valid_span(self) -> tuple[float, float]:
        """:meth:`catalog_span` narrowed by the span of the model glasses of the lens
        (:data:`raytrace.materials.MODEL_RANGE_NM`): where no index of the lens warns."""
        lo, hi = self.catalog_span()
        for m in (self.object_material, *(s.material for s in self.surfaces)):
            if m.kind == "model":
                lo, hi = max(lo, m.valid_range_nm[0]), min(hi, m.valid_range_nm[1])
        return lo, hi

    def catalog_span(self) -> tuple[float, float]:
        """The wavelengths (nm) inside the data range of every catalog glass of the lens (object
        space included): (lo, hi); (0, inf) when it has no catalog glass. Indices outside it are
        extrapolations of a vendor formula (:meth:`indices` warns)."""
        lo, hi = 0.0, math.inf
        for m in (self.object_material, *(s.material for s in self.surfaces)):
            if m.kind == "catalog":
                lo, hi = max(lo, m.wavelength_range_nm[0]), min(hi, m.wavelength_range_nm[1])
        return lo, hi

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
        lo, hi = self._valid_span()
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
                qtype=None if s.qtype is None else s.qtype.scaled(factor),
                placement=_scaled_placement(s.placement, factor),
                after=_scaled_placement(s.after, factor),
                aperture=None
                if s.aperture is None
                else replace(
                    s.aperture,
                    half_x=s.aperture.half_x * factor,
                    half_y=s.aperture.half_y * factor,
                    x0=s.aperture.x0 * factor,
                    y0=s.aperture.y0 * factor,
                ),
            )
            for s in self.surfaces
        )
        ap = self.aperture
        if ap.kind in ("epd", "float"):
            ap = Aperture(ap.kind, ap.value * factor)
        fld = self.field
        given = None if fld.given is None else (fld.given[0], fld.given[1] * factor)
        if fld.kind == "height":
            pts = tuple((a * factor, b * factor) for a, b in fld.points)
            fld = Field("height", fld.value * factor, pts, given)
        elif given is not None:
            fld = replace(fld, given=given)
        return replace(
            self,
            surfaces=surfaces,
            aperture=ap,
            field=fld,
            object_distance=self.object_distance * factor,
            image_placement=_scaled_placement(self.image_placement, factor),
        )


def _scaled_placement(p, factor: float):
    """A placement with its decenter scaled (tilts are angles); strings and None unchanged."""
    if not isinstance(p, Placement):
        return p
    return replace(p, decenter=tuple(v * factor for v in p.decenter))


def require_lens(lens, what: str = "lens") -> Lens:
    """``lens`` when it is a :class:`Lens`; else a TypeError naming ``what`` and how to get one
    (a name or path is loaded with ``load_lens``, not passed as it is)."""
    if isinstance(lens, Lens):
        return lens
    hint = (
        f": load it first, e.g. {what} = osc.load_lens({lens!r})"
        if isinstance(lens, str | os.PathLike)
        else ""
    )
    raise TypeError(f"{what} must be a Lens, not {type(lens).__name__}{hint}")


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
            if m.kind in ("catalog", "model") and not m.in_range(wl):
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
    mirrors = 0
    for i, s in enumerate(lens.surfaces, start=1):
        for name in ("curvature", "thickness", "conic"):
            v = getattr(s, name)
            if not math.isfinite(v):
                raise LensError(f"{lens.name}: surface {i}: {name} must be finite, got {v}")
        if any(not math.isfinite(a) for a in s.aspheric):
            raise LensError(f"{lens.name}: surface {i}: aspheric coefficients must be finite")
        if s.qtype is not None and any(s.aspheric):
            raise LensError(
                f"{lens.name}: surface {i}: a Q-type surface has no even-asphere terms; give "
                "either qtype or aspheric"
            )
        if not (s.semi_diameter > 0.0):
            raise LensError(
                f"{lens.name}: surface {i}: semi-diameter must be positive, got {s.semi_diameter}"
            )
        if s.mirror:
            mirrors += 1
        direction = -1.0 if mirrors % 2 else 1.0
        if i < len(lens.surfaces) and s.thickness * direction < 0.0 and not s.material.is_air:
            if mirrors == 0:
                raise LensError(
                    f"{lens.name}: surface {i}: glass thickness must not be negative, got "
                    f"{s.thickness}"
                )
            raise LensError(
                f"{lens.name}: surface {i}: glass thickness {s.thickness:g} has the wrong sign: "
                f"after {mirrors} mirror(s) the light travels toward "
                f"{'-' if direction < 0 else '+'}z, so thicknesses are "
                f"{'negative' if direction < 0 else 'positive'} (as in Zemax and CODE V)"
            )
        medium_before = lens.object_material if i == 1 else lens.surfaces[i - 2].material
        if (s.mirror or s.coordinate_break) and s.material != medium_before:
            what = "a mirror" if s.mirror else "a coordinate break"
            raise LensError(
                f"{lens.name}: surface {i} is {what}: the medium after it must be the one before "
                f"it ({medium_before.describe()}), got {s.material.describe()}"
            )
        if s.coordinate_break:
            if (
                s.mirror
                or s.stop
                or s.curvature != 0.0
                or any(s.aspheric)
                or s.conic
                or s.qtype is not None
            ):
                raise LensError(
                    f"{lens.name}: surface {i} is a coordinate break: it cannot be curved, a "
                    "mirror or the stop (it is not traced)"
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
    if lens.aperture.kind in ("na", "cone_angle") and not math.isfinite(lens.object_distance):
        raise LensError(f"{lens.name}: an object-space NA needs a finite object distance")
    if lens.aperture.kind == "cone_angle" and not lens.aperture.value < 90.0:
        raise LensError(f"{lens.name}: the object cone angle must be below 90 degrees")
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
    direction = 1.0
    surfs = lens.surfaces
    for i, s in enumerate(surfs[:-1], start=1):
        if s.mirror:
            direction = -direction  # after a mirror the thicknesses are negative (Zemax, CODE V)
        if s.coordinate_break:
            continue
        # the glass runs on through the coordinate breaks that follow (a fold mirror inside a
        # prism: thickness 0 on the mirror, the path on the break after it)
        t, k = s.thickness, i
        while k < len(surfs) - 1 and surfs[k].coordinate_break:
            t += surfs[k].thickness
            k += 1
        if t * direction <= 0.0 and not s.material.is_air:
            sign = "positive" if direction > 0 else "negative (after an odd number of mirrors)"
            raise LensError(
                f"{lens.name}: surface {i}: the glass after it has thickness {s.thickness:g} mm; "
                f"give its centre thickness (a {sign} number of mm)"
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
    direction = 1.0
    for i in range(n - 1):
        a, b = lens.surfaces[i], lens.surfaces[i + 1]
        if a.mirror:
            direction = -direction
        if not (math.isfinite(a.semi_diameter) and math.isfinite(b.semi_diameter)):
            continue
        if a.is_placed or b.is_placed or a.coordinate_break or b.coordinate_break:
            continue  # not on a common axis: the axial-gap test does not apply
        h = np.linspace(0.0, min(a.semi_diameter, b.semi_diameter), 33)
        gap = direction * (a.thickness + b.sag(h) - a.sag(h))
        j = int(np.argmin(gap))
        if gap[j] < 0.0:
            raise LensError(
                f"{lens.name}: surface {i + 1}: surfaces {i + 1} and {i + 2} cross inside their "
                f"semi-diameters (axial gap {gap[j]:.6g} mm at height {h[j]:.6g} mm); increase "
                "the thickness or reduce the semi-diameters"
            )
