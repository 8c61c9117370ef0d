"""What every subcommand shares: the one vocabulary of flags (docs/design.md, "Vocabulary"),
their help texts, loading a lens, and printing results.

Handlers raise :class:`CliError` (or any project error) for what a person can get wrong;
:func:`orthoscope.cli.main` prints it as one line and exits with status 2.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path
from typing import Any

import numpy as np

from raytrace.errors import OrthoscopeError

OBJECT_HELP = (
    "Object plane, one of: --object-distance D (mm from the object plane to the FIRST VERTEX, a "
    "positive magnitude as in lens files; 'inf'; or an image scale 'Nx'), --object-s S "
    "(Pestrecov's signed s: mm from the first principal point H, NEGATIVE for a real object), "
    "--object-scale N (Gaussian magnification -1/N). Default: the lens file's object."
)
PLANE_HELP = (
    "Image plane, one of: --s-prime S' (mm from the second principal point H', Pestrecov's s'), "
    "--from-last-vertex D (mm from the last vertex), --defocus DZ (mm from the Gaussian image "
    "plane, + away from the lens), --gaussian (the Gaussian plane of the object). Default: the "
    'lens file\'s image plane (a file whose last thickness is "gaussian" means the Gaussian '
    "plane of whatever object is traced, at the lens's reference wavelength)."
)
FIELDS_HELP = (
    "Comma-separated fields: half-field angles in degrees (object-space chief-ray slope angle; "
    "with a finite object, Pestrecov's nominal angles, y = p0 tan(alpha)) or object heights in mm, "
    "as --field-kind says. Signed values are fine: --fields -10,0,10."
)


#: Choices of the science packages, spelled here so that building the parser imports none of
#: them (tests/test_cli.py checks they equal distortion.calibration.METHODS and
#: distortion.characteristic.REFERENCES).
METHODS = ("two-point", "minimax", "least-squares", "zero-at", "given")
REFERENCES = ("characteristic", "distortion-focal-length", "real-chief-transport")


class CliError(OrthoscopeError):
    """A usage error detected after argparse (bad combination of flags, bad value)."""


#: the namespace attributes of the flags given: the option strings of the noting actions
#: (:class:`Noted`) in the order given, the deprecated spellings given (each with its
#: :class:`DeprecatedAlias`, which knows the flag it spells and what they give), and whether
#: their deprecation lines were said
GIVEN_FLAGS = "_noted_flags"
DEPRECATED_GIVEN = "_deprecated_given"
DEPRECATIONS_SAID = "_deprecations_said"

#: the refusal of a deprecated spelling given with the flag it spells (every command, one place:
#: :func:`refuse_both_spellings`)
BOTH_SPELLINGS = (
    "{old} and {new} both give {what} ({old} is the deprecated spelling of {new}): give {new} alone"
)


def note_given(namespace, option_string: str) -> None:
    """Note in ``namespace`` that the flag ``option_string`` was given (:func:`given_flags`)."""
    noted = getattr(namespace, GIVEN_FLAGS, None)
    if noted is None:
        noted = []
        setattr(namespace, GIVEN_FLAGS, noted)
    noted.append(option_string)


def given_flags(args) -> list[str]:
    """The flags of noting actions (:class:`Noted`) given, in the order given, each once: a
    deprecated spelling (:class:`DeprecatedAlias`), the flags that have one
    (:class:`NotedStore`, :class:`NotedAppend`), the object flags (:func:`add_object_args`),
    and every flag of a parser that notes them all (``camera``)."""
    return list(dict.fromkeys(getattr(args, GIVEN_FLAGS, ())))


class Noted:
    """Mixin of an argparse action: when given, it notes the option string it was given by
    (:func:`given_flags`), then does what its action does."""

    def __call__(self, parser, namespace, values, option_string=None) -> None:
        note_given(namespace, option_string or self.option_strings[0])
        super().__call__(parser, namespace, values, option_string)


class NotedStore(Noted, argparse._StoreAction):
    """A flag stored as usual and noted as given: one that has a deprecated spelling, so that
    both spellings given are told apart from one (the two store to one place)."""


class NotedAppend(Noted, argparse._AppendAction):
    """A repeatable flag (``action="append"``) noted as given (as :class:`NotedStore`)."""


class DeprecatedAlias(Noted, argparse.Action):
    """An old flag spelling that still works for one release: stored like the flag ``new`` it
    spells, and noted (:func:`given_flags`); given with ``new`` it is refused before any work
    (:func:`refuse_both_spellings`, naming ``what`` the two give); its warning on stderr is said
    once, after the command's checks (:func:`warn_deprecated`), so that a refused run prints
    the refusal alone."""

    def __init__(self, option_strings, dest, new: str = "", what: str = "", **kw) -> None:
        self.new = new
        self.what = what
        super().__init__(option_strings, dest, **kw)

    def __call__(self, parser, namespace, values, option_string=None) -> None:
        flag = option_string or self.option_strings[0]
        note_given(namespace, flag)
        said = getattr(namespace, DEPRECATED_GIVEN, None)
        if said is None:
            said = {}
            setattr(namespace, DEPRECATED_GIVEN, said)
        said[flag] = self
        if self.nargs == 0:
            setattr(namespace, self.dest, self.const)
        elif isinstance(getattr(namespace, self.dest, None), list) or self.default == []:
            cur = list(getattr(namespace, self.dest, None) or [])
            cur.append(values)
            setattr(namespace, self.dest, cur)
        else:
            setattr(namespace, self.dest, values)


def add_alias(p, old: str, new: str, dest: str, *, what: str, **kw) -> None:
    """The hidden flag ``old``: a :class:`DeprecatedAlias` of ``new`` (storing to ``dest``),
    which gives ``what`` (the refusal of both given, :func:`refuse_both_spellings`). ``new``
    must be added to ``p`` first, as a noting action (:class:`Noted`: :class:`NotedStore`,
    :class:`NotedAppend`), so that both given are told apart from one; a ValueError otherwise
    (a mistake of the code, said when the parser is built)."""
    action = p._option_string_actions.get(new)
    if not isinstance(action, Noted) or action.dest != dest:
        raise ValueError(
            f"add_alias({old!r}): add {new!r} first, storing to {dest!r} with a noting action "
            "(NotedStore, NotedAppend)"
        )
    p.add_argument(
        old, dest=dest, action=DeprecatedAlias, new=new, what=what, help=argparse.SUPPRESS, **kw
    )


def refuse_both_spellings(args) -> None:
    """CliError (one line, :data:`BOTH_SPELLINGS`) when a deprecated spelling
    (:class:`DeprecatedAlias`) was given together with the flag it spells: the two store to one
    place and the last one would win silently (a repeatable flag would take both, which a
    reader of the command cannot tell from a mistake). Run by :func:`orthoscope.cli.main` once
    the arguments are parsed, before any work, for every command."""
    given = given_flags(args)
    for old, alias in getattr(args, DEPRECATED_GIVEN, {}).items():
        if alias.new in given:
            raise CliError(BOTH_SPELLINGS.format(old=old, new=alias.new, what=alias.what))


def as_typed(args, flag: str) -> str:
    """``flag`` as the command line gave it: its deprecated spelling (:class:`DeprecatedAlias`)
    when that was typed instead, so that a message names what the user wrote."""
    for old, alias in getattr(args, DEPRECATED_GIVEN, {}).items():
        if alias.new == flag:
            return old
    return flag


def warn_deprecated(args) -> None:
    """The deprecation line of each deprecated spelling given (:class:`DeprecatedAlias`), once
    per run: after the command's checks (a handler may call it once its checks have passed;
    :func:`orthoscope.cli.main` calls it when the handler returns)."""
    if getattr(args, DEPRECATIONS_SAID, False):
        return
    setattr(args, DEPRECATIONS_SAID, True)
    for old, alias in getattr(args, DEPRECATED_GIVEN, {}).items():
        warn(f"{old} is deprecated and will be removed; use {alias.new}")


def warn(message: str) -> None:
    """One warning line on stderr."""
    print(f"orthoscope: warning: {message}", file=sys.stderr)


def first_repeat(values):
    """The first item of ``values`` that an earlier one equals (None when all differ): a plane
    or a distance listed twice would give the same row twice."""
    return next((v for i, v in enumerate(values) if v in values[:i]), None)


def number(text: str, what: str) -> float:
    """A finite float from ``text``; CliError naming ``what`` otherwise."""
    try:
        v = float(text)
    except (TypeError, ValueError):
        raise CliError(f"{what}: expected a number, got {text!r}") from None
    if not math.isfinite(v):
        raise CliError(f"{what}: expected a finite number, got {text!r}")
    return v


def length(text: str, what: str, **kw) -> float:
    """A length in mm from ``text``: a number (mm) or a number with a unit (``1.5m``, ``25cm``)
    (:func:`raytrace.units.length_mm`)."""
    from raytrace.units import UnitError, length_mm

    try:
        return length_mm(str(text).strip(), what, **kw)
    except UnitError as e:
        raise CliError(str(e)) from None


def wavelength_arg(text: str) -> float:
    """argparse type of --wavelength: nm, or with a unit (``587.6nm``, ``0.5876um``); a bare
    value below 100 looks like micrometres and is refused with the fix."""
    from raytrace.units import UnitError, wavelength_nm

    try:
        return wavelength_nm(text, "--wavelength")
    except UnitError as e:
        raise argparse.ArgumentTypeError(str(e)) from None


def parse_list(text: str, what: str, *, lengths: bool = False) -> np.ndarray:
    """``'0,10,20'`` → array; a clear error on garbage. ``lengths``: items may carry a length
    unit (``425mm``, ``0.5m``), the result is in mm."""
    parts = [p.strip() for p in str(text).split(",") if p.strip()]
    if not parts:
        raise CliError(f"{what}: empty list")
    conv = (lambda p: length(p, what)) if lengths else (lambda p: number(p, what))
    return np.array([conv(p) for p in parts])


def at_fields(text: str | None) -> tuple[float, ...] | None:
    """The fields of ``--at`` (``A`` or ``A,B``), None without it."""
    return None if text is None else tuple(parse_list(text, "--at"))


def signed_list(text: str) -> str:
    """argparse type for lists that may start with a minus sign (kept as text)."""
    return text


def bundled_or_path(word: str, folder: str, suffix: str) -> str:
    """A file argument as given, or the file of that name bundled with the lens library
    (``lenses/FOLDER/NAME.SUFFIX``, installed with the package: the name works from any folder;
    :func:`raytrace.files.library.bundled_or_given`), as the text the readers take."""
    if not word.strip():
        return word
    from raytrace.files.library import bundled_or_given

    found = bundled_or_given(word, folder, suffix)
    return word if found == Path(word) else str(found)


def load(name: str, strict: bool = False):
    """Load a lens by bundled name or path (every reader the project has); ``strict``: refuse a
    glass that the file names but that is read only as a substitute (``--strict``)."""
    from raytrace.files.library import load_lens

    return load_lens(name, strict=strict)


def load_recorded(args, name: str, *others):
    """The lens ``name`` (:func:`load`, with ``--strict`` when the command has it), recorded
    with the other input files ``others`` (None or empty: left out) as the command's inputs
    (``args._inputs``) so that no output is ever written onto one of them."""
    lens = load(name, strict=getattr(args, "strict", False))
    args._inputs = [p for p in (lens.path, *others) if p]
    return lens


def load_input(args):
    """The lens of ``args.lens`` (:func:`load`), recorded as the command's input
    (``args._inputs``, :func:`load_recorded`) so that no output is ever written onto it."""
    return load_recorded(args, args.lens)


def save_plot(make, path, args) -> None:
    """Draw the figure ``make()`` off screen and write it to ``path`` (.png, .svg or .pdf),
    never onto one of the command's inputs (``args._inputs``), over an existing file only
    with ``--force`` (``args.force``)."""
    from ..plots.common import offscreen_figures
    from ..plots.save import save_figure

    with offscreen_figures():
        fig = make()
    save_figure(fig, path, overwrite=args.force, inputs=args._inputs, flag="--force")


def save_plots(plots, data, args) -> None:
    """:func:`save_plot` of ``plot(data)`` to ``path`` for each ``(path, plot)`` of ``plots``
    whose path is given, in that order."""
    for path, plot in plots:
        if path:
            save_plot(lambda plot=plot: plot(data), path, args)


def check_traced_any(traced_any: bool, see: str = " (see the table)") -> None:
    """Refuse a plot when no field could be traced (``traced_any`` false): CliError, ``see``
    saying where the run's output lists them."""
    if not traced_any:
        raise CliError(f"no field could be traced{see}: there is nothing to plot")


