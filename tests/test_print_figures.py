"""Every figure the report includes is drawn at the width paper/report.tex prints it at, with no text under 8 pt
(issue 17): the figures are drawn from small synthetic datasets and caught before they are written."""

import re
import warnings
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from contactid import print_style as ps
from contactid.friction_parameters import parameter_dataset
from contactid.modal_figures import plot_fig03, plot_stability
from contactid.paper_figures import plot_fig04, plot_fig05, plot_fig06, plot_friction_figures
from contactid.studies import QUANTITIES, plot_noise_study, report_section

REPORT = Path(__file__).resolve().parents[1] / "paper" / "report.tex"
FIGURES = [
    "fig03_frf",
    "stability",
    "fig04_generalized_coordinates",
    "fig05_reconstruction",
    "fig06_contact_forces",
    "fig07_e0",
    "fig08_s_xi",
    "fig09_s_xidot",
]


def printed_widths_in() -> dict:
    """{figure: printed width (in)} from report.tex's \\includegraphics and its page geometry."""
    tex = REPORT.read_text()
    assert "a4paper" in tex
    margin_cm = float(re.search(r"\\usepackage\[margin=([0-9.]+)cm\]\{geometry\}", tex).group(1))
    text_width = (21.0 - 2 * margin_cm) / 2.54
    assert text_width == pytest.approx(ps.TEXT_WIDTH_IN, rel=1e-12)
    found = re.findall(r"\\includegraphics\[width=([0-9.]*)\\textwidth\]\{([A-Za-z0-9_]+)\.pdf\}", tex)
    return {name: (float(frac) if frac else 1.0) * text_width for frac, name in found}


@pytest.fixture
def caught(monkeypatch):
    """The figures the plotting functions would save, by file stem, drawn but not written."""
    figures = {}

    def save(fig, png, pdf=None):
        fig.canvas.draw()
        figures[Path(png).stem] = fig

    monkeypatch.setattr(ps, "save", save)
    yield figures
    for fig in figures.values():
        ps.pyplot().close(fig)


def _frf_and_modal():
    f = np.arange(0.0, 600.0, 0.25)
    fn, zeta = np.array([55.0, 167.0, 338.0]), np.array([0.005, 0.005, 0.005])
    iw = 2j * np.pi * f
    R = np.array([[-0.1j, -0.3j, -0.6j], [-0.05j, 0.2j, -0.1j], [-0.01j, 0.03j, -0.1j]]) * 2 * np.pi
    H = np.zeros((3, f.size), dtype=complex)
    for r, (f0, z) in enumerate(zip(fn, zeta)):
        s = 2 * np.pi * f0 * (-z + 1j * np.sqrt(1 - z**2))
        H += iw**2 * (R[:, r, None] / (iw - s) + np.conj(R[:, r, None]) / (iw - np.conj(s)))
    frf = xr.Dataset(
        {
            "h1_real": (("sensor", "frequency"), H.real),
            "h1_imag": (("sensor", "frequency"), H.imag),
            "coherence": (("sensor", "frequency"), np.ones(H.shape)),
        },
        coords={"sensor": ["a1", "a2", "a3"], "frequency": f},
    )
    modal = xr.Dataset(
        {"natural_frequency": ("mode", fn), "damping_ratio": ("mode", zeta)},
        coords={"mode": [1, 2, 3]},
        attrs={"band_low_hz": 20.0, "band_high_hz": 450.0, "order": 12},
    )
    return frf, modal


def _loops(truth: bool):
    t = np.linspace(0, 2 * np.pi, 400)
    v = {"S": 30 * np.sin(t), "xi": 1e-5 * np.cos(t), "N_dyn": 12 * np.sin(t), "eta": 5e-7 * np.sin(t + 0.1)}
    data = {k: ("time", x) for k, x in v.items()}
    data.update({f"{k}_paper": ("time", 8 * x) for k, x in v.items()})
    if truth:
        data.update({f"{k}_truth": ("time", 1.02 * x) for k, x in v.items()})
    return {c: xr.Dataset(data, coords={"time": t}) for c in ("lc1", "lc2", "lc3")}


