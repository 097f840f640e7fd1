"""docs/measurements.md, the measurement log, by topic: each topic (`## `) opens with a Latest paragraph (its newest
figures and where every run is listed), and each heading names what was measured, not when: no date, no session, no
commit hash. An entry's first line gives its date and commit."""

import re
from pathlib import Path

LOG = Path(__file__).resolve().parents[2] / "docs" / "measurements.md"
# a commit hash: 7-12 hex characters with a digit and a letter among them; a date: YYYY-MM-DD
HASH = re.compile(r"\b(?=[0-9a-f]*[0-9])(?=[0-9a-f]*[a-f])[0-9a-f]{7,12}\b", re.IGNORECASE)
DATE = re.compile(r"\b\d{4}-\d{2}-\d{2}\b")
SESSION = re.compile(r"session", re.IGNORECASE)
LATEST_MAX_LINES = 8


def _lines() -> list:
    return LOG.read_text().splitlines()


def _headings() -> list:
    """(line number, level, text) of every `## ` and `### ` heading."""
    found = []
    for n, line in enumerate(_lines(), 1):
        m = re.match(r"^(#{2,3}) (.*)$", line)
        if m:
            found.append((n, len(m.group(1)), m.group(2)))
    return found


def _topics() -> dict:
    """Each `## ` topic's heading and the lines under it, up to the next topic."""
    topics, current = {}, None
    for line in _lines():
        if line.startswith("## "):
            current = line[3:]
            assert current not in topics, f"topic twice: {current}"
            topics[current] = []
        elif current is not None:
            topics[current].append(line)
    return topics


def test_the_patterns_find_what_they_should():
    assert HASH.findall("at 84a1b75 and C9B2C73") == ["84a1b75", "C9B2C73"]
    assert not HASH.findall("1234567 deadbee feedface 54.4 Hz")  # digits alone, letters alone
    assert DATE.findall("on 2026-12-04, not 12/04") == ["2026-12-04"]
    assert SESSION.search("(Thirty-eighth Session)")


def test_headings_name_what_was_measured_not_when():
    found = []
    for n, level, text in _headings():
        for what, pattern in (("a date", DATE), ("a session", SESSION), ("a commit", HASH)):
            if pattern.search(text):
                found.append(f"docs/measurements.md:{n}: {'#' * level} {text} ({what})")
    assert not found, "\n".join(found)


def test_entry_headings_are_unique():
    texts = [text for _, level, text in _headings() if level == 3]
    repeated = sorted({t for t in texts if texts.count(t) > 1})
    assert not repeated, repeated


def test_every_topic_opens_with_its_latest_figures_and_holds_entries():
    topics = _topics()
    assert topics, "no `## ` topic in docs/measurements.md"
    for topic, lines in topics.items():
        body = [line for line in lines if not line.startswith("### ")]
        first = next((i for i, line in enumerate(lines) if line.strip()), None)
        assert first is not None and lines[first].startswith("**Latest.**"), f"{topic}: no Latest paragraph first"
        paragraph = []
        for line in lines[first:]:
            if not line.strip():
                break
            paragraph.append(line)
        assert not any(line.startswith("#") for line in paragraph), f"{topic}: the Latest paragraph runs into a heading"
        assert len(paragraph) <= LATEST_MAX_LINES, f"{topic}: Latest is {len(paragraph)} lines"
        assert "benchmarks/history.csv" in " ".join(paragraph), f"{topic}: Latest does not point to the run log"
        assert len(body) < len(lines), f"{topic}: no `### ` entry"


def test_every_entry_lies_under_a_topic():
    levels = [level for _, level, _ in _headings()]
    assert levels and levels[0] == 2, "an entry before the first topic"
