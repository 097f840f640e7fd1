"""The documentation against the tree: the module map (docs/layout.md) names every module of the package and no
other, the README's map names every document, and the README states what is true of the code, not its history."""

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
PACKAGE = ROOT / "workflow" / "contactid"
# a commit hash: 7-12 hex characters with a digit and a letter among them; a date: YYYY-MM-DD
HASH = re.compile(r"\b(?=[0-9a-f]*[0-9])(?=[0-9a-f]*[a-f])[0-9a-f]{7,12}\b")
DATE = re.compile(r"\b20\d\d-\d\d-\d\d\b")


def _modules() -> set:
    return {str(p.relative_to(PACKAGE)) for p in PACKAGE.rglob("*.py") if "__pycache__" not in p.parts}


def test_the_module_map_names_every_module_and_only_those():
    named = set(re.findall(r"^\| `([\w/]+\.py)` \|", (ROOT / "docs" / "layout.md").read_text(), flags=re.M))
    modules = _modules()
    assert not modules - named, f"docs/layout.md lacks {sorted(modules - named)}"
    assert not named - modules, f"docs/layout.md names modules that are gone: {sorted(named - modules)}"


def test_the_readme_maps_every_document_and_each_exists():
    readme = (ROOT / "README.md").read_text()
    named = set(re.findall(r"^\| `(docs/[\w.-]+\.md)` \|", readme, flags=re.M))
    docs = {f"docs/{p.name}" for p in (ROOT / "docs").glob("*.md")}
    assert named == docs, f"README's map: missing {sorted(docs - named)}, gone {sorted(named - docs)}"


def test_the_readme_is_short_and_tells_no_history():
    text = (ROOT / "README.md").read_text()
    assert len(text.splitlines()) <= 90
    assert not HASH.findall(text), HASH.findall(text)
    assert not DATE.findall(text), DATE.findall(text)


def test_the_history_patterns_find_what_they_should():
    assert HASH.findall("at 84a1b75 and c9b2c73") == ["84a1b75", "c9b2c73"]
    assert not HASH.findall("1234567 deadbee feedface 54.4 Hz")  # digits alone, letters alone
    assert DATE.findall("on 2026-12-04, not 12/04") == ["2026-12-04"]


def test_docstrings_and_comments_tell_no_history():
    """No commit hash or date in the package, the rule scripts or the rules: they state what the code does."""
    found = []
    for p in [*(ROOT / "workflow").rglob("*.py"), *(ROOT / "workflow").rglob("*.smk")]:
        if "__pycache__" in p.parts:
            continue
        for n, line in enumerate(p.read_text().splitlines(), 1):
            if HASH.search(line) or DATE.search(line):
                found.append(f"{p.relative_to(ROOT)}:{n}")
    assert not found, found


def test_the_user_docs_tell_no_history():
    """config/README.md and docs/ other than the measurement log: no commit hash, no date."""
    found = []
    for p in [ROOT / "config" / "README.md", *(ROOT / "docs").glob("*.md")]:
        if p.name == "measurements.md":
            continue
        for n, line in enumerate(p.read_text().splitlines(), 1):
            if HASH.search(line) or DATE.search(line):
                found.append(f"{p.relative_to(ROOT)}:{n}: {line.strip()[:80]}")
    assert not found, found