def _draw_all(truth: bool = True):
    frf, modal = _frf_and_modal()
    plot_fig03(frf, modal, "fig03_frf.png", "fig03_frf.pdf")
    plot_stability(frf, modal, "stability.png", "stability.pdf")
    t = np.linspace(0, 0.06, 600)
    gc = xr.Dataset(
        {"p": (("mode", "time"), np.vstack([np.sin(2 * np.pi * 50 * k * t) for k in (1, 3, 5)]) * 1e-4)},
        coords={"mode": [1, 2, 3], "time": t},
        attrs={"excitation_frequency_hz": 54.0},
    )
    plot_fig04(gc, "lc3", "fig04_generalized_coordinates.png", "x.pdf")
    s = 50 * np.sin(2 * np.pi * 54 * t)
    nnm = xr.Dataset(
        {"drive_measured": ("time", s), "drive_reconstructed": ("time", 1.01 * s)},
        coords={"time": t},
        attrs={"excitation_frequency_hz": 54.0, "reconstruction_nrmse": 0.013},
    )
    plot_fig05(nnm, "lc3", "fig05_reconstruction.png", "x.pdf")
    plot_fig06(_loops(truth), "fig06_contact_forces.png", "x.pdf")
    fit = parameter_dataset([1e6, 0.05, 1e4, 0.5, 0.4], "none").assign(
        ga_best=("generation", np.geomspace(1, 0.01, 20)), ga_mean=("generation", np.geomspace(2, 0.02, 20))
    )
    fit = fit.assign_coords(parameter=["e_f", "k_c", "e_t", "kappa", "mu"], generation=np.arange(20))
    fit.attrs.update({"preload_n": 70.0, "misfit_nrmse": 0.005})
    x = np.linspace(0, 2 * np.pi, 200)
    val = xr.Dataset(
        {
            "N": ("time", 70 + 10 * np.sin(x)),
            "xi": ("time", 1e-5 * np.cos(x)),
            "xi_dot": ("time", -1e-3 * np.sin(x)),
            "S_identified": ("time", 30 * np.sin(x)),
            "S_predicted": ("time", 30 * np.sin(x)),
        },
        attrs={"nrmse_vs_identified": 0.004},
    )
    names = {"fig07": "fig07_e0", "fig08": "fig08_s_xi", "fig09": "fig09_s_xidot", "convergence": "convergence"}
    paths = {f"{k}_{ext}": f"{v}.{ext}" for k, v in names.items() for ext in ("png", "pdf")}
    plot_friction_figures(fit, {c: val for c in ("lc1", "lc2", "lc3")}, None, paths)


def assert_print_rule(fig, name: str, width_in: float) -> None:
    """``fig`` is drawn at ``width_in`` and no text renders under MIN_FONT_PT on paper: mathtext sub- and
    superscripts (70 % of the font size) count at their rendered size (print_style.rendered_sizes_pt)."""
    assert fig.get_size_inches()[0] == pytest.approx(width_in, abs=1e-6), name
    small = [(text, size) for size, text in ps.rendered_sizes_pt(fig) if size < ps.MIN_FONT_PT]
    assert not small, f"{name}: text rendered under {ps.MIN_FONT_PT} pt: {small}"


@pytest.fixture
def no_missing_glyphs():
    """Fails the test when the font lacks a glyph the figures draw (the Unicode sub- and superscripts)."""
    with warnings.catch_warnings(record=True) as caught_warnings:
        warnings.simplefilter("always")
        yield
    missing = [str(w.message) for w in caught_warnings if "missing from" in str(w.message)]
    assert not missing, missing


