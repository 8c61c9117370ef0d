"""Lens prescription files: TOML, one surface per line, read into a validated :class:`Lens`.

The format (documented for users in ``lenses/README.md``)::

    name       = "Cooke triplet 50 mm f/4"
    source     = "where the numbers come from"
    provenance = "patent"            # optional: "patent" | "derived" | "rescaled"
    notes      = "free text"         # optional
    units      = "mm"                # only "mm"
    wavelength = 587.5618            # nm, optional (default: the helium d line)
    # several wavelengths instead (nm), optional weights, and the reference (primary) one:
    # wavelengths = [486.1327, 587.5618, 656.2725]
    # weights = [1.0, 2.0, 1.0]
    # reference_wavelength = 587.5618
    # temperature_c = 25.0           # optional system environment (°C, atm): catalog glasses
    # pressure_atm = 1.0             #   follow it by Schott's dn/dT model
    # scale_to_efl = 100.0           # optional: scale the whole lens to this paraxial EFL (mm);
    #                                #   [[configurations]] lengths are scaled with it
    object   = { distance = "inf" }  # mm from the object plane to the first vertex (> 0), or "inf"
    aperture = { fnumber = 4.0 }     # exactly one of fnumber / epd (mm) / na
    field    = { angle = 20.0 }      # exactly one of angle (max half-field, deg) / height (mm)
    surfaces = [
      { r = 21.25,   t = 2.0,  glass = "1.62041/60.32" },
      { r = -158.65, t = 6.0 },
      ...
      { r = -17.285, t = "gaussian" },
    ]

Per surface: ``r`` (radius, mm, ``"inf"`` = plane; positive when the centre of curvature lies
after the vertex) or ``c`` (curvature, 1/mm); ``t`` (mm to the next vertex; for the last surface
to the image plane, or ``"gaussian"`` to solve it to the paraxial image of the file's object);
the medium after the surface: ``glass = "nd/vd"`` (model glass), ``n = 1.5`` (fixed index) or
nothing / ``glass = "air"``; a glass defined here: ``glass = "NAME", catalog = "private",
formula = 2, coefficients = [...]`` (a formula id of :mod:`raytrace.glass.formulas`, λ in µm;
optional ``range_nm = [min, max]``); ``sd`` (semi-diameter, mm); ``stop = true``; ``k`` (conic);
``asph = [A4, A6, ...]``; ``qtype = { form = "qbfs" | "qcon", norm_radius = ρ_max, a = [a0, a1,
...] }`` (a Forbes Q-type asphere on the conic r, k: :mod:`raytrace.qtype`; ρ_max and a_m in
mm); ``label``. ``[object]`` may also carry ``glass`` / ``n`` for an immersed object space.

Placement and mirrors (:mod:`raytrace.frames` states the conventions; ``lenses/README.md`` for
users): per surface ``decenter = [x, y]`` or ``[x, y, z]`` (mm), ``tilt = [a, b, c]`` (degrees,
right-handed about x, y, z, Zemax's convention), ``order = "decenter-tilt"`` (default) or
``"tilt-decenter"``; ``after = "stay" | "return" | "bend"`` or ``after = { decenter = [...],
tilt = [...], order = ... }`` (the frame the thickness runs in after the surface); ``mirror =
true`` (the medium after it is the one before; thicknesses after an odd number of mirrors are
negative); ``type = "coordinate_break"`` (not traced: only its decenter / tilt and ``t``);
``aperture = { circle = r | rectangle = [hx, hy] | ellipse = [a, b], center = [x0, y0] }`` (a
clear aperture in the surface frame). Top level: ``image = { decenter = ..., tilt = ..., order
= ... }`` (the image surface). Aperture kinds also ``float`` (stop semi-diameter, mm),
``working_fnumber``, ``cone_angle`` (degrees); field kinds also ``paraxial_image_height`` and
``real_image_height`` (mm; turned into the object-space field on reading), and ``points =
[[x, y], ...]`` beside the kind.

The provenance is kept as the first line of ``Lens.notes`` (``"provenance: patent"``), so that it
survives :func:`dumps` / :func:`loads`; :func:`provenance` reads it back.

Every problem raises :class:`~raytrace.errors.PrescriptionError` naming the file, the line and,
where it applies, the surface (1-based). Glass keys the medium would ignore are refused too:
``catalog`` / ``model`` / ``formula`` / ``coefficients`` / ``range_nm`` without a ``glass`` name,
beside ``n`` or ``"air"``, and all but ``model`` beside an ``"nd/vd"`` glass. A ``catalog`` is
read as the ``.zmx`` reader reads a ``GCAT`` name
(:func:`raytrace.glass.catalog.canonical_catalog`: any case, a dated Zemax name such as
``"SCHOTT_2017"``). A broken ``[[configurations]]`` block is refused with the message
:func:`raytrace.files.configurations.read_configured` gives. ``scale_to_efl`` scales the block's
lengths too (thicknesses, object distances; ``"inf"`` stays), by the lens's factor
(:func:`efl_scale`), so that the configurations describe the scaled lens.
"""

from __future__ import annotations

import difflib
import math
import re
import tomllib
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import LensError, PrescriptionError
from ..frames import AFTER_MODES, ORDERS, Placement
from ..lens import APERTURE_KINDS, IMAGE_FIELDS, Aperture, ClearAperture, Field, Lens, Surface
from ..materials import AIR, LAMBDA_D, Material, fixed_index
from ..qtype import FORMS, QType
from .output import check_reads_back, write_atomic
from .text import decode_text, read_bytes, solve_paraxial_image

WHAT = "a TOML lens prescription"

PROVENANCES = ("patent", "derived", "rescaled")

# Canonical key -> accepted spellings (the first is the one the writer uses).
_SURFACE_KEYS: dict[str, tuple[str, ...]] = {
    "r": ("r", "radius"),
    "c": ("c", "curvature"),
    "t": ("t", "thickness"),
    "glass": ("glass", "material"),
    "catalog": ("catalog",),
    "model": ("model",),
    "formula": ("formula",),
    "coefficients": ("coefficients",),
    "range_nm": ("range_nm",),
    "n": ("n", "index"),
    "sd": ("sd", "semi_diameter"),
    "k": ("k", "conic"),
    "asph": ("asph", "aspheric"),
    "qtype": ("qtype",),
    "stop": ("stop",),
    "label": ("label",),
    "decenter": ("decenter",),
    "tilt": ("tilt",),
    "order": ("order",),
    "after": ("after",),
    "mirror": ("mirror",),
    "type": ("type",),
    "aperture": ("aperture",),
}
_PLACEMENT_KEYS = ("decenter", "tilt", "order")
_CLEAR_APERTURE_KEYS = ("circle", "rectangle", "ellipse", "center")
_QTYPE_KEYS = ("form", "norm_radius", "a")
_TOP_KEYS = (
    "name",
    "source",
    "provenance",
    "notes",
    "units",
    "wavelength",
    "wavelengths",
    "weights",
    "reference_wavelength",
    "temperature_c",
    "pressure_atm",
    "scale_to_efl",
    "object",
    "aperture",
    "field",
    "surfaces",
    "image",
    # [[configurations]] (thicknesses per focus / zoom position) are read by
    # raytrace.files.configurations; the lens read here is the base configuration, and a
    # broken block is refused here too (_check_configurations).
    "configurations",
)
_OBJECT_KEYS = ("distance", "glass", "catalog", "model", "n", "formula", "coefficients", "range_nm")
_APERTURE_KEYS = tuple(APERTURE_KINDS)
_FIELD_KEYS = ("angle", "height", *IMAGE_FIELDS)

_PROVENANCE_RE = re.compile(r"provenance: (patent|derived|rescaled)(\n|$)")


# --------------------------------------------------------------------------------------------
# Locating things in the raw text (tomllib gives no positions for values)
# --------------------------------------------------------------------------------------------


