"""The command's one parser, aware of the form it parses (an abbreviated flag resolves among
that form's flags), its help pages (the general one, and each action's: :func:`action_parser`)
and :func:`register`."""

from __future__ import annotations

import argparse

from .. import EXIT_USAGE, Parser
from ..common import Noted
from .actions import cmd_camera
from .forms import ACTIONS, USAGE, add_arguments, foreign_abbreviation, form_flags, form_of_word

_NOTED: dict[type, type] = {}


def _note_given(q: argparse.ArgumentParser) -> None:
    """Make every option of ``q`` but the help a :class:`~orthoscope.cli.common.Noted` one (the
    same action, of a subclass that notes it was given, :func:`given_flags`: given is told
    apart from absent even when the value given is the default, ``--model opencv``). Those that
    note themselves already (a deprecated spelling, the flag it spells) are left as they are."""
    for a in q._actions:
        if not a.option_strings or isinstance(a, (_CameraHelp, argparse._HelpAction, Noted)):
            continue
        cls = type(a)
        if cls not in _NOTED:
            _NOTED[cls] = type(f"Noted{cls.__name__}", (Noted, cls), {})
        a.__class__ = _NOTED[cls]


class _CameraParser(Parser):
    """The command's one parser, aware of the form it parses: an abbreviated long flag
    (``--calib``) resolves among the flags of that form only (argparse would match every
    form's), and one that starts only flags of other forms is refused, naming what was typed
    and where those flags belong. The form is the first word, found before parsing
    (:meth:`_form_of`); ``-h``/``--help`` (:class:`_CameraHelp`) uses it too."""

    #: the form of the argv being parsed (None: not known, every form's flags)
    _form: str | None = None

    def parse_known_args(self, args=None, namespace=None):
        import sys

        tokens = list(sys.argv[1:] if args is None else args)
        self._form = self._form_of(tokens)
        try:
            return super().parse_known_args(tokens, namespace)
        finally:
            self._form = None

    def _form_of(self, tokens) -> str | None:
        """The form of ``tokens`` (the arguments after ``camera``): its first word, skipping
        the options and their values (an abbreviation counted by what it can stand for);
        None where that is not plain (an unknown option before the first word, or none)."""
        i = 0
        while i < len(tokens):
            tok = tokens[i]
            if tok == "--":
                return form_of_word(tokens[i + 1]) if i + 1 < len(tokens) else None
            if not tok.startswith("-") or tok == "-" or self._negative_number_matcher.match(tok):
                return form_of_word(tok)
            if tok.startswith("--"):
                if "=" in tok:  # --flag=value
                    i += 1
                    continue
                acts = [a for o, a in self._option_string_actions.items() if o.startswith(tok)]
                if tok in self._option_string_actions:
                    acts = [self._option_string_actions[tok]]
            else:  # -o FILE, -oFILE, -h
                a = self._option_string_actions.get(tok[:2])
                if a is None:
                    return None
                acts = [a] if len(tok) == 2 or a.nargs == 0 else []
                if not acts:  # the value attached
                    i += 1
                    continue
            values = {0 if a.nargs == 0 else 1 for a in acts}
            if len(values) != 1:
                return None
            i += 1 + values.pop()
        return None

    def _get_option_tuples(self, option_string):
        found = super()._get_option_tuples(option_string)
        form = self._form
        if form is None or not found:
            return found
        own = form_flags(form) | {"-h", "--help"}
        mine = [t for t in found if t[1] in own]
        if mine:
            return mine
        typed = option_string.split("=", 1)[0]
        message = foreign_abbreviation(typed, [t[1] for t in found], form)
        self.exit(EXIT_USAGE, f"{self.prog}: error: {message}\n")


#: the examples of each form (the general page shows them all; tests/test_docs.py runs them)
EXAMPLES = {
    "lens": [
        "orthoscope camera cooke-triplet-f4 --sensor 24x16 --pixels 3000x2000 --model colmap "
        "-o cameras.txt",
        "orthoscope camera topogon-like-pestrecov --sensor 200x200 --pixels 2000x2000 --model "
        "fisheye --grid 13x13",
        "orthoscope camera cooke-triplet-f4 --sensor 24x16 --pixels 1200x800 --focus 2m "
        "--object-distances 1m,2m,5m,inf --grid 13x9",
    ],
    "compare": [
        "orthoscope camera compare cooke-triplet-f4 cooke-triplet-f4-synthetic-2m --sensor 24x16 "
        "--focus 2m --object-distance 2m --plot compare.png",
    ],
    "convert": [
        "orthoscope camera convert cooke-triplet-f4-synthetic-2m --model metashape -o cooke.xml",
    ],
    "variation": [
        "orthoscope camera variation cooke-triplet-f4-synthetic-1m cooke-triplet-f4-synthetic-5m "
        "--calibrated-at 1m,5m --focal-length 50 --focus 2m --object-distances 1m,2m,5m "
        "--sensor 24x16",
    ],
}