def strict_check(args, status, what: str = "field(s)", see: str = " (see the table)") -> None:
    """With ``--strict`` (``args.strict``), fail when any trace ``status`` is not OK (0).

    Raises
    ------
    CliError
        Naming how many ``what`` could not be traced.
    """
    n_bad = int(np.count_nonzero(np.asarray(status) != 0))
    if n_bad and args.strict:
        raise CliError(f"{n_bad} {what} could not be traced{see}; --strict fails")


def load_scaled(args):
    """The lens of ``--lens`` (:func:`load_input`: recorded as the command's input), scaled to
    ``--scale-to-efl`` mm when given."""
    from raytrace.paraxial import paraxial

    lens = load_input(args)
    if args.scale_to_efl is not None:
        if not (args.scale_to_efl > 0 and math.isfinite(args.scale_to_efl)):
            raise CliError(
                f"--scale-to-efl must be a positive focal length in mm, got {args.scale_to_efl}"
            )
        efl = paraxial(lens, math.inf).efl
        if not efl > 0:
            raise CliError(f"{lens.name}: EFL {efl:g} mm is not positive; cannot scale it")
        lens = lens.scaled(args.scale_to_efl / efl)
    return lens


# ----------------------------------------------------------------------------- objects
def add_lens_arg(p: argparse.ArgumentParser) -> None:
    """The positional LENS argument: a lens file or a bundled lens name."""
    p.add_argument("lens", metavar="LENS", help="Lens file path or bundled lens name.")