class _Source:
    """The raw text of a file plus helpers that find the line of a key, table or surface."""

    def __init__(self, text: str, path: str | None) -> None:
        self.text = text
        self.path = path
        self.lines = text.splitlines()
        self.surface_lines = _surface_lines(text)

    def error(
        self, message: str, line: int | None = None, surface: int | None = None
    ) -> PrescriptionError:
        return PrescriptionError(message, path=self.path, line=line, surface=surface)

    @property
    def last_line(self) -> int:
        return max(1, len(self.lines))

    def key_line(self, table: str, key: str | None = None) -> int | None:
        """Line of ``key`` inside ``[table]`` (``table=""`` for the root); falls back to the
        table header, then to a root ``table = {...}`` line. None when nothing matches."""
        current = ""
        header_line = None
        key_re = re.compile(r"^\s*" + re.escape(key) + r"\s*=") if key else None
        for i, raw in enumerate(self.lines, start=1):
            m = re.match(r"^\s*\[\[?\s*([A-Za-z0-9_.\-\"' ]+?)\s*\]\]?\s*(#.*)?$", raw)
            if m:
                current = m.group(1).strip()
                if current == table:
                    header_line = i
                continue
            if key_re is not None and current == table and key_re.match(raw):
                return i
        if header_line is not None:
            return header_line
        if table:
            return self.key_line("", table)
        return None

    def surface_line(self, i: int) -> int | None:
        """Line of the 0-based surface ``i``."""
        if len(self.surface_lines) > i:
            return self.surface_lines[i]
        return self.key_line("", "surfaces")


def _surface_lines(text: str) -> list[int]:
    """1-based line of each surface: each ``{`` opening an inline table directly inside the
    ``surfaces = [ ... ]`` array (strings and comments skipped), or each ``[[surfaces]]`` header."""
    m = re.search(r"(?m)^[ \t]*surfaces[ \t]*=[ \t]*\[", text)
    if m is None:
        return [
            text.count("\n", 0, h.start()) + 1
            for h in re.finditer(r"(?m)^[ \t]*\[\[[ \t]*surfaces[ \t]*\]\]", text)
        ]
    out: list[int] = []
    line = text.count("\n", 0, m.end()) + 1
    i, n = m.end(), len(text)
    brackets, braces = 1, 0
    while i < n and brackets > 0:
        ch = text[i]
        if ch == "\n":
            line += 1
        elif ch == "#":
            j = text.find("\n", i)
            i = n if j < 0 else j
            continue
        elif ch in "\"'":
            delim = ch * 3 if text.startswith(ch * 3, i) else ch
            j = i + len(delim)
            while j < n and not text.startswith(delim, j):
                if ch == '"' and text[j] == "\\":
                    j += 1
                j += 1
            line += text.count("\n", i, min(j, n))
            i = j + len(delim)
            continue
        elif ch == "[":
            brackets += 1
        elif ch == "]":
            brackets -= 1
        elif ch == "{":
            if braces == 0 and brackets == 1:
                out.append(line)
            braces += 1
        elif ch == "}":
            braces -= 1
        i += 1
    return out


# --------------------------------------------------------------------------------------------
# Value helpers
# --------------------------------------------------------------------------------------------


def _suggest(key: str, allowed: dict[str, tuple[str, ...]]) -> str:
    names = {alias: canon for canon, aliases in allowed.items() for alias in aliases}
    close = difflib.get_close_matches(key.lower(), list(names), n=1, cutoff=0.6)
    if not close:
        return ""
    spellings = allowed[names[close[0]]]
    if len(spellings) > 1:
        return " (did you mean " + "/".join(f"'{s}'" for s in reversed(spellings)) + "?)"
    return f" (did you mean '{spellings[0]}'?)"


def _check_keys(
    src: _Source,
    table: dict[str, Any],
    allowed: dict[str, tuple[str, ...]],
    where: str,
    line: int | None | Callable[[str], int | None],
    surface: int | None = None,
) -> None:
    """Reject keys not in ``allowed`` with a "did you mean" (``line`` may be a function of the
    key)."""
    flat = {a for aliases in allowed.values() for a in aliases}
    for key in table:
        if key not in flat:
            sugg = _suggest(key, allowed)
            if not sugg and key in _TOP_KEYS and where.startswith("["):
                sugg = (
                    f" ('{key}' belongs at the top of the file: top-level keys and the surfaces "
                    "array must come before the first [table] header)"
                )
            known = ", ".join(sorted({a for aliases in allowed.values() for a in aliases}))
            raise src.error(
                f"unknown key '{key}' in {where}{sugg}; known keys: {known}",
                line=line(key) if callable(line) else line,
                surface=surface,
            )


def _one_of(
    src: _Source,
    table: dict[str, Any],
    canon: str,
    allowed: dict[str, tuple[str, ...]],
    line: int | None,
    surface: int | None = None,
) -> Any:
    """The value under any spelling of ``canon`` (None if absent); error if given twice."""
    given = [a for a in allowed[canon] if a in table]
    if len(given) > 1:
        raise src.error(
            f"'{given[0]}' and '{given[1]}' are the same key: give only one", line, surface
        )
    return table[given[0]] if given else None


def _number(
    src: _Source,
    value: Any,
    what: str,
    line: int | None,
    surface: int | None = None,
    allow_inf: bool = False,
) -> float:
    """A finite float (or +inf when ``allow_inf`` and the value is ``"inf"`` / ``inf``)."""
    if isinstance(value, str) and allow_inf and value.strip().lower() in ("inf", "infinity"):
        return math.inf
    if isinstance(value, bool) or not isinstance(value, int | float):
        expect = 'a number or "inf"' if allow_inf else "a number"
        raise src.error(f"{what} must be {expect}, got {value!r}", line, surface)
    try:
        v = float(value)
    except OverflowError:
        raise src.error(
            f"{what}: the number is too large ({str(value)[:20]}...)", line, surface
        ) from None
    if math.isnan(v) or (math.isinf(v) and not (allow_inf and v > 0)):
        raise src.error(f"{what} must be a finite number, got {value!r}", line, surface)
    return v


_GLASS_KEYS = ("catalog", "model", "formula", "coefficients", "range_nm")
_PRIVATE_EXAMPLE = (
    'glass = "NAME", catalog = "private", formula = <id>, coefficients = [...] for a glass '
    "defined in the file"
)


def _keys_text(keys: list[str]) -> tuple[str, str, str]:
    """("catalog and model", "do", "them") for naming the keys in a refusal."""
    if len(keys) == 1:
        return keys[0], "does", "it"
    return ", ".join(keys[:-1]) + " and " + keys[-1], "do", "them"


def _stray_glass_keys(
    src: _Source,
    glass: Any,
    n: Any,
    extra: dict[str, Any],
    line: int | None,
    surface: int | None,
    place: str,
) -> None:
    """Refuse glass keys (catalog, model, formula, coefficients, range_nm) that the medium
    written would ignore: none without a glass name, none beside n or air, and only model beside
    an nd/vd model glass (a glass defined in the file takes the private keys with its name)."""
    if not extra:
        return
    keys = list(extra)
    names, does, them = _keys_text(keys)
    first = keys[0]
    if glass is None and n is None:
        if first == "model":
            example = f'glass = "1.5168/64.17", model = "{extra[first]}"'
        elif first == "catalog" and str(extra[first]).strip().lower() != "private":
            example = f'glass = "N-BK7", catalog = "{extra[first]}"'
        else:
            example = _PRIVATE_EXAMPLE
        raise src.error(
            f"{first} = {extra[first]!r} needs a glass name {place} (e.g. {example}); without "
            f"glass the medium is air: add the glass, or drop {names}",
            line,
            surface,
        )
    if n is not None:
        raise src.error(
            f"{names} {does} not apply to a fixed index n = {n!r}: drop {them}, or give the "
            'glass by name instead of n (glass = "N-BK7", catalog = "Schott"; glass = '
            '"nd/vd" for a model glass)',
            line,
            surface,
        )
    if isinstance(glass, str) and glass.strip().lower() == "air":
        raise src.error(f'{names} {does} not apply to glass = "air": drop {them}', line, surface)
    if _nd_vd(glass) is not None:
        keys = [k for k in keys if k != "model"]  # model picks an nd/vd glass's dispersion law
        if keys:
            names, does, them = _keys_text(keys)
            if "catalog" in keys and str(extra["catalog"]).strip().lower() != "private":
                instead = 'give the catalog glass by name (glass = "N-BK7", catalog = "Schott")'
            else:
                instead = "define the glass by name: " + _PRIVATE_EXAMPLE
            raise src.error(
                f"{names} {does} not apply to the model glass {glass!r} (nd/vd): drop "
                f"{them}, or {instead}",
                line,
                surface,
            )


