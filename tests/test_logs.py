"""Progress a person can read: the GA logs its generations with plain numbers, and a rule's log
records reach the console (stderr) in a short format as well as the log file."""

import logging
import re
import sys

import numpy as np
import pytest
from contactid.friction import valanis_friction_force
from contactid.friction_fit import FitSettings, fit_friction_law
from contactid.logs import fmt, setup_logging

TRUE = np.array([3.857e7, 2.547e5, 1.0e4, 0.284, 0.397])
NUMPY_REPR = re.compile(r"array\(|np\.\w+\(|\[\s*\d[\d.e+-]*\s+\d")  # array(...), np.float64(...), "[ 1.2  3.4]"


def coefficients(x, k=25):
    return (2j * np.fft.fft(x)[1 : k + 1] / x.size)[None]


def test_ga_logs_its_generations_with_plain_numbers(caplog):
    t = np.arange(1024) / 1024
    xi = 1e-5 * np.sin(2 * np.pi * t) + 3e-6 * np.sin(6 * np.pi * t + 0.3)
    n = 70 + 12 * np.sin(2 * np.pi * t + 0.5) + 4 * np.sin(6 * np.pi * t)
    S = valanis_friction_force(xi, n, TRUE[None])[0]
    settings = FitSettings(population=12, generations=16, grid_points=128, max_grid_points=256)
    with caplog.at_level(logging.INFO, logger="contactid"):
        fit_friction_law(
            coefficients(xi),
            coefficients(n - 70.0),
            coefficients(S),
            54.375,
            70.0,
            settings,
            seed=3,
            n_harmonics_data=25,
            intervals=False,
            label="synthetic fit",
        )
    messages = [r.getMessage() for r in caplog.records if r.name.startswith("contactid")]
    generations = [m for m in messages if "GA generation" in m]
    # every few generations (about eight lines per run), the last one always
    assert 2 <= len(generations) <= 9
    assert generations[-1].startswith("synthetic fit: GA generation 16/16: best misfit ")
    for m in generations:
        match = re.fullmatch(r"synthetic fit: GA generation (\d+)/16: best misfit (\S+), mean (\S+)", m)
        assert match, m
        float(match.group(2)), float(match.group(3))  # plain numbers
    best = [float(re.search(r"best misfit (\S+),", m).group(1)) for m in generations]
    assert best == sorted(best, reverse=True)  # elitism: the best never worsens
    assert any(m.startswith("synthetic fit: polished on 128 points: misfit ") for m in messages)
    assert not [m for m in messages if NUMPY_REPR.search(m)]


@pytest.fixture
def restored_logging():
    root = logging.getLogger()
    saved = root.handlers[:], root.level, sys.excepthook
    yield
    for h in root.handlers:
        if h not in saved[0]:
            h.close()
    root.handlers[:], sys.excepthook = saved[0], saved[2]
    root.setLevel(saved[1])
    logging.captureWarnings(False)


def test_rule_log_goes_to_file_and_short_lines_to_console(tmp_path, capsys, restored_logging):
    path = tmp_path / "friction_fit.log"
    log = setup_logging(str(path))
    logging.getLogger("contactid.friction_fit").info("GA generation %d/%d: best misfit %.4g", 5, 40, np.float64(0.0123))
    logging.getLogger("fontTools.subset").info("a library's chatter")  # the log file only
    logging.getLogger("somelib").warning("a library's warning")  # warnings reach the console too
    log.info("fitted %s", fmt({np.str_("mu"): np.float64(0.39598540251)}))
    for h in logging.getLogger().handlers:
        h.flush()
    err = capsys.readouterr().err.splitlines()
    assert [re.sub(r"^\d\d:\d\d:\d\d ", "", line) for line in err] == [
        "friction_fit: GA generation 5/40: best misfit 0.0123",
        "friction_fit: WARNING: a library's warning",
        "friction_fit: fitted mu = 0.396",
    ]
    text = path.read_text()
    assert "INFO contactid.friction_fit: GA generation 5/40: best misfit 0.0123" in text
    assert "a library's chatter" in text and "fitted mu = 0.396" in text


def test_fmt_writes_numbers_for_people():
    assert fmt(np.array([54.79173833, 166.91531485, 338.21649659]), 5) == "[54.792, 166.92, 338.22]"
    assert fmt({"lc2": np.float64(0.0034812), "lc3": 3}) == "lc2 = 0.003481, lc3 = 3"
    assert not NUMPY_REPR.search(fmt({np.str_("e_f"): np.float64(3.9e7), "bounded": np.bool_(True)}))
