"""Characteristic distortion of a traced lens in any image plane (Pestrecov 1958, Eqs. 8–9).

One trace of the real chief rays (``raytrace.trace.chief_rays``) serves any number of image
planes: the final segment is moved analytically to each plane. Image planes may be given as

- ``s_prime``: distance s' from the second principal point H' (Pestrecov's convention),
- ``image_distance``: distance from the last vertex,
- ``defocus``: distance from the Gaussian image plane of the object (+ = away from the lens);

none of them = the Gaussian plane. Distances in mm; planes before the last vertex are refused.

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
from dataclasses import dataclass

import numpy as np

from raytrace.errors import TraceError
from raytrace.lens import Lens

from .tables import ANGLE, HEIGHT, NOMINAL_ANGLE, DistortionCurve, format_columns

REFERENCES = ("characteristic", "distortion-focal-length", "real-chief-transport")
DFL_EPSILON = 1e-3  # near-axis reference field as a fraction of the largest |field|


@dataclass(frozen=True)
class CharacteristicDistortion:
    """Distortion of one lens and object distance in several image planes (arrays: planes × fields).

    name: lens name; reference: one of ``REFERENCES``; field_kind: ``"angle"``, ``"height"`` or
    ``"nominal-angle"``; fields (n,): as given (deg or mm); object_distance: positive magnitude
    from the object plane to the first vertex (``inf`` for infinity).
    x (n,): ``tan α`` or the object height y (mm); y (n,): object heights (mm; NaN at infinity).
    z_planes, s_prime, image_distance, defocus (p,): the planes as absolute z, from H', from the
    last vertex and from the Gaussian plane (mm). constant (p,): K0 of Eq. (8) in each plane
    (F0 in mm or M0); scale (p,): the reference's linear scale (= K0 for ``characteristic``).
    gaussian_constant: f or m0.  y0p, yp, D0 (p, n) in mm; Dr (p, n) a fraction (0 on the axis).
    status (n,): trace status per field (``raytrace.trace.STATUS_*``); NaN values where not OK.
    paraxial: the ``ParaxialResult`` used.
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
    image_distance: np.ndarray
    defocus: np.ndarray
    constant: np.ndarray
    scale: np.ndarray
    gaussian_constant: float
    y0p: np.ndarray
    yp: np.ndarray
    D0: np.ndarray
    Dr: np.ndarray
    status: np.ndarray
    paraxial: object

    @property
    def finite(self) -> bool:
        return self.field_kind != ANGLE

    @property
    def symbol(self) -> str:
        return "M" if self.finite else "F"

    @property
    def n_planes(self) -> int:
        return int(self.z_planes.size)

    def plane_label(self, i: int) -> str:
        d = self.defocus[i]
        g = (
            "Gaussian plane"
            if abs(d) <= 1e-9 * max(1.0, abs(self.s_prime[i]))
            else f"defocus {d:+.4f} mm"
        )
        return f"s' = {self.s_prime[i]:.4f} mm ({g})"

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
        )


def _planes(par, s_prime, image_distance, defocus) -> np.ndarray:
    given = [
        (k, v)
        for k, v in (("s_prime", s_prime), ("image_distance", image_distance), ("defocus", defocus))
        if v is not None
    ]
    if len(given) > 1:
        raise TraceError("give the image planes one way: s_prime, image_distance or defocus")
    if not given:
        z = np.array([par.z_gauss], dtype=float)
    else:
        kind, v = given[0]
        arr = np.atleast_1d(np.asarray(v, dtype=float)).ravel()
        if arr.size == 0 or not np.all(np.isfinite(arr)):
            raise TraceError(f"image planes ({kind}) must be finite numbers")
        conv = {
            "s_prime": par.z_from_s_prime,
            "image_distance": par.z_from_last_vertex,
            "defocus": par.z_from_defocus,
        }
        z = np.atleast_1d(np.asarray(conv[kind](arr), dtype=float))
    if not math.isfinite(par.z_gauss) and not given:
        raise TraceError("the Gaussian image is at infinity; give the image plane explicitly")
    bad = np.nonzero(z <= par.z_last)[0]
    if bad.size:
        i = int(bad[0])
        raise TraceError(
            f"image plane at {z[i] - par.z_last:+.4f} mm from the last vertex lies on or before "
            "the "
            "last surface; an image plane must be behind the lens"
        )
    return z