def _nd_vd(glass: Any) -> tuple[float, float] | None:
    """(nd, vd) of an ``"nd/vd"`` glass string (any finite numbers), else None."""
    if not isinstance(glass, str):
        return None
    parts = glass.strip().split("/")
    if len(parts) != 2:
        return None
    try:
        nd, vd = float(parts[0]), float(parts[1])
    except ValueError:
        return None
    if math.isfinite(nd) and math.isfinite(vd):
        return nd, vd
    return None


def _material(
    src: _Source,
    glass: Any,
    n: Any,
    line: int | None,
    surface: int | None = None,
    catalog: Any = None,
    model: Any = None,
    private: dict[str, Any] | None = None,
    place: str = "on the same line",
) -> Material:
    if glass is not None and n is not None:
        raise src.error('give either glass = "..." or n = <index>, not both', line, surface)
    if catalog is not None and not isinstance(catalog, str):
        raise src.error(f"catalog must be a string, got {catalog!r}", line, surface)
    if model is not None and not isinstance(model, str):
        raise src.error(f"model must be a string, got {model!r}", line, surface)
    given = {k: v for k, v in (private or {}).items() if v is not None}
    extra = {"catalog": catalog, "model": model, **given}
    extra = {k: extra[k] for k in _GLASS_KEYS if extra.get(k) is not None}
    _stray_glass_keys(src, glass, n, extra, line, surface, place)
    if n is not None:
        v = _number(src, n, "n (fixed refractive index)", line, surface)
        if v < 1.0:
            raise src.error(f"n (fixed refractive index) must be >= 1, got {v!r}", line, surface)
        try:  # at most raytrace.materials.INDEX_RANGE's upper bound
            return fixed_index(v)
        except ValueError as e:
            raise src.error(f"n (fixed refractive index): {e}", line, surface) from None
    if glass is None:
        return AIR
    help_ = (
        'use a catalog name (e.g. "N-BK7", optionally with catalog = "Schott"), "nd/vd" '
        '(e.g. "1.5168/64.17"), "air", or n = <index> for a fixed index'
    )
    if not isinstance(glass, str):
        raise src.error(f"glass must be a string, got {glass!r}: {help_}", line, surface)
    text = glass.strip()
    if text.lower() == "air":
        return AIR
    ndvd = _nd_vd(text)
    if ndvd is not None:
        nd, vd = ndvd
        if nd < 1.0 or vd <= 0.0:
            raise src.error(
                f"glass {glass!r}: nd must be >= 1 and vd > 0 (got nd={nd!r}, vd={vd!r})",
                line,
                surface,
            )
        try:  # within raytrace.materials.INDEX_RANGE and ABBE_RANGE
            return Material("model", nd, vd, model=model or "")
        except ValueError as e:
            raise src.error(f"glass {glass!r}: {e}", line, surface) from None
    if model is not None:
        raise src.error(f"model = {model!r} applies to an nd/vd model glass only", line, surface)
    if given or (catalog or "").strip().lower() == "private":
        return _private(src, text, catalog, given, line, surface)
    from ..glass.catalog import CATALOGS, canonical_catalog, lookup_glass

    vendor = None
    if catalog is not None:
        # the catalog names the .zmx reader's GCAT accepts: any case, a dated Zemax file name
        vendor = canonical_catalog(catalog)
        if vendor is None:
            raise src.error(
                f"unknown catalog {catalog!r}: the shipped catalogs are {', '.join(CATALOGS)} "
                '(any case; a dated name such as "SCHOTT_2017" means its vendor), or "private" '
                "for a glass defined in the file",
                line,
                surface,
            )
    try:
        g = lookup_glass(text, [vendor] if vendor else None, first_catalog_wins=bool(vendor))
    except PrescriptionError as e:
        raise src.error(e.reason, line, surface) from None
    if vendor and g.catalog != vendor:
        raise src.error(
            f"glass {text!r} is not in the {vendor} catalog (found in {g.catalog}): give "
            f'catalog = "{g.catalog}", or check the glass name',
            line,
            surface,
        )
    return g.material


def _private(
    src: _Source, name: str, catalog: Any, given: dict[str, Any], line, surface
) -> Material:
    """A glass defined in the file: catalog = "private", formula, coefficients, range_nm."""
    from ..glass import PRIVATE, private_material

    if (
        (catalog or "").strip().lower() != PRIVATE
        or "formula" not in given
        or ("coefficients" not in given)
    ):
        raise src.error(
            f'glass {name!r}: a glass defined in the file needs catalog = "{PRIVATE}", formula '
            "and coefficients together (formula ids: raytrace.glass.FORMULAS)",
            line,
            surface,
        )
    formula = given["formula"]
    if isinstance(formula, bool) or not isinstance(formula, int | str):
        raise src.error(f"glass {name!r}: formula must be an id, got {formula!r}", line, surface)
    coef = given["coefficients"]
    if not isinstance(coef, list):
        raise src.error(f"glass {name!r}: coefficients must be a list of numbers", line, surface)
    coef = [_number(src, c, f"glass {name!r} coefficient", line, surface) for c in coef]
    rng = given.get("range_nm", [0.0, "inf"])
    if not isinstance(rng, list) or len(rng) != 2:
        raise src.error(f"glass {name!r}: range_nm must be [min, max] in nm", line, surface)
    lo, hi = (_number(src, v, "range_nm", line, surface, allow_inf=True) for v in rng)
    try:
        return private_material(name, formula, coef, (lo, hi))
    except ValueError as e:
        raise src.error(str(e), line, surface) from None


def _wavelengths(src: _Source, data: dict[str, Any]) -> dict[str, Any]:
    """The Lens keywords wavelength, wavelengths, weights from ``wavelength`` (one, the
    reference) or ``wavelengths`` + optional ``weights`` + ``reference_wavelength``."""
    from ..units import UnitError, wavelength_nm

    def nm(value, key):
        line = src.key_line("", key)
        # a number is nm; a string may carry its unit ("587.6nm", "0.5876um"), as on the CLI
        v = value if isinstance(value, str) else _number(src, value, f"{key} (nm)", line)
        try:
            return wavelength_nm(v, key)
        except UnitError as e:
            raise src.error(str(e), line) from None

    one = nm(data["wavelength"], "wavelength") if "wavelength" in data else None
    ref = (
        nm(data["reference_wavelength"], "reference_wavelength")
        if "reference_wavelength" in data
        else None
    )
    if one is not None and ref is not None and one != ref:
        raise src.error(
            f"wavelength = {one!r} and reference_wavelength = {ref!r} disagree: give one",
            src.key_line("", "reference_wavelength"),
        )
    ref = ref if ref is not None else one
    if "wavelengths" not in data:
        if "weights" in data:
            raise src.error("weights need wavelengths = [...]", src.key_line("", "weights"))
        return {"wavelength": LAMBDA_D if ref is None else ref}
    wl_line = src.key_line("", "wavelengths")
    raw = data["wavelengths"]
    if not isinstance(raw, list) or not raw:
        raise src.error("wavelengths must be a non-empty list of nm", wl_line)
    wls = tuple(nm(v, "wavelengths") for v in raw)
    if ref is None:
        if len(wls) > 1:
            raise src.error(
                "several wavelengths need reference_wavelength = one of them (the primary "
                "wavelength for paraxial data and solves)",
                wl_line,
            )
        ref = wls[0]
    if ref not in wls:
        raise src.error(
            f"the reference wavelength {ref!r} nm is not in wavelengths = {list(wls)}",
            src.key_line("", "reference_wavelength") or wl_line,
        )
    weights: tuple[float, ...] = ()
    if "weights" in data:
        w_line = src.key_line("", "weights")
        raw_w = data["weights"]
        if not isinstance(raw_w, list) or len(raw_w) != len(wls):
            raise src.error(f"weights must list one number per wavelength ({len(wls)})", w_line)
        weights = tuple(_number(src, v, "weights", w_line) for v in raw_w)
        if any(v < 0.0 for v in weights):
            raise src.error("weights must not be negative", w_line)
    return {"wavelength": ref, "wavelengths": wls, "weights": weights}


