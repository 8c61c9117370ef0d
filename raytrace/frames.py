"""Surface placement: decenters, tilts, coordinate breaks and mirrors folded into ONE frame per
surface (a rotation matrix and a vertex position in the global frame), computed once per lens.

Frames
    A frame is ``(R, o)``: the columns of the 3 × 3 rotation ``R`` are the frame's x, y, z axes
    and ``o`` its origin, both in global coordinates (mm); a point ``p`` of the frame is
    ``o + R p`` globally. The **global frame** is the object-space frame: light from the object
    travels toward +z, the object plane is ``z = −object_distance`` and the light arrives at the
    first surface in the frame with origin (0, 0, 0) and axes x, y, z (docs/design.md,
    "Conventions"). Moving a frame ``F = (R, o)`` by a placement ``(Q, d)`` expressed in F gives
    ``(R Q, o + R d)``; a thickness ``t`` is the move ``(I, (0, 0, t))``.

Per surface j (:func:`surface_frames`), starting from the arrival frame ``A_j`` (for surface 1 the
global frame):

1. the **surface frame** ``S_j = A_j ∘ placement_j`` (``Surface.placement``; the identity when
   None): the surface's vertex is ``S_j``'s origin and its axis ``S_j``'s z axis; its sag, normal,
   semi-diameter and clear aperture are expressed in ``S_j``;
2. the **departure frame** ``D_j`` (``Surface.after``): ``"stay"`` → ``S_j`` (Zemax coordinate
   break and surface tilt/decenter with nothing after it; CODE V basic decenter ``DEC``);
   ``"return"`` → ``A_j`` (CODE V ``DAR``; the Zemax tilt/decenter tab's *reverse* after the
   surface, which undoes the before-surface move exactly); ``"bend"`` → ``S_j ∘ (Q_j, 0)``, the
   rotation of the placement applied a second time, no decenter (CODE V ``BEN``: the axis turns
   by twice the tilt, for fold mirrors); a :class:`Placement` → ``S_j ∘ after`` (Zemax
   tilt/decenter tab, explicit values after the surface);
3. the next arrival frame ``A_{j+1} = D_j ∘ (I, (0, 0, t_j))``: the thickness runs along the
   departure frame's z axis (for a Zemax coordinate break: in the new frame). After the last
   surface, ``A_img`` is the arrival frame of the image surface and ``S_img = A_img ∘
   Lens.image_placement``.

A **coordinate break** (``Surface.coordinate_break``; Zemax ``COORDBRK``) is a surface that is not
traced: only its frame move and thickness count.

Placements (:class:`Placement`; one convention here, the readers translate each program into it)
    ``decenter = (x, y, z)`` mm and ``tilt = (a, b, c)`` degrees, **right-handed** rotations of
    the frame about its x, y, z axes (a positive ``a`` turns +y toward +z and +z toward −y).
    ``order = "decenter-tilt"``: decenter along the starting axes, then tilt about x, then the new
    y, then the new z: ``Q = Rx(a) Ry(b) Rz(c)``, ``d = (x, y, z)``. ``order = "tilt-decenter"``:
    tilt about z, then the new y, then the new x, then decenter along the tilted axes:
    ``Q = Rz(c) Ry(b) Rx(a)``, ``d = Q (x, y, z)``. The inverse of a move is the *inverse
    sequence*: ``Placement(−decenter, −tilt, other order)`` (:meth:`Placement.inverse`) — not
    the same order with negated values (that differs as soon as two tilts, or a tilt and a
    decenter, are combined).

Source conventions (what the readers translate):

* **Zemax OpticStudio** coordinate break (OpticStudio manual, "Coordinate Break"; the same
  parameters in the surface Tilt/Decenter tab): ``PARM 1..6`` = decenter x, decenter y, tilt
  about x, y, z (degrees), order flag. Order flag 0: decenter, then tilt about x, the new y, the
  new z (``"decenter-tilt"``); any other value: tilt about z, the new y, the new x, then decenter
  (``"tilt-decenter"``). The tilts are right-handed: +45° about x followed by a mirror folds the
  beam toward +y (the OpticStudio-authored ``optiland/one_mirror_up_45deg.zmx`` of the corpus;
  optiland 0.6.3 ``CoordinateSystem.get_rotation_matrix``, right-handed). The break's thickness
  runs in the new frame. Stored as-is (right-handed = this module's convention).
* **CODE V** (CODE V Reference Manual, "Decentered and tilted surfaces"; implemented in ray-optics
  0.9.8 ``rayoptics.elem.surface.DecenterData`` and ``rayoptics.util.misc_math.euler2rot3d``):
  ``XDE YDE ZDE`` decenter, then ``ADE`` α about x, ``BDE`` β about the new y, ``CDE`` γ about
  the new z. α and β are **left-handed** (a positive α turns +z toward +y), γ is right-handed:
  the reader stores ``tilt = (−α, −β, γ)`` with ``order = "decenter-tilt"``. Decenter types:
  basic (``DEC``, the default) → ``after = "stay"``; ``DAR`` → ``"return"``; ``BEN`` →
  ``"bend"``; ``REV`` (the surface itself is not moved, the following surfaces are moved by the
  inverse: −γ, −β, −α, −decenter) → ``placement = None``, ``after = placement.inverse()``.
* **Mirrors** (Zemax ``GLAS MIRROR``, CODE V ``REFL``): both programs keep the frame at a mirror
  (no flip of z) and write the thickness after an odd number of mirrors negative; radii are in
  the surface frame. :attr:`SurfaceFrames.direction` is the sign (−1)^(mirrors passed) the
  thickness after each surface has in a well-formed file (the paraxial trace uses n' = −n).

Axis frames (what the kernels use; :attr:`SurfaceFrames.axis_rotation`, ``axis_origin``)
    The axis frame of surface j is its surface frame moved back along its own z axis by the
    nominal vertex position ``zv_j`` (the signed sum of the thicknesses before it, as for a
    centred lens): in it the vertex is at (0, 0, zv_j) and the axis is the z axis, exactly the
    geometry the coaxial kernels assume. For a centred lens every axis frame is the global frame
    (identity, exactly), so nothing is transformed. The **image frame** is the image surface's
    frame moved back by the nominal image position ``Lens.image_z`` in the same way: final ray
    segments are reported in it, so image planes are ``z = const`` there (the Gaussian plane of
    the nominal lens at ``z_gauss``, the file's image surface at ``Lens.image_z``).

Everything here is plain numpy (no numba): the kernels receive the frames through
:func:`raytrace.packing.pack`.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:  # pragma: no cover
    from .lens import Lens

ORDERS = ("decenter-tilt", "tilt-decenter")
AFTER_MODES = ("stay", "return", "bend")


def _triple(value, what: str) -> tuple[float, float, float]:
    try:
        seq = list(value)
    except TypeError:
        raise ValueError(f"{what} must be a sequence of 2 or 3 numbers, got {value!r}") from None
    if len(seq) == 2:
        seq = [*seq, 0.0]
    if len(seq) != 3:
        raise ValueError(f"{what} must have 2 or 3 components, got {len(seq)}")
    out = []
    for v in seq:
        if isinstance(v, bool):
            raise ValueError(f"{what} must be numbers, got {v!r}")
        try:
            f = float(v)
        except (TypeError, ValueError):
            raise ValueError(f"{what} must be numbers, got {v!r}") from None
        if not math.isfinite(f):
            raise ValueError(f"{what} must be finite numbers, got {v!r}")
        out.append(f + 0.0)  # -0.0 -> 0.0 (hash/eq of equal placements)
    return (out[0], out[1], out[2])


@dataclass(frozen=True)
class Placement:
    """One rigid move of a coordinate frame (module docstring for the conventions).

    Attributes
    ----------
    decenter : (x, y, z)
        mm, along the axes of the frame the move starts from (``"decenter-tilt"``) or of the
        tilted frame (``"tilt-decenter"``). Two values are read as (x, y, 0).
    tilt : (a, b, c)
        Degrees, right-handed rotations about x, y, z (Zemax's convention; CODE V's α, β enter
        with the opposite sign).
    order : {"decenter-tilt", "tilt-decenter"}
        Zemax order flag 0 / ≠ 0.
    """

    decenter: tuple[float, float, float] = (0.0, 0.0, 0.0)
    tilt: tuple[float, float, float] = (0.0, 0.0, 0.0)
    order: str = "decenter-tilt"

    def __post_init__(self) -> None:
        object.__setattr__(self, "decenter", _triple(self.decenter, "decenter"))
        object.__setattr__(self, "tilt", _triple(self.tilt, "tilt"))
        if self.order not in ORDERS:
            raise ValueError(f"order must be one of {', '.join(ORDERS)}, got {self.order!r}")

    @property
    def is_identity(self) -> bool:
        """True when the move changes nothing (all values zero)."""
        return not any(self.decenter) and not any(self.tilt)

    @property
    def matrix(self) -> tuple[np.ndarray, np.ndarray]:
        """``(Q, d)``: the move as a rotation and an offset in the starting frame."""
        return move(self)

    def inverse(self) -> Placement:
        """The move that undoes this one: the inverse sequence (−decenter, −tilt, other order)."""
        other = ORDERS[1] if self.order == ORDERS[0] else ORDERS[0]
        return Placement(
            tuple(-v + 0.0 for v in self.decenter), tuple(-v + 0.0 for v in self.tilt), other
        )

    def describe(self) -> str:
        """Short text for listings, e.g. ``dec (0, 1.5, 0) tilt (45, 0, 0)``."""
        parts = []
        if any(self.decenter):
            parts.append("dec (" + ", ".join(f"{v:g}" for v in self.decenter) + ")")
        if any(self.tilt):
            parts.append("tilt (" + ", ".join(f"{v:g}" for v in self.tilt) + ")")
        if self.order != ORDERS[0] and len(parts) > 0:
            parts.append("tilt first")
        return " ".join(parts) or "none"


def placement_or_none(p) -> Placement | None:
    """``p`` as a :class:`Placement`, or None when it is None or changes nothing."""
    if p is None:
        return None
    if not isinstance(p, Placement):
        raise ValueError(f"expected a Placement, got {type(p).__name__}")
    return None if p.is_identity else p


def rot_x(deg: float) -> np.ndarray:
    """Right-handed rotation of a frame about its x axis by ``deg`` degrees."""
    a = math.radians(deg)
    c, s = math.cos(a), math.sin(a)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def rot_y(deg: float) -> np.ndarray:
    """Right-handed rotation about y (+z turns toward +x)."""
    a = math.radians(deg)
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def rot_z(deg: float) -> np.ndarray:
    """Right-handed rotation about z (+x turns toward +y)."""
    a = math.radians(deg)
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _exact(deg: float, f) -> np.ndarray:
    """Rotation with exact zeros and ones for multiples of 90° (a fold stays exactly folded)."""
    m = f(deg)
    q = deg / 90.0
    if q == round(q):
        m = np.round(m)
        m[m == 0.0] = 0.0
    return m


def move(p: Placement | None) -> tuple[np.ndarray, np.ndarray]:
    """``(Q, d)`` of a placement (identity for None): the moved frame is ``(R Q, o + R d)``."""
    if p is None:
        return np.eye(3), np.zeros(3)
    a, b, c = p.tilt
    rx, ry, rz = _exact(a, rot_x), _exact(b, rot_y), _exact(c, rot_z)
    d = np.array(p.decenter, dtype=float)
    if p.order == "decenter-tilt":
        return rx @ ry @ rz, d
    q = rz @ ry @ rx
    return q, q @ d


def compose(
    frame: tuple[np.ndarray, np.ndarray], m: tuple[np.ndarray, np.ndarray]
) -> tuple[np.ndarray, np.ndarray]:
    """The frame ``frame`` moved by ``m = (Q, d)`` (expressed in ``frame``)."""
    R, o = frame
    Q, d = m
    return R @ Q, o + R @ d


def codev_tilt(alpha: float, beta: float, gamma: float) -> tuple[float, float, float]:
    """CODE V's ``ADE BDE CDE`` (α, β left-handed; γ right-handed) as this module's right-handed
    tilts about x, y, z."""
    return (-float(alpha) + 0.0, -float(beta) + 0.0, float(gamma) + 0.0)


@dataclass(frozen=True, eq=False)
class SurfaceFrames:
    """The frames of every surface of a lens (global coordinates, mm; module docstring).

    rotation, origin : (n, 3, 3), (n, 3)
        Surface frames ``S_j`` (columns of rotation = the surface's x, y, z axes).
    arrival_rotation, arrival_origin : (n, 3, 3), (n, 3)
        Arrival frames ``A_j``.
    axis_rotation, axis_origin : (n, 3, 3), (n, 3)
        Axis frames (the surface frame moved back by ``zv`` along its z): identity and zero for a
        centred lens.
    zv : (n,)
        Nominal vertex positions (signed sums of thicknesses; ``Lens.vertex_z``).
    direction : (n,)
        (−1)^(mirrors up to and including surface j): the sign of a well-formed thickness after
        surface j.
    image_rotation, image_origin : (3, 3), (3,)
        The image frame (the image surface's frame moved back by ``image_z``).
    image_surface_rotation, image_surface_origin : (3, 3), (3,)
        The image surface's own frame.
    image_z : float
        Nominal image position (``Lens.image_z``).
    placed : (n,) bool
        Whether surface j's axis frame differs from the global frame.
    image_placed : bool
        Whether the image frame differs from the global frame.
    """

    rotation: np.ndarray
    origin: np.ndarray
    arrival_rotation: np.ndarray
    arrival_origin: np.ndarray
    axis_rotation: np.ndarray
    axis_origin: np.ndarray
    zv: np.ndarray
    direction: np.ndarray
    image_rotation: np.ndarray
    image_origin: np.ndarray
    image_surface_rotation: np.ndarray
    image_surface_origin: np.ndarray
    image_z: float
    placed: np.ndarray
    image_placed: bool

    def to_global(self, j: int, points: np.ndarray) -> np.ndarray:
        """Points (…, 3) in surface j's frame → global coordinates."""
        return self.origin[j] + np.asarray(points, dtype=float) @ self.rotation[j].T

    def image_to_global(self, points: np.ndarray) -> np.ndarray:
        """Points (…, 3) in image-frame coordinates → global coordinates."""
        return self.image_origin + np.asarray(points, dtype=float) @ self.image_rotation.T


def _moved_after(surface, S, A, m) -> tuple[np.ndarray, np.ndarray]:
    after = surface.after
    if isinstance(after, Placement):
        return compose(S, move(after))
    if after == "return":
        return A
    if after == "bend":
        return compose(S, (m[0], np.zeros(3)))
    return S


@functools.lru_cache(maxsize=256)
def surface_frames(lens: Lens) -> SurfaceFrames:
    """The frames of ``lens`` (module docstring), cached per lens (a frozen, hashable Lens; the
    arrays are read-only)."""
    ss = lens.surfaces
    n = len(ss)
    zv = np.array(lens.vertex_z, dtype=float)
    image_z = float(lens.image_z)
    rot = np.empty((n, 3, 3))
    org = np.empty((n, 3))
    arot = np.empty((n, 3, 3))
    aorg = np.empty((n, 3))
    xrot = np.empty((n, 3, 3))
    xorg = np.empty((n, 3))
    placed = np.zeros(n, dtype=bool)
    direction = np.empty(n)
    R, o = np.eye(3), np.zeros(3)
    exact = True  # the arrival frame is exactly (I, (0, 0, zv_j)): nothing moved so far
    sign = 1.0
    for j, s in enumerate(ss):
        arot[j], aorg[j] = R, o
        p = s.placement
        m = move(p)
        S = compose((R, o), m) if p is not None else (R, o)
        D = _moved_after(s, S, (R, o), m)
        rot[j], org[j] = S
        if s.mirror:
            sign = -sign
        direction[j] = sign
        surface_exact = exact and p is None
        if surface_exact:
            xrot[j], xorg[j] = np.eye(3), 0.0
        else:
            xrot[j] = S[0]
            xorg[j] = S[1] - S[0] @ np.array([0.0, 0.0, zv[j]])
            placed[j] = True
        after = s.after
        if isinstance(after, Placement):
            exact = surface_exact and after.is_identity
        elif after != "return":
            exact = surface_exact
        nxt = zv[j + 1] if j + 1 < n else image_z
        if exact:
            R, o = np.eye(3), np.array([0.0, 0.0, nxt])
        else:
            R, o = D[0], D[1] + D[0] @ np.array([0.0, 0.0, s.thickness])
    ip = lens.image_placement
    Si = compose((R, o), move(ip)) if ip is not None else (R, o)
    image_placed = not (exact and ip is None)
    if image_placed:
        irot = Si[0]
        iorg = Si[1] - Si[0] @ np.array([0.0, 0.0, image_z])
    else:
        irot, iorg = np.eye(3), np.zeros(3)
    out = SurfaceFrames(
        rotation=rot,
        origin=org,
        arrival_rotation=arot,
        arrival_origin=aorg,
        axis_rotation=xrot,
        axis_origin=xorg,
        zv=zv,
        direction=direction,
        image_rotation=irot,
        image_origin=iorg,
        image_surface_rotation=np.array(Si[0]),
        image_surface_origin=np.array(Si[1]),
        image_z=image_z,
        placed=placed,
        image_placed=bool(image_placed),
    )
    for a in (rot, org, arot, aorg, xrot, xorg, zv, direction, irot, iorg, placed):
        a.flags.writeable = False
    return out


def relative(
    frm: tuple[np.ndarray, np.ndarray], to: tuple[np.ndarray, np.ndarray]
) -> tuple[np.ndarray, np.ndarray]:
    """``(M, t)`` taking coordinates in frame ``frm`` to coordinates in frame ``to``:
    ``p_to = M p_frm + t``, ``d_to = M d_frm``."""
    R1, o1 = frm
    R2, o2 = to
    return R2.T @ R1, R2.T @ (o1 - o2)


def is_identity_frame(R: np.ndarray, o: np.ndarray) -> bool:
    """True for the exact identity frame."""
    return bool(np.array_equal(R, np.eye(3)) and not np.any(o))


def placements_summary(lens: Lens) -> list[tuple[int, str]]:
    """(1-based surface, text) of every surface that is moved, bent or a coordinate break."""
    out = []
    for i, s in enumerate(lens.surfaces, start=1):
        what = []
        if s.coordinate_break:
            what.append("coordinate break")
        if s.placement is not None:
            what.append(s.placement.describe())
        if s.after != "stay":
            what.append(
                "after: " + (s.after.describe() if isinstance(s.after, Placement) else s.after)
            )
        if what:
            out.append((i, ", ".join(what)))
    return out


def as_placement(value: Placement | Sequence | None) -> Placement | None:
    """A Placement from a Placement or None (helper for keyword arguments)."""
    return placement_or_none(value)
