"""The shape of the code base (docs/design.md, "Layout"): imports run orthoscope → distortion →
raytrace and never back; the science packages neither print nor parse arguments; no module
imports another module's private names; every package is installed; the public API answers
the README's quick start."""

from __future__ import annotations

import ast
import re
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
LAYERS = {"raytrace": 0, "distortion": 1, "orthoscope": 2}


def _modules(pkg: str):
    for p in sorted((ROOT / pkg).rglob("*.py")):
        yield p, ast.parse(p.read_text(encoding="utf-8"), filename=str(p))


def _imported(tree: ast.AST, path: Path, pkg: str):
    """(module name, imported names, line) of every import, relative ones resolved."""
    rel = path.relative_to(ROOT).with_suffix("")
    parts = list(rel.parts)
    if parts[-1] == "__init__":
        parts = parts[:-1]
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for a in node.names:
                yield a.name, [], node.lineno
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = parts[: len(parts) - node.level + (1 if path.name == "__init__.py" else 0)]
                mod = ".".join(base + ([node.module] if node.module else []))
            else:
                mod = node.module or ""
            yield mod, [a.name for a in node.names], node.lineno


@pytest.mark.parametrize("pkg", sorted(LAYERS))
def test_imports_run_one_way(pkg):
    bad = []
    for path, tree in _modules(pkg):
        for mod, _, line in _imported(tree, path, pkg):
            top = mod.split(".")[0]
            if top in LAYERS and LAYERS[top] > LAYERS[pkg]:
                bad.append(f"{path.relative_to(ROOT)}:{line} imports {mod}")
    assert not bad, "\n".join(bad)


@pytest.mark.parametrize("pkg", ["raytrace", "distortion"])
def test_science_packages_do_not_print_or_parse_arguments(pkg):
    bad = []
    for path, tree in _modules(pkg):
        for node in ast.walk(tree):
            if isinstance(node, ast.Call) and getattr(node.func, "id", None) == "print":
                bad.append(f"{path.relative_to(ROOT)}:{node.lineno} print()")
        for mod, _, line in _imported(tree, path, pkg):
            if mod == "argparse":
                bad.append(f"{path.relative_to(ROOT)}:{line} imports argparse")
    assert not bad, "\n".join(bad)


def test_no_private_names_imported_across_modules():
    bad = []
    for pkg in LAYERS:
        for path, tree in _modules(pkg):
            for mod, names, line in _imported(tree, path, pkg):
                if mod.split(".")[0] not in LAYERS:
                    continue
                for n in names:
                    if n.startswith("_") and not n.startswith("__"):
                        bad.append(f"{path.relative_to(ROOT)}:{line} imports {mod}.{n}")
    assert not bad, "\n".join(bad)


def test_kernels_import_nothing_of_the_python_layer():
    bad = []
    for path, tree in _modules("raytrace/kernels"):
        for mod, _, line in _imported(tree, path, "raytrace"):
            if mod.startswith("raytrace.") and not mod.startswith("raytrace.kernels"):
                bad.append(f"{path.relative_to(ROOT)}:{line} imports {mod}")
    assert not bad, "\n".join(bad)


def test_every_package_is_installed():
    cfg = tomllib.loads((ROOT / "pyproject.toml").read_text())
    listed = set(cfg["tool"]["setuptools"]["packages"])
    found = {
        ".".join(p.parent.relative_to(ROOT).parts)
        for pkg in LAYERS
        for p in (ROOT / pkg).rglob("__init__.py")
    }
    assert found - listed == set(), f"packages missing from pyproject.toml: {found - listed}"


def test_readme_test_line_installs_every_extra():
    """CI runs the README's second set-up line (.ci/run); every optional extra has tests, so the
    line installs them all, and the referees whose Qt GUI no extra may carry."""
    cfg = tomllib.loads((ROOT / "pyproject.toml").read_text())
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    line = text.split("```sh\n", 1)[1].splitlines()[1]
    named = set(re.search(r"pip install -e '\.\[([^\]]*)\]'", line).group(1).split(","))
    assert named == set(cfg["project"]["optional-dependencies"])
    assert "pip install --no-deps rayoptics==0.9.8 opticalglass==1.1.1" in line
    assert "pytest" in line


