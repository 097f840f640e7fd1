"""The package's docstrings follow numpydoc (CONTRIBUTING.md, "Docstrings").

ruff's pydocstyle rules with the numpy convention check their form (tests/project/test_environment.py runs ruff) and
pydoclint checks the sections against the signatures; these tests run pydoclint and check what neither can: every
parameter, attribute and result typed `float` or an array states its unit in brackets, and every array its shape.
"""

from __future__ import annotations

import ast
import re
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest
from docstring_parser import DocstringStyle, parse

ROOT = Path(__file__).resolve().parents[2]
PACKAGE = ROOT / "workflow" / "contactid"

NUMERIC = re.compile(r"\b(float|np\.ndarray|ndarray|NDArray|ArrayLike|np\.floating)\b")
ARRAY = re.compile(r"\b(np\.ndarray|ndarray|NDArray|ArrayLike)\b")
# the unit symbols a bracket may combine with /, *, spaces, commas, parentheses and ^exponents; "-" and "1" mark a
# dimensionless number, "[unit of x]" a quantity in the unit of argument x
UNITS = {
    *("m", "mm", "um", "s", "ms", "us", "kg", "g", "N", "Hz", "rad", "Pa", "J", "W", "V", "dB", "%", "deg", "1", "-"),
    *("cycle", "cycles", "sample", "samples", "mode", "dof", "pt"),
}
BRACKET = re.compile(r"\[([^\[\]]+)\]")


def is_unit(text: str) -> bool:
    text = re.sub(r"\^-?[\d.]+", "", re.sub(r"units? of [\w.]+", "1", text.strip()))
    tokens = [t for t in re.split(r"[\s/*·(),]+", text) if t]
    return bool(tokens) and all(t in UNITS for t in tokens)


def problems_of(name: str, kind: str, annotation: str | None, description: str | None) -> list[str]:
    if not annotation or not NUMERIC.search(annotation):
        return []
    out = []
    if not any(is_unit(b) for b in BRACKET.findall(description or "")):
        out.append(f"{name}: {kind} annotated {annotation} states no unit in brackets ([Hz], [N/m], [-], ...)")
    if ARRAY.search(annotation) and "shape (" not in (description or ""):
        out.append(f"{name}: {kind} annotated {annotation} states no shape ('shape (n_t,)')")
    return out


def function_problems(qual: str, node: ast.FunctionDef | ast.AsyncFunctionDef) -> list[str]:
    doc = parse(ast.get_docstring(node) or "", DocstringStyle.NUMPYDOC)
    params = {p.arg_name.lstrip("*"): p.description for p in doc.params if p.args[0] == "param"}
    out = []
    for a in node.args.posonlyargs + node.args.args + node.args.kwonlyargs:
        if a.arg not in ("self", "cls") and a.annotation is not None:
            out += problems_of(f"{qual}({a.arg})", "parameter", ast.unparse(a.annotation), params.get(a.arg))
    returns = ast.unparse(node.returns) if node.returns is not None else ""
    if NUMERIC.search(returns):
        entries = doc.many_returns
        if not entries:
            return [*out, f"{qual}: returns {returns} without a Returns entry"]
        # a tuple's entries are checked by their own types; a single result by the annotation where it says more
        typed = [r for r in entries if r.type_name and NUMERIC.search(r.type_name)]
        for r in typed or entries[:1]:
            annotation = r.type_name if r in typed and (len(entries) > 1 or ARRAY.search(r.type_name)) else returns
            out += problems_of(f"{qual} -> {r.return_name or r.type_name}", "result", annotation, r.description)
    return out


def class_problems(qual: str, node: ast.ClassDef) -> list[str]:
    doc = parse(ast.get_docstring(node) or "", DocstringStyle.NUMPYDOC)
    attrs = {m.arg_name: m.description for m in doc.meta if m.args[0] == "attribute"}
    out = []
    for st in node.body:
        if isinstance(st, ast.AnnAssign) and isinstance(st.target, ast.Name) and not st.target.id.startswith("_"):
            annotation = ast.unparse(st.annotation)
            if "ClassVar" not in annotation:
                out += problems_of(f"{qual}.{st.target.id}", "attribute", annotation, attrs.get(st.target.id))
    return out