def _environment(src: _Source, data: dict[str, Any]) -> dict[str, Any]:
    out = {}
    for key, lo, hi in (("temperature_c", -273.15, 1000.0), ("pressure_atm", 0.0, 100.0)):
        if key in data:
            line = src.key_line("", key)
            v = _number(src, data[key], key, line)
            if not lo <= v <= hi:
                raise src.error(f"{key} = {v!r} is out of range ({lo:g} to {hi:g})", line)
            out[key] = v
    return out


def _string(src: _Source, data: dict[str, Any], key: str, default: str | None) -> str | None:
    v = data.get(key, default)
    if v is not None and not isinstance(v, str):
        raise src.error(f"{key} must be a string, got {v!r}", src.key_line("", key))
    return v


def _table(src: _Source, data: dict[str, Any], key: str) -> dict[str, Any] | None:
    v = data.get(key)
    if v is not None and not isinstance(v, dict):
        raise src.error(
            f"{key} must be a table, e.g. [{key}] or {key} = {{ ... }}", src.key_line("", key)
        )
    return v


# --------------------------------------------------------------------------------------------
# Reading
# --------------------------------------------------------------------------------------------


def read_lens(path: str | Path) -> Lens:
    """Read a prescription file (see the module docstring) into a validated :class:`Lens`."""
    return loads(read_bytes(path), path=str(path))


def loads(text: str | bytes, *, path: str | Path | None = None) -> Lens:
    """Parse prescription text into a validated :class:`Lens` (``path`` is used in messages and
    stored in ``Lens.path``; the default name is its stem)."""
    spath = None if path is None else str(path)
    if isinstance(text, bytes):
        text = decode_text(text, spath, WHAT, latin1=False)
    src = _Source(text, spath)
    if not text.strip():
        raise src.error("the file is empty: expected a TOML lens prescription", line=1)
    try:
        data = tomllib.loads(text)
    except RecursionError:
        raise src.error("the TOML nests too deeply to be a lens prescription", line=1) from None
    except tomllib.TOMLDecodeError as e:
        msg = str(e)
        m = re.search(r"at line (\d+)", msg)
        line = int(m.group(1)) if m else None
        if "inline table" in msg or "key part" in msg:
            msg += " (each surface is an inline table { key = value, ... } on ONE line)"
        raise src.error(f"TOML syntax error: {msg}", line=line) from None
    if not data:
        raise src.error("the file holds no prescription (only comments or blank lines)", line=1)
    return _build(src, data)[0]


def build_lens(
    data: dict[str, Any], *, text: str = "", path: str | Path | None = None
) -> tuple[Lens, float]:
    """The validated :class:`Lens` of parsed TOML ``data`` and the factor ``scale_to_efl``
    multiplied its lengths by (1.0 without the key); ``text`` (the file's text) and ``path``
    place the errors, as :func:`loads` does."""
    return _build(_Source(text, None if path is None else str(path)), data)


def efl_scale(data: dict[str, Any], *, text: str = "", path: str | Path | None = None) -> float:
    """The factor ``scale_to_efl`` multiplies every length of the lens in parsed TOML ``data``
    by (1.0 without the key): what :mod:`.configurations` scales the ``[[configurations]]``
    lengths by, so that they describe the scaled lens. Builds the lens (its EFL gives the
    factor); ``text`` (the file's text) and ``path`` place the errors, as :func:`loads` does."""
    if "scale_to_efl" not in data:
        return 1.0
    return build_lens(data, text=text, path=path)[1]


def _build(src: _Source, data: dict[str, Any]) -> tuple[Lens, float]:
    """The lens of ``data`` and the factor ``scale_to_efl`` scaled it by (1.0 without it)."""
    top = {k: (k,) for k in _TOP_KEYS}
    _check_keys(src, data, top, "the file", lambda k: src.key_line("", k))
    name = _string(src, data, "name", None)
    if name is None:
        name = Path(src.path).stem if src.path else "lens"
    source = _string(src, data, "source", "") or ""
    notes = _string(src, data, "notes", None)
    prov = _string(src, data, "provenance", None)
    if prov is not None and prov not in PROVENANCES:
        raise src.error(
            f"provenance must be one of {', '.join(PROVENANCES)}, got {prov!r}",
            src.key_line("", "provenance"),
        )
    units = _string(src, data, "units", "mm")
    if units != "mm":
        raise src.error(
            f'units must be "mm" (the only unit supported), got {units!r}',
            src.key_line("", "units"),
        )
    wl_kw = _wavelengths(src, data)
    env_kw = _environment(src, data)
    scale_to = None
    if "scale_to_efl" in data:
        line = src.key_line("", "scale_to_efl")
        scale_to = _number(src, data["scale_to_efl"], "scale_to_efl (mm)", line)
        if scale_to <= 0.0:
            raise src.error(f"scale_to_efl must be positive, got {scale_to!r}", line)
        if prov is None:
            prov = "rescaled"
        elif prov == "patent":
            raise src.error(
                "a lens scaled with scale_to_efl is no longer the patent's numbers: "
                'use provenance = "rescaled"',
                src.key_line("", "provenance"),
            )

    # [object]
    object_distance, object_material = math.inf, AIR
    obj = _table(src, data, "object")
    if obj is not None:
        _check_keys(
            src,
            obj,
            {k: (k,) for k in _OBJECT_KEYS},
            "[object]",
            lambda k: src.key_line("object", k),
        )
        if "distance" in obj:
            line = src.key_line("object", "distance")
            object_distance = _number(
                src, obj["distance"], "object distance (mm)", line, allow_inf=True
            )
            if object_distance <= 0.0:
                raise src.error(
                    "object distance must be positive (a magnitude from the object plane to the "
                    f'first vertex) or "inf", got {object_distance!r}',
                    line,
                )
        medium_key = next((k for k in ("glass", "n", *_GLASS_KEYS) if k in obj), "glass")
        object_material = _material(
            src,
            obj.get("glass"),
            obj.get("n"),
            src.key_line("object", medium_key),
            catalog=obj.get("catalog"),
            model=obj.get("model"),
            private={k: obj.get(k) for k in ("formula", "coefficients", "range_nm")},
            place="in [object]",
        )

    aperture = _choice(src, data, "aperture", _APERTURE_KEYS, Aperture)
    fld, image_field = _field(src, data, math.isfinite(object_distance))
    image_placement = None
    img = _table(src, data, "image")
    if img is not None:
        allowed = {k: (k,) for k in _PLACEMENT_KEYS}
        _check_keys(src, img, allowed, "[image]", lambda k: src.key_line("image", k))
        image_placement = _placement(src, img, "[image]", src.key_line("image"), None)

    surfaces = _surfaces(src, data, object_material)

    lens_notes = notes
    if prov is not None:
        lens_notes = f"provenance: {prov}" + ("" if notes is None else "\n" + notes)
    lens_notes = lens_notes or ""

    last_t = surfaces[-1].thickness
    solve = "gaussian" if isinstance(last_t, str) else None
    if solve:
        surfaces[-1] = replace(surfaces[-1], thickness=0.0)
    lens = _make_lens(
        src,
        name=name,
        surfaces=tuple(surfaces),
        aperture=aperture,
        field=fld,
        object_distance=object_distance,
        **wl_kw,
        **env_kw,
        source=source,
        notes=lens_notes,
        units="mm",
        object_material=object_material,
        path=src.path,
        image_placement=image_placement,
    )
    if solve:
        lens = _solve_gaussian(src, lens)
    factor = 1.0
    if scale_to is not None:
        lens, factor = _scale_to_efl(src, lens, scale_to)
    if image_field is not None:
        from ..errors import TraceError
        from ..trace.image_field import field_for_image_height

        kind, height = image_field
        try:
            lens = replace(lens, field=field_for_image_height(lens, height, kind))
        except (LensError, TraceError, ValueError) as e:
            raise src.error(
                f"field {kind} = {height!r}: {e}", src.key_line("field", kind)
            ) from None
    if "configurations" in data:
        _check_configurations(src, data, lens, factor)
    return lens, factor