@pytest.mark.slow
def test_every_report_figure_is_drawn_at_its_printed_width_with_8pt_text(caught, no_missing_glyphs):
    widths = printed_widths_in()
    assert set(FIGURES) <= set(widths), "report.tex includes each figure at an explicit fraction of \\textwidth"
    _draw_all()
    for name in FIGURES:
        assert_print_rule(caught[name], name, widths[name])


def test_the_rendered_size_counts_mathtext_subscripts_at_70_percent():
    """The check above would catch a label like the old Fig. 5's 'd$_p$ (m s$^{-2}$)': 5.6 pt at 8 pt."""
    plt = ps.pyplot()
    with plt.rc_context(ps.STYLE):
        fig, ax = plt.subplots(figsize=(ps.TEXT_WIDTH_IN, 2))
        ax.set_ylabel("acceleration at d$_p$ (m s$^{-2}$)")
        ax.set_xlabel("acceleration at " + "d" + ps.sub("p") + " (m s" + ps.sup("-2") + ")")
        fig.canvas.draw()
    sizes = dict((text, size) for size, text in ps.rendered_sizes_pt(fig))
    plt.close(fig)
    assert sizes["acceleration at d$_p$ (m s$^{-2}$)"] == pytest.approx(5.6)
    assert sizes["acceleration at dₚ (m s⁻²)"] == 8.0


def test_fig06_limits_come_from_the_working_method_also_without_truth(caught):
    """Without truth (measured data) the working method's loops fill their panels: the paper's chain, eight times
    larger, has rows of its own and leaves the working method's limits alone."""
    plot_fig06(_loops(truth=False), "fig06_contact_forces.png", "x.pdf")
    axes = caught["fig06_contact_forces"].axes
    assert len(axes) == 12
    for ax, span in zip(axes[:6], (60.0, 60.0, 60.0, 24.0, 24.0, 24.0)):
        lo, hi = ax.get_ylim()
        assert span <= hi - lo <= 1.2 * span
    for ax, span in zip(axes[6:], (480.0, 480.0, 480.0, 192.0, 192.0, 192.0)):
        lo, hi = ax.get_ylim()
        assert span <= hi - lo <= 1.2 * span
    legend = caught["fig06_contact_forces"].legends[0]
    assert [t.get_text() for t in legend.get_texts()] == ["working method", "paper's chain"]


def test_fig06_draws_each_loop_over_the_records_last_periods(caught):
    """A record of 100 periods whose first periods are a transient 50 times the settled loop: Fig. 6 draws the last
    LOOP_PERIODS periods (about 400 of 10 000 samples at 100 samples a period), so the transient neither fills the
    PDF nor sets the axis limits; a dataset that does not give its frequency is drawn whole."""
    from contactid.paper_figures import LOOP_PERIODS

    f0, fs = 50.0, 5000.0
    t = np.arange(10_000) / fs
    transient = 1 + 49 * np.exp(-t / 0.05)
    v = {
        "S": 30 * transient * np.sin(2 * np.pi * f0 * t),
        "xi": 1e-5 * transient * np.cos(2 * np.pi * f0 * t),
        "N_dyn": 12 * np.sin(2 * np.pi * f0 * t),
        "eta": 5e-7 * np.sin(2 * np.pi * f0 * t + 0.1),
    }
    data = {k: ("time", x) for k, x in v.items()} | {f"{k}_paper": ("time", 8 * x) for k, x in v.items()}
    ds = xr.Dataset(data, coords={"time": t}, attrs={"excitation_frequency_hz": f0})
    plot_fig06({"lc1": ds}, "fig06_contact_forces.png", "x.pdf")
    ax = caught["fig06_contact_forces"].axes[0]
    n = len(ax.lines[0].get_xdata())
    assert abs(n - LOOP_PERIODS * fs / f0) <= 2
    lo, hi = ax.get_ylim()
    assert 60.0 <= hi - lo <= 1.2 * 60.0  # the settled loop's span, not the transient's
    ps.pyplot().close(caught.pop("fig06_contact_forces"))
    plot_fig06({"lc1": ds.assign_attrs(excitation_frequency_hz=None)}, "fig06_contact_forces.png", "x.pdf")
    assert len(caught["fig06_contact_forces"].axes[0].lines[0].get_xdata()) == t.size


