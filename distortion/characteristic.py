"""Characteristic distortion of a traced lens in any image plane (Pestrecov 1958, Eqs. 8–9).

One trace of the real chief rays (``raytrace.trace.chief_rays``) serves any number of image
planes: the final segment is moved analytically to each plane. Image planes may be given as

- ``s_prime``: distance s' from the second principal point H' (Pestrecov's convention),
- ``from_last_vertex``: distance from the last vertex,
- ``defocus``: distance from the Gaussian image plane of the object (+ = away from the lens),
- or ``plane=`` :class:`~raytrace.paraxial.ImagePlane` objects (docs/design.md, "Vocabulary");

none of them = the Gaussian plane. Distances in mm (or strings with a length unit, ``"50.5mm"``,
as the command line takes them); planes before the last vertex are refused.

Fields: angles α in degrees (object at infinity), object heights y in mm (finite conjugates) or,
for a finite object, nominal angles α standing for ``y = p0·tan α`` (``field_kind="angle"`` with a
finite object distance). For an object at infinity ``x = tan α``; for finite conjugates ``x = y``.

Reference definitions (``REFERENCES``), never mixed silently:

``characteristic`` (default; Pestrecov Eqs. 8–9)
    ``y0' = K0·x`` with the paraxial constants of orthoscopy IN THE ACTUAL PLANE:
    ``M0 = p0'/(m_e p0)``, ``F0 = p0'/m_e``. ``D0 = y' − y0'``, ``Dr = D0/y0'``.

``distortion-focal-length``
    ``y0' = K_dfl·x`` with the scale ``K_dfl = y'(ε)/x(ε)`` of a near-axis real chief ray at the
    evaluation plane (what several commercial and open tools report). It is evaluated at
    ε and 2ε (ε = ``1e-3 ×`` the largest |field|) and Richardson-extrapolated to ε → 0
    (``K = (4K(ε) − K(2ε))/3``; the ε² distortion term cancels). Because Pestrecov derives
    Eq. (8) as exactly this limit, ``K_dfl`` equals M0/F0 in every plane up to the O(ε⁴) and
    round-off residue: the two definitions differ only by that residue (a cross-check of the
    paraxial constants against the real tracer, Gaussian plane or not).

``real-chief-transport``
    The Gaussian-plane ideal point carried along the real chief ray to the actual plane:
    reference height ``y_ref = y'_par,G + Δz·tan u'_real`` with ``y'_par,G = m0·y`` (or ``f tan α``)
    and ``Δz`` the defocus, so the linear distortion ``y' − y_ref = y'_real,G − y'_par,G`` is that
    of the Gaussian plane in every plane, and
    ``Dr = (y'_real,G − y'_par,G)/(y'_par,G + Δz·tan u'_real)``.
    It agrees with ``characteristic`` only in the Gaussian plane.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from raytrace.errors import TraceError
from raytrace.lens import Lens, require_lens
from raytrace.paraxial import (
    ImagePlane,
    ParaxialResult,
    orthoscopy_abscissa,
    orthoscopy_constants,
)
from raytrace.trace.results import field_unit, object_words

from .curve import (
    ANGLE,
    HEIGHT,
    DistortionCurve,
    FieldKindMixin,
    fields_and_abscissa,
    plane_label,
    relative_distortion,
    require_choice,
)

REFERENCES = ("characteristic", "distortion-focal-length", "real-chief-transport")
DFL_EPSILON = 1e-3  # near-axis reference field as a fraction of the largest |field|
#: what a chromatic distortion is measured against: the reference wavelength's constants, or
#: each wavelength's own (``characteristic_distortion(..., wavelengths=..., scale=...)``)
SCALES = ("reference", "own")


@dataclass(frozen=True, eq=False)
class CharacteristicDistortion(FieldKindMixin):
    """Distortion of one lens and object distance in several image planes (arrays: planes × fields).

    name: lens name; reference: one of ``REFERENCES``; field_kind: ``"angle"``, ``"height"`` or
    ``"nominal-angle"``; fields (n,): as given (deg or mm); object_distance: positive magnitude
    from the object plane to the first vertex (``inf`` for infinity).
    x (n,): ``tan α`` or the object height y (mm); y (n,): object heights (mm; NaN at infinity).
    z_planes, s_prime, from_last_vertex, defocus (p,): the planes as absolute z, from H', from the
    last vertex and from the Gaussian plane (mm). constant (p,): K0 of Eq. (8) in each plane
    (F0 in mm or M0); scale (p,): the reference's linear scale (= K0 for ``characteristic``).
    gaussian_constant: f or m0.  y0p, yp, D0 (p, n) in mm; Dr (p, n) a fraction (0 on the axis).
    status (n,): trace status per field (``raytrace.trace.STATUS_*``); NaN values where not OK.
    paraxial: the ``ParaxialResult`` used.
    lens, clip: the lens traced and whether its semi-diameters clipped the chief rays, kept so
    that :meth:`retrace` can trace the same setting at other fields (e.g. densely for a plot).
    wavelength: the traced wavelength (nm). scale_basis: ``""`` for a single-wavelength call
    (everything at ``wavelength``); in a :class:`ChromaticDistortion`, ``"reference"`` when
    ``paraxial`` (so F0/M0, s', the Gaussian plane) is the lens's reference wavelength's, or
    ``"own"`` when it is the traced wavelength's.
    """

    name: str
    reference: str
    field_kind: str
    fields: np.ndarray
    object_distance: float
    x: np.ndarray
    y: np.ndarray
    z_planes: np.ndarray
    s_prime: np.ndarray
    from_last_vertex: np.ndarray
    defocus: np.ndarray
    constant: np.ndarray
    scale: np.ndarray
    gaussian_constant: float
    y0p: np.ndarray
    yp: np.ndarray
    D0: np.ndarray
    Dr: np.ndarray
    status: np.ndarray
    paraxial: ParaxialResult
    lens: Lens | None = None
    clip: bool = True
    wavelength: float = math.nan
    scale_basis: str = ""

    @property
    def n_planes(self) -> int:
        return int(self.z_planes.size)

    def plane_label(self, i: int) -> str:
        return plane_label(self.s_prime[i], self.defocus[i])

    def __repr__(self) -> str:
        unit, obj = field_unit(self.field_kind), object_words(self.object_distance)
        planes = ", ".join(f"{v:.4g}" for v in self.s_prime[:4]) + (
            ", ..." if self.n_planes > 4 else ""
        )
        with np.errstate(invalid="ignore"):
            worst = float(np.nanmax(np.abs(self.D0))) if np.isfinite(self.D0).any() else math.nan
        bad = int(np.count_nonzero(self.status != 0))
        return (
            f"CharacteristicDistortion({self.name!r}, {self.fields.size} fields "
            f"{self.fields.min():g}..{self.fields.max():g} {unit}, object {obj}, "
            f"s' = [{planes}] mm, max |D0| = {worst:.6g} mm, reference {self.reference}"
            + (f", {bad} fields failed" if bad else "")
            + ")"
        )

    def curve(self, i: int = 0) -> DistortionCurve:
        """Plane ``i`` as a :class:`DistortionCurve` (fields with status != OK dropped) for
        calibration, tables and plots. Its constant is K0 of Eq. (8) in that plane."""
        ok = np.isfinite(self.yp[i])
        return DistortionCurve(
            fields=self.fields[ok],
            field_kind=self.field_kind,
            x=self.x[ok],
            y0p=self.y0p[i][ok],
            D0=self.D0[i][ok],
            constant=float(self.constant[i]),
            name=self.name,
            plane=self.plane_label(i),
            source=f"traced; reference {self.reference}",
            decimals=4,
            extra={"traced": self, "plane": i},
        )

    def retrace(self, fields: npt.ArrayLike) -> CharacteristicDistortion:
        """The same lens, object, image planes, reference, wavelength and clipping at other
        ``fields`` (same kind and unit as :attr:`fields`: degrees, or mm for object heights) —
        one more trace, e.g. at many fields for a smooth plot."""
        if self.lens is None:
            raise TraceError("this distortion result carries no lens to trace again")
        f = {"object_heights_mm" if self.field_kind == HEIGHT else "fields_deg": fields}
        kw = dict(
            from_last_vertex=self.from_last_vertex,
            object_distance=self.object_distance,
            reference=self.reference,
            clip=self.clip,
        )
        if self.scale_basis:  # a member of a ChromaticDistortion: the same scale again
            return characteristic_distortion(
                self.lens, **f, **kw, wavelengths=[self.wavelength], scale=self.scale_basis
            )[0]
        return characteristic_distortion(self.lens, **f, **kw, wavelength=self.paraxial.wavelength)


def characteristic_distortion(
    lens: Lens,
    fields_deg: npt.ArrayLike | None = None,
    *,
    object_heights_mm: npt.ArrayLike | None = None,
    plane: ImagePlane | Sequence[ImagePlane] | str | None = None,
    s_prime: npt.ArrayLike | None = None,
    from_last_vertex: npt.ArrayLike | None = None,
    defocus: npt.ArrayLike | None = None,
    object_distance: float | str | None = None,
    object_s: float | None = None,
    object_scale: float | None = None,
    reference: str = "characteristic",
    wavelength: float | str | None = None,
    wavelengths: npt.ArrayLike | str | None = None,
    scale: str = "reference",
    clip: bool = True,
) -> CharacteristicDistortion | ChromaticDistortion:
    """Distortion of ``lens`` at the given fields in one or more image planes (Pestrecov 1958,
    Eqs. 8–9; the module docstring defines the three references).

    Parameters
    ----------
    lens : Lens
    fields_deg : array_like, optional
        Field angles α in degrees (object-space chief-ray slope angle). With a finite object they
        are Pestrecov's nominal angles: object heights ``y = p0 tan α``. Default: 11 fields from
        0 to the lens's field.
    object_heights_mm : array_like, optional
        Object heights in mm instead of angles (finite objects only).
    plane : ImagePlane, list of ImagePlane, "gaussian" or "file", optional
        The image plane(s); or give ONE of ``s_prime`` (mm from H'), ``from_last_vertex`` (mm
        from the last vertex), ``defocus`` (mm from the Gaussian plane, + away from the lens),
        each a number or a sequence (numbers in mm or strings with a length unit, ``"50.5mm"``).
        Default: the Gaussian image plane of the object. All planes come from one trace.
    object_distance, object_s, object_scale
        The object plane (at most one): mm from the first vertex (or ``inf`` / ``"12x"``),
        Pestrecov's signed s from H (mm, negative), or an image scale N ("N×", magnification
        −1/N). Default: the lens file's object.
    reference : {"characteristic", "distortion-focal-length", "real-chief-transport"}
        The reference the ideal image is measured from (module docstring).
    wavelength : float, optional
        nm; default the lens's reference wavelength. The lens is analysed as a monochromatic
        lens at this wavelength: paraxial data, the Gaussian plane and F0/M0 at this wavelength.
    wavelengths : sequence of float or "lens", optional
        Several wavelengths (nm) from one kernel call (``"lens"``: the lens's own); returns a
        :class:`ChromaticDistortion`. The object and the image planes are resolved at the lens's
        reference wavelength, so every wavelength is measured in the same physical planes for
        the same object points. Give ``wavelength`` or ``wavelengths``, not both.
    scale : {"reference", "own"}
        With ``wavelengths``: ``"reference"`` (default) measures every wavelength's distortion
        against the reference wavelength's F0/M0 (one camera constant for all colour channels,
        as a calibration sees it); ``"own"`` against each wavelength's own F0/M0 (its own
        paraxial data, principal points and Gaussian plane; the planes stay where they are).
    clip : bool
        Apply the lens's semi-diameters to the chief rays.

    Returns
    -------
    CharacteristicDistortion or ChromaticDistortion
        Arrays (planes × fields) of y0', y', D0 (mm) and Dr (fraction); with ``wavelengths``
        one such result per wavelength and stacked arrays (wavelengths × planes × fields). A
        field the lens cannot pass has a status code and NaN values.

    Raises
    ------
    TraceError, LensError
        For impossible requests (a plane before the last vertex, heights with an object at
        infinity, an unknown reference, ...).
    """
    require_lens(lens)
    from raytrace.paraxial import (
        checked_wavelength,
        image_planes,
        paraxial,
        plane_z,
        resolve_paraxial,
    )
    from raytrace.trace import aim

    require_choice(reference, REFERENCES, "distortion reference")
    require_choice(scale, SCALES, "scale")
    chromatic = wavelengths is not None
    if chromatic and wavelength is not None:
        raise TraceError("give wavelength= or wavelengths=, not both")
    wl = None if chromatic else checked_wavelength(wavelength)
    par = resolve_paraxial(lens, object_distance, object_s, object_scale, wl)
    fk, f, kind, x = fields_and_abscissa(lens, par, fields_deg, object_heights_mm)
    planes = image_planes(
        plane, s_prime=s_prime, from_last_vertex=from_last_vertex, defocus=defocus
    )
    z = plane_z(par, planes)

    extra = np.empty(0)
    if reference == "distortion-focal-length":
        fmax = float(np.max(np.abs(f)))
        eps = DFL_EPSILON * (fmax if fmax > 0 else 1.0)
        extra = np.array([eps, 2.0 * eps])
    ff = np.concatenate([f, extra])
    common = dict(
        lens=lens, reference=reference, fk=fk, kind=kind, f=f, x=x, z=z, extra=extra, clip=clip
    )
    if not chromatic:
        cr = aim(lens, ff, fk, par.object_distance, wl, clip)
        return _build(par=par, cr=cr, cr_scale=cr, basis="", **common)

    from raytrace.trace.chief import resolve_wavelengths

    wls = resolve_wavelengths(lens, wavelengths)
    ref = float(lens.wavelength)
    traced = wls if (ref in wls or scale == "own") else (*wls, ref)
    crs = aim(lens, ff, fk, par.object_distance, clip=clip, wavelengths=traced)
    cr_ref = crs.at(ref) if ref in traced else None
    results = []
    for i, w in enumerate(wls):
        if scale == "reference":
            p_i, cs = par, cr_ref
        else:
            p_i = paraxial(lens, object_distance=par.object_distance, wavelength=w)
            cs = crs[i]
        results.append(_build(par=p_i, cr=crs[i], cr_scale=cs, basis=scale, **common))
    return ChromaticDistortion(
        wavelengths=np.array(wls, dtype=float),
        reference_wavelength=ref,
        scale=scale,
        results=tuple(results),
        reference_paraxial=par,
    )


def _build(
    *, lens, par, cr, cr_scale, basis, reference, fk, kind, f, x, z, extra, clip
) -> CharacteristicDistortion:
    """One wavelength's distortion from its traced chief rays ``cr`` (fields then the ``extra``
    near-axis fields), measured against the constants of ``par`` (and, for the
    distortion-focal-length reference, the near-axis rays of ``cr_scale``)."""
    from raytrace.paraxial import ideal_heights
    from raytrace.trace import STATUS_OK

    infinite = par.infinite
    yobj = np.full(f.shape, np.nan) if kind == ANGLE else x
    sp = np.asarray(par.s_prime_of(z), dtype=float)
    K0 = orthoscopy_constants(par, sp)
    KG = par.efl if infinite else par.m0
    n = f.size
    status = cr.status[:n].copy()
    ok = status == STATUS_OK
    H = np.atleast_2d(cr.heights_at(z))  # (p, n + extra)
    yp = np.where(ok[None, :], H[:, :n], np.nan)

    if reference == "characteristic":
        scale = K0.copy()
        y0p = ideal_heights(par, x, sp)
    elif reference == "distortion-focal-length":
        if not np.all(cr_scale.status[n:] == STATUS_OK):
            raise TraceError(
                "the near-axis reference chief ray for the distortion focal length failed"
            )
        Hs = np.atleast_2d(cr_scale.heights_at(z))
        xe = orthoscopy_abscissa(par, extra, fk)
        k1 = Hs[:, n] / xe[0]
        k2 = Hs[:, n + 1] / xe[1]
        scale = (4.0 * k1 - k2) / 3.0
        y0p = scale[:, None] * x[None, :]
    else:  # real-chief-transport
        dz = z - par.z_gauss
        tan_u = cr.tan_out[:n]
        y0p = KG * x[None, :] + dz[:, None] * tan_u[None, :]
        scale = KG + dz / par.m_e if infinite else KG + dz / (par.m_e * par.p0)
    D0 = yp - y0p
    Dr = relative_distortion(D0, y0p, off_axis=x[None, :] != 0.0, valid=np.isfinite(yp))
    return CharacteristicDistortion(
        name=lens.name,
        reference=reference,
        field_kind=kind,
        fields=f,
        object_distance=par.object_distance,
        x=x,
        y=yobj,
        z_planes=z,
        s_prime=sp,
        from_last_vertex=z - par.z_last,
        defocus=z - par.z_gauss,
        constant=K0,
        scale=np.asarray(scale, dtype=float),
        gaussian_constant=float(KG),
        y0p=y0p,
        yp=yp,
        D0=D0,
        Dr=Dr,
        status=status,
        paraxial=par,
        lens=lens,
        clip=bool(clip),
        wavelength=float(cr.wavelength),
        scale_basis=basis,
    )


@dataclass(frozen=True, eq=False)
class ChromaticDistortion:
    """Characteristic distortion at several wavelengths, from one kernel call (wavelength ×
    field), in the same physical image planes and for the same object points.

    wavelengths (w,): nm, as asked for; reference_wavelength: the lens's reference (nm);
    scale: ``"reference"`` — every wavelength measured against the reference wavelength's F0/M0
    (and, for the other definitions, its paraxial data / near-axis scale), as one camera constant
    for all colour channels — or ``"own"`` — each wavelength against its own (SCALES).
    results: one :class:`CharacteristicDistortion` per wavelength (its ``wavelength`` and
    ``scale_basis`` say which). reference_paraxial: the reference wavelength's paraxial data (the
    object and the planes were resolved with it).

    Stacked arrays: ``yp``, ``y0p``, ``D0``, ``Dr`` (w, planes, fields); ``constant``, ``scale``
    (w, planes); ``status`` (w, fields).
    """

    wavelengths: np.ndarray
    reference_wavelength: float
    scale: str
    results: tuple[CharacteristicDistortion, ...]
    reference_paraxial: ParaxialResult

    def __getitem__(self, i: int) -> CharacteristicDistortion:
        return self.results[i]

    def __iter__(self):
        return iter(self.results)

    @property
    def n_wavelengths(self) -> int:
        return len(self.results)

    def at(self, wavelength: float) -> CharacteristicDistortion:
        """The result at ``wavelength`` (nm; one of :attr:`wavelengths`)."""
        from raytrace.trace.chief import wavelength_index

        return self.results[wavelength_index(self.wavelengths, wavelength, "the wavelengths")]

    def _stack(self, name: str) -> np.ndarray:
        return np.stack([getattr(r, name) for r in self.results])

    name = property(lambda self: self.results[0].name)
    reference = property(lambda self: self.results[0].reference)
    field_kind = property(lambda self: self.results[0].field_kind)
    fields = property(lambda self: self.results[0].fields)
    x = property(lambda self: self.results[0].x)
    object_distance = property(lambda self: self.results[0].object_distance)
    z_planes = property(lambda self: self.results[0].z_planes)
    yp = property(lambda self: self._stack("yp"))
    y0p = property(lambda self: self._stack("y0p"))
    D0 = property(lambda self: self._stack("D0"))
    Dr = property(lambda self: self._stack("Dr"))
    constant = property(lambda self: self._stack("constant"))
    status = property(lambda self: self._stack("status"))

    def plane_label(self, i: int) -> str:
        """Plane ``i`` described with the reference wavelength's H' and Gaussian plane."""
        par = self.reference_paraxial
        z = float(self.z_planes[i])
        return plane_label(z - par.z_Hp, z - par.z_gauss, f" at {self.reference_wavelength:g} nm")

    @property
    def scale_description(self) -> str:
        """One line saying which constants the distortion is measured against."""
        sym = self.results[0].symbol + "0"
        if self.scale == "reference":
            return (
                f"every wavelength against the reference wavelength's {sym} "
                f"({self.reference_wavelength:g} nm)"
            )
        return f"each wavelength against its own {sym}"

    def __repr__(self) -> str:
        wl = ", ".join(f"{w:g}" for w in self.wavelengths)
        with np.errstate(invalid="ignore"):
            D0 = self.D0
            worst = float(np.nanmax(np.abs(D0))) if np.isfinite(D0).any() else math.nan
        return (
            f"ChromaticDistortion({self.name!r}, {self.fields.size} fields x "
            f"{self.n_wavelengths} wavelengths [{wl}] nm, scale {self.scale} "
            f"(reference {self.reference_wavelength:g} nm), max |D0| = {worst:.6g} mm)"
        )