DESCRIPTION = {
    "compare": (
        "A measured calibration against the prescription's prediction at the same focus and "
        "object distance: real chief rays of the lens traced onto the calibration's sensor, the "
        "calibration's own model fitted to them (the prediction), and the two compared - "
        "radial distortion profiles and the difference over the sensor in pixels. The sensor is "
        "the calibration's pixel count with --sensor or --pitch; the focus setting puts it in "
        "the Gaussian image plane of the focused object (default: focused on the object)."
    ),
    "convert": (
        "One camera model into another over the calibration's sensor: exact algebra where the "
        "target holds the model, otherwise a least-squares refit with its residual in pixels. "
        "--model names a family (the smallest model of it that holds the calibration exactly) "
        "or one model."
    ),
    "variation": (
        "Camera models per object distance from two measured calibrations of one lens at two "
        "focus distances: the radial distortion profile at each object distance for a lens "
        "focused at --focus, by Brown's Eqs. 1-4 or Fraser & Shortis' Eq. 6 (with g_ss')."
    ),
}


EXPLAIN = (
    "Real chief rays (through the centre of the real stop) traced onto a sensor give the "
    "correspondences ideal direction <-> image point that a camera model is fitted to by least "
    "squares, with its residual in pixels. The ideal direction is the object-space chief ray's "
    "(object at infinity) or the direction from the projection centre - the paraxial entrance "
    "pupil at the reference wavelength - to the object point; the image point is the chief ray's "
    "intercept with the sensor plane, in the sensor's pixels (OpenCV: pixel centres at integers). "
    "The focus setting puts the sensor in the Gaussian image plane of the focused object (unit "
    "focusing, at the reference wavelength); default: focused on the object. 'compare' fits the "
    "calibration's own model to the traced lens and compares distortion profiles and the "
    "difference over the sensor; 'convert' turns one model into another (exact algebra or a "
    "refit with its residual); 'variation' predicts models per object distance from two "
    "calibrations (Brown Eqs. 1-4; Fraser & Shortis Eq. 6)."
)


def _epilog(forms) -> str:
    lines = [f"  {e}" for form in forms for e in EXAMPLES[form]]
    return "Examples:\n" + "\n".join(lines)


class _CameraHelp(argparse.Action):
    """``-h``/``--help``: the help page of the form the command's first word names (``orthoscope
    camera compare --help`` and ``orthoscope camera --help compare`` print compare's), otherwise
    the command's general page."""

    def __init__(
        self, option_strings, dest=argparse.SUPPRESS, default=argparse.SUPPRESS, help=None
    ):
        super().__init__(option_strings, dest=dest, default=default, nargs=0, help=help)

    def __call__(self, parser, namespace, values, option_string=None):
        words = getattr(namespace, "words", None) or []
        form = words[0] if words else getattr(parser, "_form", None)  # --help before the words
        if form in ACTIONS:
            parser = action_parser(form)
        parser.print_help()
        parser.exit()


def action_parser(action: str) -> argparse.ArgumentParser:
    """The help page of ``orthoscope camera ACTION`` (compare, convert, variation): its usage,
    what it does, the flags it reads and its examples. Only for the help: the command's one
    parser (:func:`register`) parses every form."""
    q = Parser(
        prog=f"orthoscope camera {action}",
        usage=USAGE[action],
        description=DESCRIPTION[action],
        epilog=_epilog([action]) + "\n\nRun 'orthoscope camera --help' for every form.",
        add_help=False,
    )
    q.add_argument("-h", "--help", action="help", help="Show this help and exit.")
    add_arguments(q, action)
    return q


def register(sub: argparse._SubParsersAction) -> None:
    q = sub.add_parser(
        "camera",
        help="Camera models (OpenCV, fisheye, COLMAP, Metashape, Australis) from a lens; "
        "compare, convert, vary with distance.",
        usage="\n       ".join(USAGE.values()),
        description=EXPLAIN,
        epilog=_epilog(EXAMPLES)
        + "\n\nRun 'orthoscope camera compare --help' (convert, variation) for the flags of each.",
        add_help=False,
    )
    q.__class__ = _CameraParser  # the parser of the subcommand, aware of the form it parses
    q.add_argument(
        "-h",
        "--help",
        action=_CameraHelp,
        help="Show this help and exit (with compare, convert or variation: that form's help).",
    )
    add_arguments(q, None)
    _note_given(q)
    q.set_defaults(func=cmd_camera)