def test_the_noise_study_figure_is_drawn_at_the_width_its_section_includes_it(caught, no_missing_glyphs):
    """The noise study's figure (in the report when noise_study.in_report) at the text width, text >= 8 pt."""
    noise, lengths, seeds = np.array([0.001, 0.003, 0.01, 0.03]), np.array([4096, 16384]), np.arange(3)
    rng = np.random.default_rng(0)
    ds = xr.Dataset(
        {
            f"error_{q}": (("noise_fraction", "record_samples", "seed"), rng.normal(0, 0.01, (4, 2, 3)))
            for q in QUANTITIES
        },
        coords={"noise_fraction": noise, "record_samples": lengths, "seed": seeds},
        attrs={"default_noise_fraction": 0.003},
    )
    assert "\\includegraphics[width=\\textwidth]{noise_study.pdf}" in report_section(ds)
    plot_noise_study(ds, 0.003, "noise_study.png", "noise_study.pdf")
    assert_print_rule(caught["noise_study"], "noise_study", ps.TEXT_WIDTH_IN)


def _gap_diagnosis() -> dict:
    """A diagnosis with a candidate that shrinks the gap, two that do not move it (one ends above 'before', as
    zero-effect refits do by the bootstrap's noise), one diverged, and a zero stage value."""
    row = {"n_parameters": 1, "heldout_gap_before": 0.0025, "score": 1.0, "reduction": None, "parameters": {}}
    rows = [
        {
            **row,
            "effect": "contact_separation",
            "heldout_gap_after": 0.00175,
            "heldout_gap_after_interval": [0.0017, 0.0018],
        },
        {
            **row,
            "effect": "structural_damping",
            "heldout_gap_after": 0.00256,
            "heldout_gap_after_interval": [0.0025, 0.0026],
        },
        {
            **row,
            "effect": "viscous_friction",
            "heldout_gap_after": 0.0025,
            "heldout_gap_after_interval": [0.0025, 0.0025],
        },
        {**row, "effect": "preload_drift", "heldout_gap_after": None, "heldout_gap_after_interval": [None, None]},
    ]
    stage = {"accelerations": 0.0023, "identification_residual": 2.8e-5, "open_fraction": 0.0, "contact_force_N": 0.1}
    by_case = {
        c: {"before": 0.0025, "before_interval": [0.0024, 0.0026], "after": 0.0018, "after_interval": [0.0017, 0.0019]}
        for c in ("lc2", "lc3")
    }
    harm = {"before": [0.001, 1e-4, 0.001], "after": [0.0009, 1e-4, 0.0008]}
    return {
        "verdict": "none",
        "ranking": rows,
        "where": {
            "stage": stage,
            "heldout_gap_before": 0.0025,
            "record_scatter": 2.9e-5,
            "identification_noise": {"lc1": 9e-6, "lc2": 8e-6, "lc3": 6e-6},
            "place": "contact",
        },
        "explanation": [],
        "remaining_gap": {"heldout_gap": 0.0025, "share": 1.0, "floor": 0.006, "at_floor": True, "place": "contact"},
        "shrink": {
            "winner": {"effect": "contact_separation", "by_case": by_case, "by_harmonic": harm},
            "runner_up": {"effect": "structural_damping", "by_case": by_case, "by_harmonic": harm},
        },
    }