def add_lens_object_args(
    p: argparse.ArgumentParser,
    *,
    fields: bool = True,
    planes: bool = True,
    repeatable: bool = False,
) -> None:
    """LENS (:func:`add_lens_arg`) and the object flags (:func:`add_object_args`), then the
    field flags (:func:`add_field_args`) and the image-plane flags (:func:`add_plane_args`,
    ``repeatable``) unless ``fields`` / ``planes`` is false: what a command that traces a lens
    takes first, in this order."""
    add_lens_arg(p)
    add_object_args(p)
    if fields:
        add_field_args(p)
    if planes:
        add_plane_args(p, repeatable=repeatable)


def add_object_args(p: argparse.ArgumentParser) -> None:
    g = p.add_argument_group("object plane (give at most one)", OBJECT_HELP)
    # noted (given_flags): two of them given are refused naming the flags as typed
    g.add_argument(
        "--object-distance",
        action=NotedStore,
        metavar="D",
        help="mm from the object plane to the first vertex.",
    )
    g.add_argument(
        "--object-s", action=NotedStore, metavar="S", help="Pestrecov's s: mm from H, negative."
    )
    g.add_argument(
        "--object-scale",
        action=NotedStore,
        metavar="N",
        help="image scale N (Nx): magnification -1/N.",
    )
    add_alias(g, "--s", "--object-s", "object_s", what="the object's s", metavar="S")