def _check_configurations(
    src: _Source, data: dict[str, Any], lens: Lens, factor: float = 1.0
) -> None:
    """Refuse a broken ``[[configurations]]`` block (read by :mod:`.configurations`) with the
    message :func:`~raytrace.files.configurations.read_configured` gives, at the line of the
    configuration at fault (the lens itself does not use the block). ``factor``: the
    ``scale_to_efl`` factor, which the block's lengths are scaled by."""
    from .configurations import Configurations, check_surfaces, configurations_from_toml

    tables = data["configurations"]
    try:
        confs = configurations_from_toml(data, path=src.path, scale=factor)
        check_surfaces(lens, confs)
    except PrescriptionError as e:
        headers = [
            i
            for i, raw in enumerate(src.lines, start=1)
            if re.match(r"^\s*\[\[\s*configurations\s*\]\]", raw)
        ]
        line = src.key_line("", "configurations") or src.key_line("configurations")
        if isinstance(tables, list) and len(headers) == len(tables):
            # the first table that fails on its own is the one at fault (each is independent)
            for t, header in zip(tables, headers, strict=True):
                try:
                    one = configurations_from_toml(
                        {"configurations": [t]}, path=src.path, scale=factor
                    )
                    check_surfaces(lens, Configurations(one.configurations, 1, src.path or ""))
                except PrescriptionError:
                    line = header
                    break
        raise src.error(e.reason, line) from None


def _field(src: _Source, data: dict[str, Any], finite: bool) -> tuple[Field, Any]:
    """(Field, image_field): the [field] table — one kind with its value, optional ``points``;
    an image-space kind gives a provisional field and ``(kind, height)`` to solve later."""
    t = _table(src, data, "field")
    wanted = " / ".join(_FIELD_KEYS)
    if t is None:
        raise src.error(f"missing [field] table: give exactly one of {wanted}", line=src.last_line)
    allowed = {k: (k,) for k in (*_FIELD_KEYS, "points")}
    _check_keys(src, t, allowed, "[field]", lambda k: src.key_line("field", k))
    given = [k for k in _FIELD_KEYS if k in t]
    if len(given) != 1:
        got = ", ".join(given) if given else "none"
        raise src.error(
            f"[field] needs exactly one of {wanted} (got: {got})", src.key_line("field")
        )
    kind = given[0]
    line = src.key_line("field", kind)
    value = _number(src, t[kind], f"field {kind}", line)
    if value < 0.0:
        raise src.error(f"field {kind} must be positive, got {value!r}", line)
    if kind == "angle" and value >= 90.0:
        raise src.error(f"field angle must be below 90 degrees, got {value!r}", line)
    pts: tuple[tuple[float, float], ...] = ()
    if "points" in t:
        pl = src.key_line("field", "points")
        raw = t["points"]
        if not isinstance(raw, list) or not all(isinstance(p, list) and len(p) == 2 for p in raw):
            raise src.error("field points must be a list of [x, y] pairs", pl)
        pts = tuple(
            (_number(src, a, "field point x", pl), _number(src, b, "field point y", pl))
            for a, b in raw
        )
    if kind in IMAGE_FIELDS:
        return Field("height" if finite else "angle", 0.0), (kind, value)
    return Field(kind, value, pts), None


def _triple_value(src: _Source, value: Any, what: str, line, no) -> tuple[float, float, float]:
    if not isinstance(value, list) or len(value) not in (2, 3):
        raise src.error(f"{what} must be a list of 2 or 3 numbers, got {value!r}", line, no)
    vals = [_number(src, v, what, line, no) for v in value]
    return (vals[0], vals[1], vals[2] if len(vals) == 3 else 0.0)


def _placement(src: _Source, e: dict[str, Any], where: str, line, no) -> Placement | None:
    """A Placement from ``decenter``, ``tilt``, ``order`` keys (None when none is given)."""
    if not any(k in e for k in _PLACEMENT_KEYS):
        return None
    dec = _triple_value(src, e["decenter"], "decenter (mm)", line, no) if "decenter" in e else None
    tilt = _triple_value(src, e["tilt"], "tilt (degrees)", line, no) if "tilt" in e else None
    order = e.get("order", ORDERS[0])
    if order not in ORDERS:
        raise src.error(f"order must be one of {', '.join(ORDERS)}, got {order!r}", line, no)
    return Placement(dec or (0.0, 0.0, 0.0), tilt or (0.0, 0.0, 0.0), order)


def _clear_aperture(src: _Source, value: Any, line, no) -> ClearAperture:
    if not isinstance(value, dict):
        raise src.error(
            "aperture must be a table { circle = r | rectangle = [hx, hy] | ellipse = [a, b], "
            f"center = [x0, y0] }}, got {value!r}",
            line,
            no,
        )
    _check_keys(src, value, {k: (k,) for k in _CLEAR_APERTURE_KEYS}, "aperture", line, no)
    shapes = [k for k in ("circle", "rectangle", "ellipse") if k in value]
    if len(shapes) != 1:
        raise src.error("aperture needs exactly one of circle / rectangle / ellipse", line, no)
    shape = shapes[0]
    if shape == "circle":
        r = _number(src, value["circle"], "aperture circle radius (mm)", line, no)
        hx = hy = r
    else:
        hx, hy, _ = _triple_value(src, value[shape], f"aperture {shape} (mm)", line, no)
    x0 = y0 = 0.0
    if "center" in value:
        x0, y0, _ = _triple_value(src, value["center"], "aperture center (mm)", line, no)
    try:
        return ClearAperture(shape, hx, hy, x0, y0)
    except ValueError as e:
        raise src.error(str(e), line, no) from None


def _choice(src: _Source, data: dict[str, Any], table: str, keys: tuple[str, ...], cls: type):
    """The single ``kind = value`` entry of [aperture] / [field]."""
    t = _table(src, data, table)
    wanted = " / ".join(keys)
    if t is None:
        raise src.error(
            f"missing [{table}] table: give exactly one of {wanted}", line=src.last_line
        )
    _check_keys(src, t, {k: (k,) for k in keys}, f"[{table}]", lambda k: src.key_line(table, k))
    given = [k for k in keys if k in t]
    if len(given) != 1:
        got = ", ".join(given) if given else "none"
        raise src.error(
            f"[{table}] needs exactly one of {wanted} (got: {got})", line=src.key_line(table)
        )
    kind = given[0]
    line = src.key_line(table, kind)
    value = _number(src, t[kind], f"{table} {kind}", line)
    if value < 0.0 or (value == 0.0 and table == "aperture"):
        raise src.error(f"{table} {kind} must be positive, got {value!r}", line)
    if kind == "angle" and value >= 90.0:
        raise src.error(f"field angle must be below 90 degrees, got {value!r}", line)
    return cls(kind, value)


def _surfaces(src: _Source, data: dict[str, Any], object_material: Material = AIR) -> list[Surface]:
    raw = data.get("surfaces")
    if raw is None:
        raise src.error(
            "missing surfaces = [ ... ] (one inline table per surface; it must come before "
            "the first [table] header)",
            line=src.last_line,
        )
    sline = src.key_line("", "surfaces")
    if not isinstance(raw, list) or not raw:
        raise src.error("surfaces must be a non-empty array of { ... } tables", sline)
    out: list[Surface] = []
    n = len(raw)
    for i, entry in enumerate(raw):
        no = i + 1
        line = src.surface_line(i)
        if not isinstance(entry, dict):
            raise src.error(f"each surface must be a {{ ... }} table, got {entry!r}", line, no)
        out.append(_surface(src, entry, line, no, last=(i == n - 1)))
    # media of mirrors and coordinate breaks (the one before), thickness signs
    direction = 1.0
    placed = any(s.is_placed or s.coordinate_break for s in out)
    for i, srf in enumerate(out):
        no, line = i + 1, src.surface_line(i)
        before = object_material if i == 0 else out[i - 1].material
        given = raw[i].get("glass", raw[i].get("material", raw[i].get("n", raw[i].get("index"))))
        if srf.mirror or srf.coordinate_break:
            if given is not None and srf.material != before:
                what = "a mirror" if srf.mirror else "a coordinate break"
                raise src.error(
                    f"{what} returns the light into the medium before it "
                    f"({before.describe()}): remove the glass", line, no
                )  # fmt: skip
            out[i] = srf = replace(srf, material=before)
        if srf.mirror:
            direction = -direction
        t = srf.thickness
        if isinstance(t, str) or i == n - 1 or srf.coordinate_break:
            continue
        # a glass of thickness 0 before a coordinate break or placed surface (a prism's mirror
        # face, as .zmx files write it) is kept, as the .zmx reader keeps it
        nxt = out[i + 1]
        folds = nxt.coordinate_break or nxt.is_placed
        if not srf.material.is_air and (t * direction < 0.0 or (t == 0.0 and not folds)):
            if direction > 0:
                raise src.error(f"glass thickness must be positive, got t = {t!r}", line, no)
            raise src.error(
                f"glass thickness must be negative after an odd number of mirrors, got t = {t!r}",
                line,
                no,
            )
        if (
            srf.material.is_air
            and t * direction < 0.0
            and not placed
            and not any(x.mirror for x in out)
        ):
            raise src.error(f"air thickness must not be negative, got t = {t!r}", line, no)

    stops = [i for i, s in enumerate(out) if s.stop]
    if not stops:
        raise src.error("no surface is the aperture stop: add stop = true to one surface", sline)
    if len(stops) > 1:
        listed = " and ".join(str(i + 1) for i in stops)
        raise src.error(
            f"two or more stops (surfaces {listed}): exactly one surface may have stop = true",
            src.surface_line(stops[1]),
            stops[1] + 1,
        )
    return out