def characteristic_distortion(
    lens: Lens,
    fields,
    *,
    field_kind: str | None = None,
    object_distance: float | None = None,
    s_prime=None,
    image_distance=None,
    defocus=None,
    reference: str = "characteristic",
    wavelength: float | None = None,
    clip: bool = True,
) -> CharacteristicDistortion:
    """Distortion of ``lens`` at ``fields`` in one or more image planes (module docstring).

    fields: angles (deg) or object heights (mm), see ``field_kind`` (default: the lens's field kind;
        ``"angle"`` with a finite object means nominal angles, ``y = p0 tan α``).
    object_distance: positive magnitude from the object plane to the first vertex (``inf``);
        default the lens's.
    s_prime / image_distance / defocus: the image plane(s), scalar or array (mm); at most one.
    reference: ``characteristic`` | ``distortion-focal-length`` | ``real-chief-transport``.
    Raises TraceError / LensError for impossible requests; fields the lens cannot pass get a
    status code and NaN values.
    """
    from raytrace.paraxial import paraxial, pestrecov_constants
    from raytrace.trace import STATUS_OK, chief_rays

    if reference not in REFERENCES:
        raise TraceError(
            f"unknown distortion reference {reference!r}; expected one of {', '.join(REFERENCES)}"
        )
    par = paraxial(lens, object_distance=object_distance, wavelength=wavelength)
    fk = lens.field.kind if field_kind is None else field_kind
    if fk not in ("angle", "height"):
        raise TraceError(f"field_kind must be 'angle' or 'height', got {fk!r}")
    f = np.atleast_1d(np.asarray(fields, dtype=float)).ravel()
    if f.size == 0:
        raise TraceError("no fields given")
    infinite = par.infinite
    if fk == "height" and infinite:
        raise TraceError("object-height fields need a finite object distance")
    kind = ANGLE if infinite else (HEIGHT if fk == "height" else NOMINAL_ANGLE)
    if kind == ANGLE:
        x = np.tan(np.radians(f))
        yobj = np.full(f.shape, np.nan)
    elif kind == HEIGHT:
        x = f.copy()
        yobj = x
    else:
        x = par.p0 * np.tan(np.radians(f))
        yobj = x
    z = _planes(par, s_prime, image_distance, defocus)
    sp = np.asarray(par.s_prime_of(z), dtype=float)
    K0 = np.array([pestrecov_constants(par, float(v)).scale for v in sp])
    KG = par.efl if infinite else par.m0

    extra = np.empty(0)
    if reference == "distortion-focal-length":
        fmax = float(np.max(np.abs(f)))
        eps = DFL_EPSILON * (fmax if fmax > 0 else 1.0)
        extra = np.array([eps, 2.0 * eps])
    cr = chief_rays(
        lens,
        np.concatenate([f, extra]),
        field_kind=fk,
        object_distance=par.object_distance,
        wavelength=wavelength,
        clip=clip,
    )
    n = f.size
    status = cr.status[:n].copy()
    ok = status == STATUS_OK
    H = np.atleast_2d(cr.heights_at(z))  # (p, n + extra)
    yp = np.where(ok[None, :], H[:, :n], np.nan)

    if reference == "characteristic":
        scale = K0.copy()
        y0p = K0[:, None] * x[None, :]
    elif reference == "distortion-focal-length":
        if not np.all(cr.status[n:] == STATUS_OK):
            raise TraceError(
                "the near-axis reference chief ray for the distortion focal length failed"
            )
        xe = extra if kind != ANGLE else np.tan(np.radians(extra))
        if kind == NOMINAL_ANGLE:
            xe = par.p0 * np.tan(np.radians(extra))
        k1 = H[:, n] / xe[0]
        k2 = H[:, n + 1] / xe[1]
        scale = (4.0 * k1 - k2) / 3.0
        y0p = scale[:, None] * x[None, :]
    else:  # real-chief-transport
        dz = z - par.z_gauss
        tan_u = cr.tan_out[:n]
        y0p = KG * x[None, :] + dz[:, None] * tan_u[None, :]
        scale = KG + dz / par.m_e if infinite else KG + dz / (par.m_e * par.p0)
    D0 = yp - y0p
    with np.errstate(divide="ignore", invalid="ignore"):
        Dr = np.where(x[None, :] != 0.0, D0 / np.where(y0p != 0.0, y0p, 1.0), 0.0)
    Dr = np.where(np.isfinite(yp), Dr, np.nan)
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
        image_distance=z - par.z_last,
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
    )