#: the object flags (:func:`add_object_args`; ``--s``: the deprecated ``--object-s``)
OBJECT_FLAGS = ("--object-distance", "--object-s", "--object-scale", "--s")


def object_flags_given(args) -> list[str]:
    """The object flags given (:data:`OBJECT_FLAGS`), as typed and in the order given; two of
    them are refused in one line naming both."""
    obj = [f for f in given_flags(args) if f in OBJECT_FLAGS]
    if len(obj) > 1:
        raise CliError(f"give the object one way, not {' and '.join(obj)}")
    return obj


def resolve_object(lens, args) -> float:
    """The object distance (mm from the first vertex, or inf) from the object flags
    (:func:`add_object_args`): two of them given are refused, naming the flags as typed and in
    the order given (the deprecated ``--s`` with ``--object-s`` was refused when the arguments
    were parsed, :func:`refuse_both_spellings`), and a value of ``--s`` is named as typed."""
    from raytrace.paraxial import resolve_object_distance
    from raytrace.units import UnitError, image_scale

    object_flags_given(args)
    s_flag = as_typed(args, "--object-s")
    s = None if args.object_s is None else length(args.object_s, s_flag)
    scale = None
    if args.object_scale is not None:
        try:
            scale = image_scale(args.object_scale, "--object-scale")
        except UnitError as e:
            raise CliError(str(e)) from None
    od = args.object_distance
    if od is not None:
        t = str(od).strip().lower()
        if t not in ("inf", "infinity") and not t.endswith(("x", "×")):
            od = length(t, "--object-distance", allow_inf=True)
    return resolve_object_distance(lens, object_distance=od, object_s=s, object_scale=scale)