def _surface(src: _Source, e: dict[str, Any], line: int | None, no: int, last: bool) -> Surface:
    K = _SURFACE_KEYS
    _check_keys(src, e, K, "surface", line, no)
    r = _one_of(src, e, "r", K, line, no)
    c = _one_of(src, e, "c", K, line, no)
    if r is not None and c is not None:
        raise src.error("give either r (radius) or c (curvature), not both", line, no)
    if r is None and c is None:
        raise src.error(
            'missing radius: give r (radius in mm, "inf" for a plane) or c (curvature, 1/mm)',
            line,
            no,
        )
    if r is not None:
        rv = _number(src, r, "r (radius, mm)", line, no, allow_inf=True)
        if rv == 0.0:
            raise src.error('r = 0 is not a surface (use r = "inf" for a plane)', line, no)
        curvature = 0.0 if math.isinf(rv) else 1.0 / rv
    else:
        curvature = _number(src, c, "c (curvature, 1/mm)", line, no)

    material = _material(
        src,
        _one_of(src, e, "glass", K, line, no),
        _one_of(src, e, "n", K, line, no),
        line,
        no,
        catalog=_one_of(src, e, "catalog", K, line, no),
        model=_one_of(src, e, "model", K, line, no),
        private={
            k: _one_of(src, e, k, K, line, no) for k in ("formula", "coefficients", "range_nm")
        },
    )

    t = _one_of(src, e, "t", K, line, no)
    if t is None:
        what = 'distance to the image plane, or "gaussian"' if last else "to the next vertex"
        raise src.error(f"missing thickness t (mm, {what})", line, no)
    thickness: Any
    if isinstance(t, str) and t.strip().lower() == "gaussian":
        if not last:
            raise src.error(
                't = "gaussian" is only allowed on the last surface (it solves the image distance)',
                line,
                no,
            )
        thickness = "gaussian"
    else:
        thickness = _number(src, t, "t (thickness, mm)", line, no)
        # signs are checked by _surfaces (after mirrors thicknesses are negative)

    sd = math.inf
    sdv = _one_of(src, e, "sd", K, line, no)
    if sdv is not None:
        sd = _number(src, sdv, "sd (semi-diameter, mm)", line, no, allow_inf=True)
        if sd <= 0.0:
            raise src.error(f"sd (semi-diameter) must be positive, got {sd!r}", line, no)

    conic = 0.0
    kv = _one_of(src, e, "k", K, line, no)
    if kv is not None:
        conic = _number(src, kv, "k (conic constant)", line, no)

    asph: tuple[float, ...] = ()
    av = _one_of(src, e, "asph", K, line, no)
    if av is not None:
        if not isinstance(av, list):
            raise src.error(f"asph must be a list [A4, A6, ...], got {av!r}", line, no)
        asph = tuple(
            _number(src, a, f"asph[{j}] (A{4 + 2 * j})", line, no) for j, a in enumerate(av)
        )

    qtype = None
    qv = _one_of(src, e, "qtype", K, line, no)
    if qv is not None:
        qtype = _qtype(src, qv, line, no)
        if asph:
            raise src.error(
                "give either asph or qtype (a Q-type surface has no even terms)", line, no
            )

    stop = e.get("stop", False)
    if not isinstance(stop, bool):
        raise src.error(f"stop must be true or false, got {stop!r}", line, no)
    label = e.get("label", "")
    if not isinstance(label, str):
        raise src.error(f"label must be a string, got {label!r}", line, no)

    if math.isfinite(sd) and math.isnan(float(_sag(curvature, conic, asph, sd, qtype))):
        raise src.error(
            f"sd = {sd!r} is larger than the surface allows (|r| = {abs(1.0 / curvature)!r})",
            line,
            no,
        )
    placement = _placement(src, e, "surface", line, no)
    after: Placement | str = "stay"
    if "after" in e:
        a = e["after"]
        if isinstance(a, dict):
            _check_keys(src, a, {k: (k,) for k in _PLACEMENT_KEYS}, "after", line, no)
            after = _placement(src, a, "after", line, no) or "stay"
        elif a in AFTER_MODES:
            after = a
        else:
            raise src.error(
                f"after must be one of {', '.join(AFTER_MODES)} or {{ decenter = [...], tilt = "
                f"[...], order = ... }}, got {a!r}",
                line,
                no,
            )
    mirror = e.get("mirror", False)
    if not isinstance(mirror, bool):
        raise src.error(f"mirror must be true or false, got {mirror!r}", line, no)
    kind = e.get("type", "surface")
    if kind not in ("surface", "coordinate_break"):
        raise src.error(f'type must be "surface" or "coordinate_break", got {kind!r}', line, no)
    cb = kind == "coordinate_break"
    if cb and (curvature != 0.0 or mirror or stop or conic or asph or qtype or math.isfinite(sd)):
        raise src.error(
            "a coordinate break has only decenter, tilt, order and t (it is not traced)", line, no
        )
    aperture = None
    if "aperture" in e:
        aperture = _clear_aperture(src, e["aperture"], line, no)
    return Surface(
        curvature=curvature,
        thickness=thickness,  # type: ignore[arg-type]  ("gaussian" is resolved by the caller)
        material=material,
        semi_diameter=sd,
        stop=stop,
        conic=conic,
        aspheric=asph,
        qtype=qtype,
        label=label,
        line=line,
        placement=placement,
        after=after,
        mirror=mirror,
        coordinate_break=cb,
        aperture=aperture,
    )


def _sag(
    c: float, k: float, asph: tuple[float, ...], r: np.ndarray | float, qtype: QType | None = None
) -> np.ndarray:
    return Surface(c, 0.0, conic=k, aspheric=asph, qtype=qtype).sag(r)


def _qtype(src: _Source, value: Any, line, no) -> QType:
    """``qtype = { form = "qbfs" | "qcon", norm_radius = mm, a = [a0, a1, ...] }``."""
    want = 'qtype = { form = "qbfs" or "qcon", norm_radius = mm, a = [a0, a1, ...] }'
    if not isinstance(value, dict):
        raise src.error(f"expected {want}, got {value!r}", line, no)
    _check_keys(src, value, {k: (k,) for k in _QTYPE_KEYS}, "qtype", line, no)
    form = value.get("form")
    if form not in FORMS:
        raise src.error(f'qtype form must be "qbfs" or "qcon", got {form!r}', line, no)
    if "norm_radius" not in value:
        raise src.error(f"qtype needs norm_radius (mm): {want}", line, no)
    rn = _number(src, value["norm_radius"], "qtype norm_radius (mm)", line, no)
    if not rn > 0.0:
        raise src.error(f"qtype norm_radius must be positive (mm), got {rn!r}", line, no)
    a = value.get("a", [])
    if not isinstance(a, list):
        raise src.error(f"qtype a must be a list [a0, a1, ...] (mm), got {a!r}", line, no)
    terms = tuple(_number(src, v, f"qtype a[{j}] (mm)", line, no) for j, v in enumerate(a))
    return QType(form, rn, terms)