def format_characteristic(
    res: CharacteristicDistortion, *, decimals: int = 4, layout: str = "auto"
) -> str:
    """Text table. One plane: Pestrecov's Table I layout (y, y0', y', D0, Dr per field). Several
    planes: Table V layout — D0 (mm) per field (rows) and plane (columns, headed by s')."""
    from raytrace.trace import STATUS_NAMES

    s = res.symbol
    unit = " mm" if not res.finite else ""
    head = [
        f"{res.name} — distortion ({res.reference}); object distance {res.object_distance:g} mm"
    ]
    flabel = {ANGLE: "α (deg)", HEIGHT: "y (mm)", NOMINAL_ANGLE: "nominal α (deg)"}[res.field_kind]
    bad = [
        f"{v:g}: {STATUS_NAMES.get(int(c), c)}"
        for v, c in zip(res.fields, res.status, strict=True)
        if c != 0
    ]
    tail = ["fields not traced: " + ", ".join(bad)] if bad else []
    if res.n_planes == 1:
        head.append(
            f"{res.plane_label(0)};  {s}0 = {res.constant[0]:.6f}{unit};  "
            f"scale = {res.scale[0]:.6f}{unit}"
        )
        q = []
        if res.finite:
            q.append(("y (mm)", res.x, decimals, True))
        q += [
            ("y0' (mm)", res.y0p[0], decimals, True),
            ("y' (mm)", res.yp[0], decimals, True),
            ("D0 (mm)", res.D0[0], decimals, True),
            ("Dr (%)", 100.0 * res.Dr[0], decimals, True),
        ]
        return "\n".join([format_columns(head, flabel, res.fields, q, layout=layout)] + tail)
    head.append("Linear distortion D0 (mm) in image planes at s' (mm from H'):")
    for i in range(res.n_planes):
        head.append(f"  {res.plane_label(i)}: {s}0 = {res.constant[i]:.6f}{unit}")
    q = [(f"s'={res.s_prime[i]:.1f}", res.D0[i], decimals, True) for i in range(res.n_planes)]
    return "\n".join([format_columns(head, flabel, res.fields, q, layout="rows")] + tail)


def characteristic_to_dict(res: CharacteristicDistortion) -> dict:
    """JSON-ready dict (NaN → None)."""

    def lst(a):
        return [
            None if not math.isfinite(v) else float(v) for v in np.asarray(a, dtype=float).ravel()
        ]

    from raytrace.trace import STATUS_NAMES

    return {
        "lens": res.name,
        "reference": res.reference,
        "field_kind": res.field_kind,
        "object_distance_mm": "inf" if math.isinf(res.object_distance) else res.object_distance,
        "fields": lst(res.fields),
        "x": lst(res.x),
        "y_mm": lst(res.y),
        "status": [STATUS_NAMES.get(int(c), str(int(c))) for c in res.status],
        "gaussian_constant": res.gaussian_constant,
        "planes": [
            {
                "z_mm": float(res.z_planes[i]),
                "s_prime_mm": float(res.s_prime[i]),
                "from_last_vertex_mm": float(res.image_distance[i]),
                "defocus_mm": float(res.defocus[i]),
                "F0_mm" if res.symbol == "F" else "M0": float(res.constant[i]),
                "scale": float(res.scale[i]),
                "y0p_mm": lst(res.y0p[i]),
                "yp_mm": lst(res.yp[i]),
                "D0_mm": lst(res.D0[i]),
                "Dr": lst(res.Dr[i]),
                "Dr_pct": lst(100.0 * res.Dr[i]),
            }
            for i in range(res.n_planes)
        ],
    }