# ----------------------------------------------------------------------------- image planes
def add_plane_args(p: argparse.ArgumentParser, *, repeatable: bool = False) -> None:
    g = p.add_argument_group(
        "image plane" + (" (each flag repeatable; one kind per call)" if repeatable else ""),
        PLANE_HELP,
    )
    act = "append" if repeatable else "store"
    noted = NotedAppend if repeatable else NotedStore  # the flags with a deprecated spelling
    g.add_argument("--s-prime", type=str, action=noted, metavar="S'", help="mm from H'.")
    g.add_argument(
        "--from-last-vertex", type=str, action=noted, metavar="D", help="mm from the last vertex."
    )
    g.add_argument(
        "--defocus", type=str, action=act, metavar="DZ", help="mm from the Gaussian plane."
    )
    g.add_argument(
        "--gaussian",
        action="store_true",
        help="the Gaussian image plane of the object (with the flags above: one plane more).",
    )
    for old, new, dest, what in (
        ("--image-distance", "--s-prime", "s_prime", "the image plane's s'"),
        (
            "--image-from-vertex",
            "--from-last-vertex",
            "from_last_vertex",
            "the image plane's distance from the last vertex",
        ),
    ):
        add_alias(g, old, new, dest, what=what, metavar="X", default=[] if repeatable else None)


def resolve_planes(lens, args) -> list:
    """The :class:`~raytrace.paraxial.ImagePlane` list the plane flags ask for (default: the lens
    file's plane, or, when the file solves its image to the Gaussian plane, the Gaussian plane of
    the traced object at the lens's reference wavelength: ``--wavelength`` does not move it)."""
    from raytrace.paraxial import ImagePlane

    given = {}  # kind: (the flag as typed, its values)
    for key, flag in (
        ("s_prime", "--s-prime"),
        ("from_last_vertex", "--from-last-vertex"),
        ("defocus", "--defocus"),
    ):
        v = getattr(args, key, None)
        if v in (None, []):
            continue
        flag = as_typed(args, flag)
        vals = v if isinstance(v, list) else [v]
        nums = []
        for item in vals:
            nums.extend(parse_list(item, flag, lengths=True).tolist())
        given[key] = (flag, nums)
    if len(given) > 1:
        flags = ", ".join(flag for flag, _ in given.values())
        raise CliError(f"give the image planes one way, not {flags}")
    if given:  # --gaussian with them adds the Gaussian plane to the list
        ((kind, (flag, vals)),) = given.items()
        dup = first_repeat(vals)
        if dup is not None:
            raise CliError(f"{flag}: the plane {dup:g} is listed twice")
        gauss = [ImagePlane("gaussian")] if args.gaussian else []
        return [ImagePlane(kind, float(v)) for v in vals] + gauss
    if args.gaussian:
        return [ImagePlane("gaussian")]
    if lens.image_solve == "gaussian":  # the file's solve: for the traced object, at the
        return [ImagePlane("gaussian_reference")]  # reference wavelength (not --wavelength's)
    return [ImagePlane("file")]


def resolve_one_plane(lens, args, message: str) -> list:
    """The image plane of the plane flags (:func:`resolve_planes`), a list of one, for a command
    that takes one plane; CliError ``message`` when they give several."""
    planes = resolve_planes(lens, args)
    if len(planes) != 1:
        raise CliError(message)
    return planes


def plane_origin(args) -> str:
    """How the image plane was given, for the report."""
    for key in ("s_prime", "from_last_vertex", "defocus"):
        if getattr(args, key, None) not in (None, []):
            return "--" + key.replace("_", "-")
    return "--gaussian" if getattr(args, "gaussian", False) else "lens file"


