"""No private name (a leading underscore, not a dunder) is imported from one of the package's modules into another,
anywhere in workflow/: the package, the rule scripts, the rule files and the Snakefile. A name another module uses is
public where it is defined; a private alias of a public name (``from .latex import plain_text as _t``) is fine. The
tests may import private helpers: they are not checked."""

import ast
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
WORKFLOW = ROOT / "workflow"
PACKAGE = "contactid"

# a ``from contactid... import ...`` statement in a rule file or the Snakefile, its names up to the end of the line
# or, parenthesised, up to the closing parenthesis
SMK_IMPORT = re.compile(rf"^\s*from\s+{PACKAGE}(?:\.[\w.]+)?\s+import\s+(\([^)]*\)|[^\n#]*)", re.MULTILINE)


def _is_private(name: str) -> bool:
    return name.startswith("_") and not (name.startswith("__") and name.endswith("__"))


def private_imports_in_python(source: str, where: str = "<source>") -> list[str]:
    """The private names ``source`` imports from the package's modules (a relative import, or one from
    ``contactid...``), each as ``where:line: from module import name``."""
    found = []
    for node in ast.walk(ast.parse(source)):
        if not isinstance(node, ast.ImportFrom):
            continue
        module = node.module or ""
        if node.level == 0 and module != PACKAGE and not module.startswith(PACKAGE + "."):
            continue
        for alias in node.names:
            if _is_private(alias.name):
                found.append(f"{where}:{node.lineno}: from {'.' * node.level}{module} import {alias.name}")
    return found


def private_imports_in_rules(source: str, where: str = "<source>") -> list[str]:
    """The private names the ``from contactid... import ...`` lines of a rule file (or the Snakefile) import."""
    found = []
    for match in SMK_IMPORT.finditer(source):
        line = source.count("\n", 0, match.start()) + 1
        for item in match.group(1).strip("()").split(","):
            name = item.split()[0] if item.split() else ""
            if _is_private(name):
                found.append(f"{where}:{line}: {match.group(0).strip().splitlines()[0]} ... {name}")
    return found


def private_imports() -> list[str]:
    """Every private name imported across the package's modules in workflow/ and the Snakefile."""
    found = []
    for path in sorted(WORKFLOW.rglob("*.py")):
        if "__pycache__" in path.parts:
            continue
        found += private_imports_in_python(path.read_text(), str(path.relative_to(ROOT)))
    for path in [ROOT / "Snakefile", *sorted(WORKFLOW.rglob("*.smk"))]:
        found += private_imports_in_rules(path.read_text(), str(path.relative_to(ROOT)))
    return found


def test_no_private_name_is_imported_across_the_packages_modules():
    found = private_imports()
    assert not found, "private names imported from another module (make them public where defined):\n" + "\n".join(
        found
    )


def test_the_finder_flags_a_private_name_and_passes_a_private_alias():
    assert private_imports_in_python("from .x import _y\n") == ["<source>:1: from .x import _y"]
    assert private_imports_in_python("from contactid.x import (\n    a,\n    _b,\n)\n") != []
    assert private_imports_in_python("from .x import y as _y\nfrom .x import __version__\n") == []
    assert private_imports_in_python("from numpy import _private\n") == []
    assert private_imports_in_rules("from contactid.x import a, _y\n") != []
    assert private_imports_in_rules("from contactid.x import y as _y\n") == []