def module_problems(source: str, name: str) -> list[str]:
    out: list[str] = []

    def visit(body: list[ast.stmt], prefix: str) -> None:
        for n in body:
            if isinstance(n, ast.ClassDef) and not n.name.startswith("_"):
                out.extend(class_problems(f"{prefix}{n.name}", n))
                visit(n.body, f"{prefix}{n.name}.")
            elif isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef)) and not n.name.startswith("_"):
                out.extend(function_problems(f"{prefix}{n.name}", n))

    visit(ast.parse(source).body, f"{name}:")
    return out


def test_every_float_and_array_of_the_public_api_states_a_unit_and_every_array_a_shape():
    found = []
    for path in sorted(PACKAGE.rglob("*.py")):
        found += module_problems(path.read_text(), path.relative_to(PACKAGE).as_posix())
    assert not found, f"{len(found)} docstring entries without a unit or a shape:\n" + "\n".join(found[:40])


@pytest.mark.parametrize(
    ("bracket", "ok"),
    [("N/m", True), ("m/s^2", True), ("N/m^1.5", True), ("(m/s^2)^2/Hz", True), ("-", True), ("unit of x", True)]
    + [("s^-1", True), ("m, m/s", True), ("banana", False), ("x[i]", False), ("", False), ("N per metre", False)],
)
def test_the_unit_grammar(bracket, ok):
    assert is_unit(bracket) is ok


BAD = '''
import numpy as np
from dataclasses import dataclass


def natural_frequencies(stiffness: np.ndarray, count: int, scale: float) -> np.ndarray:
    """Return the frequencies.

    Parameters
    ----------
    stiffness
        Stiffness matrix [N/m].
    count
        How many.
    scale
        A factor.

    Returns
    -------
    frequencies : np.ndarray
        Natural frequencies, shape (count,).
    """


@dataclass
class Modes:
    """Hold the modes.

    Attributes
    ----------
    frequencies
        Natural frequencies [Hz], shape (n_modes,).
    damping
        Ratios.
    """

    frequencies: np.ndarray
    damping: np.ndarray
    count: int
'''


def test_the_check_names_each_missing_unit_and_shape_and_passes_a_complete_docstring():
    found = module_problems(BAD, "bad.py")
    no_unit, no_shape = "states no unit in brackets ([Hz], [N/m], [-], ...)", "states no shape ('shape (n_t,)')"
    assert sorted(found) == sorted(
        [
            f"bad.py:Modes.damping: attribute annotated np.ndarray {no_unit}",
            f"bad.py:Modes.damping: attribute annotated np.ndarray {no_shape}",
            f"bad.py:natural_frequencies(stiffness): parameter annotated np.ndarray {no_shape}",
            f"bad.py:natural_frequencies(scale): parameter annotated float {no_unit}",
            f"bad.py:natural_frequencies -> frequencies: result annotated np.ndarray {no_unit}",
        ]
    )
    good = (
        BAD.replace("[N/m].", "[N/m], shape (n_dof, n_dof).")
        .replace("A factor.", "A factor [-].")
        .replace("frequencies, shape", "frequencies [Hz], shape")
        .replace("Ratios.", "Damping ratios [-], shape (n_modes,).")
    )
    assert module_problems(good, "good.py") == []


def run_pydoclint(*paths: Path) -> subprocess.CompletedProcess:
    cli = Path(sys.executable).with_name("pydoclint")
    cmd = [str(cli), "--config", str(ROOT / "pyproject.toml"), "-q", *map(str, paths)]
    return subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True)


def test_pydoclint_finds_every_public_function_documented_as_its_signature():
    out = run_pydoclint(PACKAGE)
    assert out.returncode == 0, f"pydoclint:\n{out.stdout[-3000:]}{out.stderr[-1000:]}"


def test_pydoclint_with_the_projects_settings_flags_an_undocumented_argument(tmp_path):
    source = textwrap.dedent('''\
        """A module."""


        def area(width: float, height: float) -> float:
            """Return the area.

            Parameters
            ----------
            width
                Width [m].

            Returns
            -------
            area : float
                Area [m^2].
            """
            return width * height
        ''')
    (tmp_path / "area.py").write_text(source)
    out = run_pydoclint(tmp_path / "area.py")
    report = out.stdout + out.stderr
    assert out.returncode != 0 and "DOC101" in report and "DOC103" in report
    fixed = source.replace("Width [m].\n", "Width [m].\n    height\n        Height [m].\n")
    (tmp_path / "area.py").write_text(fixed)
    assert run_pydoclint(tmp_path / "area.py").returncode == 0