# ----------------------------------------------------------------------------- fields
def add_field_args(p: argparse.ArgumentParser) -> None:
    g = p.add_argument_group("fields")
    g.add_argument("--fields", metavar="F1,F2,...", help=FIELDS_HELP)
    g.add_argument(
        "--max-field", type=float, metavar="F", help="Largest field (default: the lens's)."
    )
    g.add_argument(
        "--steps",
        type=int,
        default=None,
        metavar="N",
        help="Number of equal field steps from 0 to --max-field (default 10).",
    )
    g.add_argument(
        "--field-kind",
        choices=["angle", "height"],
        help="What the fields are: 'angle' (deg) or 'height' (object mm). Default: the lens "
        "file's kind.",
    )


#: Work limits of one command (fields, radii, rays; raytrace.limits, shared with the API).
#: Beyond them a command refuses before allocating anything and names the flag that lifts the
#: limit (--allow-large).
from raytrace.limits import MAX_FIELDS, MAX_SAMPLES  # noqa: E402, F401


def check_size(value: int, limit: int, what: str, args, per_item_bytes: int = 200) -> int:
    """``value`` if it is at most ``limit`` (or the run has --allow-large); else CliError with
    the memory the request would take and the flag that lifts the limit."""
    if value < 1:
        raise CliError(f"{what} must be at least 1, got {value}")
    if value > limit and not getattr(args, "allow_large", False):
        gb = value * per_item_bytes / 1e9
        raise CliError(
            f"{what} {value}: more than {limit} (about {gb:.3g} GB and a long run); give "
            "--allow-large (before the command) to run it anyway"
        )
    return value


def resolve_fields(lens, args) -> tuple[np.ndarray, str]:
    """(fields, kind) from --fields or --max-field/--steps (default: the lens's field, 10 steps)."""
    kind = args.field_kind or lens.field.kind
    if args.fields is not None:
        if args.max_field is not None or args.steps is not None:
            raise CliError("give either --fields or --max-field/--steps, not both")
        f = parse_list(args.fields, "--fields")
        check_size(f.size, MAX_FIELDS, "--fields (count)", args, per_item_bytes=150)
        return f, kind
    fmax = args.max_field
    if fmax is None:
        if kind != lens.field.kind:
            raise CliError(f"--field-kind {kind} needs --fields or --max-field")
        fmax = lens.field.value
    steps = 10 if args.steps is None else args.steps
    if steps < 1:
        raise CliError("--steps must be at least 1")
    check_size(steps, MAX_FIELDS, "--steps", args, per_item_bytes=150)
    if not math.isfinite(fmax):
        raise CliError("--max-field must be finite")
    if fmax == 0.0:  # the axis alone: one field, not steps + 1 copies of it
        return np.zeros(1), kind
    return np.linspace(0.0, fmax, steps + 1), kind


def field_keyword(fields: np.ndarray, kind: str) -> dict[str, Any]:
    """The API keyword for fields of ``kind``: ``fields_deg`` or ``object_heights_mm``."""
    return {"fields_deg": fields} if kind == "angle" else {"object_heights_mm": fields}


def check_finite_object(kind: str, object_distance: float) -> None:
    """Refuse object-height fields (``kind == "height"``) with the object at infinity."""
    if kind == "height" and object_distance == float("inf"):
        raise CliError("object-height fields need a finite object (--object-distance)")


def resolve_object_fields(lens, args) -> tuple[float, np.ndarray, str]:
    """(object distance, fields, field kind) of the object and field flags
    (:func:`resolve_object`, :func:`resolve_fields`); object-height fields with the object at
    infinity are refused (:func:`check_finite_object`)."""
    od = resolve_object(lens, args)
    fields, kind = resolve_fields(lens, args)
    check_finite_object(kind, od)
    return od, fields, kind


def refuse_flags(message: str, flags) -> None:
    """CliError ``message`` (``{}`` = the flag names) when a flag of the ``(flag, value)`` pairs
    ``flags`` is given (its value true): flags that do not apply to this run."""
    given = [flag for flag, value in flags if value]
    if given:
        raise CliError(message.format(", ".join(given)))


# ----------------------------------------------------------------------------- output
JSON_HELP = "Print JSON (keys carry units; README)."
FORCE_HELP = "Replace existing output files (never an input)."
STRICT_HELP = (
    "Exit with status 2 when a field cannot be traced, when the lens file names a glass read "
    "only as a substitute (an N- successor, a parent glass, a model of nd/vd), or when a glass "
    "is evaluated outside its catalog data range (an nd/vd model glass outside 365-1014 nm)."
)
TABLE_LAYOUT_HELP = (
    "Table orientation: 'rows' (one row per field; default) or 'paper' (fields across, as "
    "Pestrecov's Tables I, II and V)."
)