def _lens_error(src: _Source, lens_name: str, err: Exception, default_line: int | None):
    msg = str(err)
    if msg.startswith(lens_name + ": "):
        msg = msg[len(lens_name) + 2 :]
    m = re.match(r"surface (\d+): ", msg)
    if m:
        no = int(m.group(1))
        return src.error(msg[m.end() :], src.surface_line(no - 1), no)
    low = msg.lower()
    for word, (table, key) in {
        "wavelength": ("", "wavelength"),
        "aperture": ("aperture", None),
        "na ": ("aperture", None),
        "field": ("field", None),
        "object": ("object", None),
    }.items():
        if word in low:
            line = src.key_line(table, key) if table else src.key_line("", key)
            if line is not None:
                return src.error(msg, line)
    return src.error(msg, default_line)


def _make_lens(src: _Source, **kw: Any) -> Lens:
    try:
        return Lens(**kw)
    except (LensError, ValueError) as e:
        raise _lens_error(src, kw["name"], e, src.key_line("", "surfaces")) from None


def _solve_gaussian(src: _Source, lens: Lens) -> Lens:
    """Put the image plane at the paraxial image of the lens's own object (``t = "gaussian"``)."""
    n = lens.n_surfaces
    line = src.surface_line(n - 1)
    j = lens.first_placed()
    if j is not None:  # said as a change to the file (paraxial() says it as Python calls)
        where = "the image surface" if j == 0 else f"surface {j}"
        at = src.key_line("image") if j == 0 else src.surface_line(j - 1)
        at_text = f" (line {at})" if at is not None else ""
        raise src.error(
            f't = "gaussian" (the paraxial image solve) needs a centred lens, and {where}'
            f"{at_text} is decentered or tilted: give the last thickness as a number (mm from "
            "the last vertex to the image plane), or remove the decenter / tilt",
            line,
            n,
        )
    return solve_paraxial_image(
        lens,
        lambda message, at: src.error(message, at, n),
        src.surface_lines,
        line,
        _gaussian_refusal,
        trace_error=lambda e: _lens_error(src, lens.name, e, line),
    )


def _gaussian_refusal(d: float) -> str:
    """Why ``t = "gaussian"`` has no image ``d`` mm from the last vertex (infinite or virtual)."""
    if not math.isfinite(d):
        return 't = "gaussian": the paraxial image is at infinity; give the image distance'
    return (
        f't = "gaussian": the paraxial image is virtual ({abs(d):.6g} mm before the last '
        "vertex); give the image distance"
    )


def _scale_to_efl(src: _Source, lens: Lens, target: float) -> tuple[Lens, float]:
    """The lens scaled to EFL ``target`` and the factor (every length multiplied by it)."""
    from ..paraxial import paraxial

    line = src.key_line("", "scale_to_efl")
    try:
        efl = float(paraxial(lens).efl)
    except LensError as e:
        raise _lens_error(src, lens.name, e, line) from None
    factor = target / efl
    if not (math.isfinite(factor) and factor > 0.0):
        raise src.error(
            f"scale_to_efl: the prescription's EFL is {efl:.6g} mm; it cannot be scaled to "
            f"{target!r} mm",
            line,
        )
    scaled = lens.scaled(factor)
    record = (
        f"scaled by {factor!r} from the prescription's EFL {efl!r} mm to EFL {target!r} mm "
        "(scale_to_efl)"
    )
    scaled = replace(scaled, notes=scaled.notes + "\n" + record if scaled.notes else record)
    if lens.image_solve == "gaussian":
        scaled = _solve_gaussian(src, scaled)
    return scaled, factor


def provenance(lens: Lens) -> str | None:
    """The lens's provenance ("patent", "derived", "rescaled") from the first line of its notes,
    or None when the file gave none."""
    m = _PROVENANCE_RE.match(lens.notes)
    return m.group(1) if m else None


# --------------------------------------------------------------------------------------------
# Writing
# --------------------------------------------------------------------------------------------

_HEADER = """\
# orthoscope lens prescription (TOML). Units: mm; wavelength: nm; angles: degrees.
# Light travels left to right (+z); the first vertex is at z = 0.
"""

_COLUMNS = """\
# One surface per line, in the order the light meets them. Columns:
#   r / c   radius of curvature, mm ("inf" = plane; + when the centre of curvature lies to the
#           right of the vertex), or c = curvature 1/mm
#   t       axial thickness to the next vertex, mm; last surface: to the image plane, or
#           "gaussian" = solved to the paraxial image of the object above
#   glass   medium after the surface: a catalog name (with catalog = "Schott", ...), or "nd/vd"
#           model glass; n = fixed index; omitted = air
#   sd      semi-diameter, mm (omitted = unlimited)
#   k       conic constant;  asph = [A4, A6, ...] even-asphere coefficients of r^4, r^6, ...
#   qtype   Forbes Q-type asphere on the conic r, k: { form = "qbfs" | "qcon", norm_radius =
#           mm, a = [a0, a1, ...] mm }
#   stop    true on the aperture stop (exactly one);  label = optional name
#   decenter, tilt, order, after, mirror, type, aperture: placement (mm, degrees right-handed
#           about x, y, z), mirrors and coordinate breaks, clear apertures (lenses/README.md)
"""


def _toml_str(s: str) -> str:
    """A TOML string literal for ``s`` (a literal multi-line string for readable notes)."""
    if (
        "\n" in s
        and "'''" not in s
        and not s.endswith("'")
        and all(ch in "\n\t" or (ch >= " " and ch != "\x7f") for ch in s)
    ):
        return "'''\n" + s + "'''"
    out = []
    for ch in s:
        if ch == "\\":
            out.append("\\\\")
        elif ch == '"':
            out.append('\\"')
        elif ch == "\n":
            out.append("\\n")
        elif ch == "\t":
            out.append("\\t")
        elif ch < " " or ch == "\x7f":
            out.append(f"\\u{ord(ch):04x}")
        else:
            out.append(ch)
    return '"' + "".join(out) + '"'


def _fnum(x: float) -> str:
    """Full-precision TOML number (``"inf"`` for +infinity)."""
    x = float(x)
    if math.isinf(x) and x > 0:
        return '"inf"'
    if not math.isfinite(x):
        raise ValueError(f"cannot write non-finite number {x!r}")
    return repr(x)


def _radius_cell(c: float) -> tuple[str, str]:
    """("r", text) with the shortest radius whose reciprocal is exactly ``c``; ("c", text)
    when no radius reproduces the curvature bit for bit."""
    c = float(c)
    if c == 0.0:
        return "r", '"inf"'
    r0 = 1.0 / c
    candidates = [r0]
    lo = hi = r0
    for _ in range(8):
        lo, hi = math.nextafter(lo, -math.inf), math.nextafter(hi, math.inf)
        candidates += [lo, hi]
    ok = [r for r in candidates if math.isfinite(r) and 1.0 / r == c]
    if not ok:
        return "c", repr(c)
    best = min(ok, key=lambda r: (len(repr(r)), abs(r - r0)))
    return "r", repr(best)


def _material_cells(m: Material) -> list[tuple[str, str] | None]:
    """Two cells (aligned columns): the medium, and its catalog or model-glass law if any."""
    if m.is_air:
        return [None, None]
    if m.kind == "index":
        return [("n", repr(float(m.nd))), None]
    if m.kind == "catalog":
        cells = [("glass", _toml_str(m.name)), ("catalog", _toml_str(m.catalog))]
        from ..glass import PRIVATE

        if m.catalog == PRIVATE:
            f = repr(m.formula) if isinstance(m.formula, int) else _toml_str(str(m.formula))
            coef = "[" + ", ".join(repr(float(c)) for c in m.coefficients) + "]"
            lo, hi = m.wavelength_range_nm
            cells[1] = (
                "catalog",
                f'"{PRIVATE}", formula = {f}, coefficients = {coef}, '
                f"range_nm = [{_fnum(lo)}, {_fnum(hi)}]",
            )
        return cells
    glass = ("glass", '"' + f"{float(m.nd)!r}/{float(m.vd)!r}" + '"')
    return [glass, ("model", _toml_str(m.model)) if m.model != "cauchy2" else None]