def test_quick_start_api_runs_and_documents_units():
    import numpy as np

    import orthoscope as osc

    assert re.fullmatch(r"\d+\.\d+(\.\d+)?.*", osc.__version__)
    assert set(osc.__all__) <= set(dir(osc))
    lens = osc.load_lens("topogon-us2031792-fig1")
    p = osc.paraxial(lens)
    # US 2,031,792 (Topogon, Fig. 1) EFL 66.04 mm; see lenses/README.md
    assert p.efl == pytest.approx(66.04, abs=0.005)
    rays = osc.chief_rays(lens, fields_deg=[0, 10, 20])
    assert rays.ok.all() and rays.y_last.shape == (3,)
    out = osc.trace_rays(lens, np.array([[0.0, 1.0, -10.0]]), np.array([[0.0, 0.0, 1.0]]))
    assert out.ok.all()
    d = osc.characteristic_distortion(lens, fields_deg=[0, 10, 20, 30], s_prime=p.s_prime_gauss)
    cal = osc.calibrate(d, method="minimax")
    assert cal.Dc_max_abs <= np.max(np.abs(d.D0))
    doc = osc.characteristic_distortion.__doc__
    assert "Parameters" in doc and "Returns" in doc and "mm" in doc
    for r in (lens, p, rays, d, cal):
        assert len(repr(r)) < 400 and "np.float64" not in repr(r), type(r)


def test_every_public_function_documents_its_parameters():
    # numpydoc with units for the whole API, not only the quick start's functions (design.md,
    # "Style"; a review from a notebook found 63 public functions without a Parameters section)
    import inspect

    import orthoscope as osc

    missing = []
    for name in osc.__all__:
        obj = getattr(osc, name)
        if not inspect.isfunction(obj):
            continue
        doc = inspect.getdoc(obj) or ""
        sig = inspect.signature(obj)
        returns = sig.return_annotation not in (None, "None")
        # a function without parameters still says what it returns (list_lenses did not)
        if (list(sig.parameters) and "Parameters" not in doc) or (returns and "Returns" not in doc):
            missing.append(name)
    assert missing == []


def test_dir_of_the_package_is_its_api():
    """dir(orthoscope): the public names, dunders and loaded subpackages; not the helpers of
    orthoscope/__init__.py (a review saw Any, TYPE_CHECKING, annotations and importlib)."""
    import types

    import orthoscope as osc

    extra = [
        n
        for n in dir(osc)
        if n not in osc.__all__
        and not (n.startswith("__") and n.endswith("__"))
        and not isinstance(getattr(osc, n), types.ModuleType)
    ]
    assert extra == []
    assert set(osc.__all__) <= set(dir(osc))
    for helper in ("Any", "TYPE_CHECKING", "annotations", "importlib", "_API", "_version"):
        assert helper not in dir(osc)


@pytest.mark.parametrize("pkg", sorted(LAYERS))
def test_results_holding_arrays_are_eq_false(pkg):
    """docs/design.md, "Conventions": a dataclass with an array field is ``eq=False`` (a
    generated ``==`` would compare arrays and raise "truth value of an array is ambiguous")."""
    bad = []
    for path, tree in _modules(pkg):
        for node in ast.walk(tree):
            if not isinstance(node, ast.ClassDef):
                continue
            deco = [
                d
                for d in node.decorator_list
                if (isinstance(d, ast.Call) and getattr(d.func, "id", "") == "dataclass")
                or getattr(d, "id", "") == "dataclass"
            ]
            if not deco:
                continue
            arrays = [
                s.target.id
                for s in node.body
                if isinstance(s, ast.AnnAssign)
                and isinstance(s.target, ast.Name)
                and re.search(r"\b(ndarray|NDArray)\b", ast.unparse(s.annotation))
                and not ast.unparse(s.annotation).startswith("Callable")  # a function field
            ]
            kw = {k.arg: k.value for k in getattr(deco[0], "keywords", [])}
            eq_false = isinstance(kw.get("eq"), ast.Constant) and kw["eq"].value is False
            if arrays and not eq_false:
                bad.append(f"{path.relative_to(ROOT)}:{node.lineno} {node.name} ({arrays[0]})")
    assert not bad, "dataclasses holding arrays without eq=False:\n" + "\n".join(bad)