def test_the_gap_figures_the_report_includes_meet_the_print_rule(caught, no_missing_glyphs):
    """The gap section includes its four figures as PDFs at the text width they are drawn at, text >= 8 pt."""
    from contactid.gap import figures
    from contactid.gap.report import gap_section

    diag = _gap_diagnosis()
    tex = gap_section({**diag, "calibration_case": "lc1", "reason": "r"} | {"where": _where_for_text(diag)}, None)
    found = dict(
        (name, frac)
        for frac, name in re.findall(r"\\includegraphics\[width=([0-9.]*)\\textwidth\]\{(gap_\w+)\.pdf\}", tex)
    )
    assert set(found) == {f"gap_{v}" for v in figures.IN_REPORT} and set(found.values()) == {""}
    assert not re.search(r"\\includegraphics\[[^]]*\]\{[^}]*\.png\}", tex)  # no PNG scaled into the page
    for view in figures.IN_REPORT:
        getattr(figures, view)(diag, f"gap_{view}.png", f"gap_{view}.pdf")
        assert_print_rule(caught[f"gap_{view}"], view, ps.TEXT_WIDTH_IN)


def _where_for_text(diag: dict) -> dict:
    """The 'where' block with what the section's text reads besides the figures."""
    stage = {k: 0.001 for k in ("generalized_coordinates", "contact_force_S", "energy_tangential")}
    return {
        **diag["where"],
        "stage": {**stage, **diag["where"]["stage"]},
        "heldout_gap_before_interval": [0.0024, 0.0026],
        "by_harmonic": {1: 0.001},
        "worst_sensor": "a1",
        "worst_harmonic": 1,
        "even_share": 0.1,
        "worst_cycle_part": "slip",
        "place_reason": "eta not observable",
    }


def test_the_ranking_clips_a_candidate_without_effect_at_before_and_draws_min_gap_and_the_scatter(caught):
    """Read back from the Axes: a candidate whose held-out gap after is at or above before ends at before,
    labelled no effect; the effective one ends at its own gap; the lines sit at the diagnosis' values (%)."""
    from contactid.gap import figures
    from matplotlib.patches import Rectangle

    figures.ranking(_gap_diagnosis(), "gap_ranking.png")
    ax = caught["gap_ranking"].axes[0]
    ends = {r.get_gid()[4:]: r.get_width() for r in ax.findobj(Rectangle) if (r.get_gid() or "").startswith("bar:")}
    assert ends == pytest.approx({"contact_separation": 0.175, "structural_damping": 0.25, "viscous_friction": 0.25})
    marked = {t.get_gid()[10:] for t in ax.texts if t.get_text() == "no effect"}
    assert marked == {"structural_damping", "viscous_friction"}
    assert any(t.get_text() == "prediction diverged" for t in ax.texts)
    lines = {line.get_label().split(":")[0]: line.get_xdata()[0] for line in ax.get_lines()}
    assert lines["before (identified model)"] == pytest.approx(0.25)
    assert lines["gap.min_gap"] == pytest.approx(0.6)
    assert lines["records' scatter"] == pytest.approx(0.0029)
    assert ax.get_xlim()[1] >= 0.6  # min_gap in view, which explains the verdict none


def test_the_stage_figure_has_readable_labels_thresholds_and_a_visible_zero(caught):
    from contactid.gap import figures

    figures.stages(_gap_diagnosis(), "gap_stages.png")
    ax = caught["gap_stages"].axes[0]
    labels = [t.get_text() for t in ax.get_yticklabels()]
    assert "contact force N (elastic normal law)" in labels and not any("_" in lab for lab in labels)
    marks = {line.get_gid(): line.get_xdata()[0] for line in ax.get_lines() if line.get_gid()}
    assert marks == pytest.approx(
        {"threshold:heldout": 0.6, "threshold:contact_force_N": 25.0, "threshold:identification_residual": 20 * 8e-4}
    )
    assert [t.get_gid() for t in ax.texts if t.get_text() == "0" and t.get_gid()] == ["zero:open_fraction"]
    assert [t.get_text() for t in ax.texts if t.get_text().startswith("10 %")] == ["10 %  (normal_limit: 25 %)"]