def _list(values) -> str:
    return "[" + ", ".join(repr(float(v) + 0.0) for v in values) + "]"


def _placement_text(p: Placement) -> str:
    """``{ decenter = [...], tilt = [...], order = ... }`` body cells of a placement."""
    parts = []
    if any(p.decenter):
        d = p.decenter if p.decenter[2] else p.decenter[:2]
        parts.append(f"decenter = {_list(d)}")
    if any(p.tilt):
        parts.append(f"tilt = {_list(p.tilt)}")
    if p.order != ORDERS[0]:
        parts.append(f'order = "{p.order}"')
    return ", ".join(parts)


def _geometry_cells(s: Surface) -> list[tuple[str, str] | None]:
    """Cells of the placement, mirror, coordinate-break and clear-aperture keys."""
    cells: list[tuple[str, str] | None] = [
        ("type", '"coordinate_break"') if s.coordinate_break else None,
        ("mirror", "true") if s.mirror else None,
    ]
    p = s.placement
    if p is not None:
        text = _placement_text(p)
        first, _, rest = text.partition(" = ")
        cells.append((first, rest))
    else:
        cells.append(None)
    a = s.after
    if isinstance(a, Placement):
        cells.append(("after", "{ " + _placement_text(a) + " }"))
    else:
        cells.append(("after", f'"{a}"') if a != "stay" else None)
    ap = s.aperture
    if ap is None:
        cells.append(None)
    else:
        size = repr(ap.half_x) if ap.shape == "circle" else _list((ap.half_x, ap.half_y))
        body = f"{ap.shape} = {size}"
        if ap.x0 or ap.y0:
            body += f", center = {_list((ap.x0, ap.y0))}"
        cells.append(("aperture", "{ " + body + " }"))
    return cells


def _qtype_text(q: QType) -> str:
    terms = ", ".join(repr(float(a)) for a in q.terms)
    return f'{{ form = "{q.form}", norm_radius = {q.norm_radius!r}, a = [{terms}] }}'


def _surface_cells(s: Surface, last: bool, solve: str | None) -> list[tuple[str, str] | None]:
    t = '"gaussian"' if (last and solve == "gaussian") else _fnum(s.thickness)
    own_medium = not (s.mirror or s.coordinate_break)
    cells: list[tuple[str, str] | None] = [
        _radius_cell(s.curvature),
        ("t", t),
        *(_material_cells(s.material) if own_medium else [None, None]),
        ("sd", _fnum(s.semi_diameter)) if math.isfinite(s.semi_diameter) else None,
        ("k", repr(float(s.conic))) if s.conic != 0.0 else None,
        ("asph", "[" + ", ".join(repr(float(a)) for a in s.aspheric) + "]") if s.aspheric else None,
        ("qtype", _qtype_text(s.qtype)) if s.qtype is not None else None,
        ("stop", "true") if s.stop else None,
        ("label", _toml_str(s.label)) if s.label else None,
        *_geometry_cells(s),
    ]
    return cells


def dumps(lens: Lens) -> str:
    """The prescription text of ``lens``: ``loads(dumps(lens)) == lens`` exactly (full float
    precision, materials, aspheric terms, image solve, provenance and notes)."""
    if lens.image_solve not in (None, "gaussian"):
        raise PrescriptionError(f"cannot write image_solve = {lens.image_solve!r}")
    if lens.units != "mm":
        raise PrescriptionError(f"cannot write units {lens.units!r} (only mm)")
    out = [_HEADER]
    out.append(f"name       = {_toml_str(lens.name)}\n")
    out.append(f"source     = {_toml_str(lens.source)}\n")
    notes: str | None = lens.notes
    m = _PROVENANCE_RE.match(lens.notes)
    if m:
        out.append(f'provenance = "{m.group(1)}"\n')
        notes = lens.notes[m.end() :] if m.group(2) == "\n" else None
    elif not notes:
        notes = None
    if notes is not None:
        out.append(f"notes      = {_toml_str(notes)}\n")
    out.append('units      = "mm"\n')
    if len(lens.wavelengths) == 1:
        out.append(f"wavelength = {_fnum(lens.wavelength)}   # nm\n")
    else:
        out.append("wavelengths = [" + ", ".join(_fnum(w) for w in lens.wavelengths) + "]   # nm\n")
        out.append(f"reference_wavelength = {_fnum(lens.wavelength)}   # nm\n")
    if any(w != 1.0 for w in lens.weights):
        out.append("weights = [" + ", ".join(_fnum(w) for w in lens.weights) + "]\n")
    if lens.temperature_c is not None:
        out.append(f"temperature_c = {_fnum(lens.temperature_c)}   # °C\n")
    if lens.pressure_atm is not None:
        out.append(f"pressure_atm = {_fnum(lens.pressure_atm)}   # atm\n")
    out.append("\n")

    obj = [f"distance = {_fnum(lens.object_distance)}"]
    obj += [f"{c[0]} = {c[1]}" for c in _material_cells(lens.object_material) if c]
    out.append(
        '# object distance: mm from the object plane to the first vertex (positive), or "inf"\n'
    )
    out.append(f"object   = {{ {', '.join(obj)} }}\n")
    ap_help = {
        "fnumber": "f-number",
        "epd": "entrance-pupil diameter, mm",
        "na": "object NA",
        "float": "float by stop size: the stop's semi-diameter, mm",
        "working_fnumber": "paraxial working f-number",
        "cone_angle": "object cone angle, degrees",
    }
    out.append(
        f"aperture = {{ {lens.aperture.kind} = {_fnum(lens.aperture.value)} }}"
        f"   # {ap_help[lens.aperture.kind]}\n"
    )
    fld = lens.field
    fld_help = {"angle": "max half-field angle, degrees", "height": "max object height, mm"}
    if fld.given is not None:
        out.append(
            f"field    = {{ {fld.given[0]} = {_fnum(fld.given[1])} }}"
            f"   # mm, = {fld.kind} {fld.value!r} in object space\n"
        )
    else:
        pts = ""
        if fld.points:
            pts = ", points = [" + ", ".join(_list(p) for p in fld.points) + "]"
        out.append(
            f"field    = {{ {fld.kind} = {_fnum(fld.value)}{pts} }}   # {fld_help[fld.kind]}\n"
        )
    if lens.image_placement is not None:
        out.append(
            f"image    = {{ {_placement_text(lens.image_placement)} }}"
            "   # decenter (mm) / tilt (deg) of the image surface\n"
        )
    out.append("\n")

    out.append(_COLUMNS)
    n = lens.n_surfaces
    rows = [_surface_cells(s, i == n - 1, lens.image_solve) for i, s in enumerate(lens.surfaces)]
    ncol = len(rows[0])
    widths = [
        max((len(f"{c[0]} = {c[1]}") for row in rows if (c := row[j]) is not None), default=0)
        for j in range(ncol)
    ]
    texts = []
    for row in rows:
        present = [j for j in range(ncol) if row[j] is not None]
        parts = []
        for j in range(ncol):
            if widths[j] == 0:
                continue
            cell = row[j]
            if cell is None:
                parts.append(" " * (widths[j] + 1))
            else:
                sep = "," if j != present[-1] else ""
                parts.append(f"{cell[0]} = {cell[1]}{sep}".ljust(widths[j] + 1))
        texts.append(" ".join(parts).rstrip())
    width = max(len(t) for t in texts)
    out.append("surfaces = [\n")
    for i, t in enumerate(texts, start=1):
        out.append(f"  {{ {t.ljust(width)} }},  # {i}\n")
    out.append("]\n")
    return "".join(out)


def write_lens(lens: Lens, path: str | Path, **options: Any) -> None:
    """Write ``lens`` to ``path`` in the prescription format (UTF-8), atomically; ``options``
    (``overwrite``, ``inputs``, ``flag``) as in :func:`raytrace.files.output.write_atomic`."""
    text = dumps(lens)
    check_reads_back(text, loads, path)
    write_atomic(path, text, **options)