def add_output_args(
    p: argparse.ArgumentParser,
    *,
    csv: bool = True,
    json_help: str = JSON_HELP,
    csv_help: str = "Print CSV.",
) -> None:
    """``--json`` and (with ``csv``) ``--csv``, one or the other: what :func:`print_result`
    prints."""
    g = p.add_mutually_exclusive_group()
    g.add_argument("--json", action="store_true", help=json_help)
    if csv:
        g.add_argument("--csv", action="store_true", help=csv_help)


def add_force_arg(p, *, help: str = FORCE_HELP) -> None:
    """``--force``: output files may replace existing files (never an input)."""
    p.add_argument("--force", action="store_true", help=help)


def add_strict_arg(p, *, help: str = STRICT_HELP) -> None:
    """``--strict``: what is only a warning or a table entry by default fails the run."""
    p.add_argument("--strict", action="store_true", help=help)


def add_table_layout_arg(p) -> None:
    """``--table-layout rows|paper`` of the distortion tables."""
    p.add_argument(
        "--table-layout", choices=["rows", "paper"], default="rows", help=TABLE_LAYOUT_HELP
    )


def check_output_path(path, args) -> None:
    """Refuse an output file before any work (:func:`raytrace.files.output.check_output`: a
    name that ends in a path separator, one of the command's inputs ``args._inputs``, a missing
    folder or one that cannot take a new file, an existing file without --force ``args.force``),
    and a second output of the run naming the same file. None: nothing to check."""
    if path is None:
        return
    import os

    from raytrace.files.output import check_output

    check_output(path, inputs=getattr(args, "_inputs", ()), overwrite=args.force, flag="--force")
    # two outputs of one run naming one file: the second would replace the first
    seen = args.__dict__.setdefault("_outputs", set())
    key = os.path.realpath(path)
    if key in seen:
        raise CliError(f"{path}: two outputs of this command name the same file; give each its own")
    seen.add(key)


def check_plot_path(path: str | None, flag: str, args) -> None:
    """Refuse a plot file name before any work: suffix, folder, no overwrite without --force."""
    if path is None:
        return
    check_output_path(path, args)
    check_plot_suffix(path, flag)


def check_plot_paths(args, *dests: str) -> None:
    """:func:`check_plot_path` of each plot flag named by its namespace attribute in ``dests``
    (``plot_rotation`` is ``--plot-rotation``), in that order."""
    for dest in dests:
        check_plot_path(getattr(args, dest), "--" + dest.replace("_", "-"), args)


def check_plot_suffix(path: str, flag: str) -> None:
    """Refuse a plot file name (of ``flag``) that is not .png, .svg or .pdf."""
    from pathlib import Path

    if Path(path).suffix.lower() not in (".png", ".svg", ".pdf"):
        raise CliError(f"{flag} {path}: the file must end in .png, .svg or .pdf")


def print_result(args, *, json, text, csv=None) -> None:
    """A command's result on stdout in the form its output flags ask for: ``json()`` as JSON
    with ``--json``, ``csv()`` with ``--csv`` (where the command has it), ``text()``
    otherwise. Only the chosen one is called."""
    if args.json:
        print_json(json())
    elif csv is not None and args.csv:
        print(csv())
    else:
        print(text())


def add_wavelength_arg(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--wavelength",
        type=wavelength_arg,
        metavar="NM",
        help="Wavelength in nm, or with a unit: 587.6nm, 0.5876um (default: the lens file's).",
    )


def print_json(obj) -> None:
    from ..report.jsonout import dumps

    print(dumps(obj))


def check_dask(text: str | None) -> None:
    """Check a --dask value before any work (raytrace.executors.check_executor) and, for a run on
    Dask, keep Dask's own log records (connection errors, with tracebacks) off the terminal: the
    command's one-line messages say what happened."""
    if text is None:
        return
    import logging

    from raytrace.executors import check_executor, quiet_dask_logs

    check_executor(text)
    try:
        import distributed  # noqa: F401  (its import sets its loggers' levels)
    except ImportError:
        return  # the run says how to install it
    quiet_dask_logs(logging.CRITICAL)
