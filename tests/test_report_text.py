"""The report's text: the values it quotes for any set of load cases, and the contact forces without truth."""

import pandas as pd
from contactid.report_text import contact_fragment


def test_contact_forces_without_truth_get_a_paragraph_not_a_table_of_dashes():
    nan = float("nan")
    rows = [{"case": "lc1", **{f"{m}_{q}": nan for m in "wp" for q in ("S", "N", "xi", "eta")}}]
    text = contact_fragment(pd.DataFrame(rows))
    assert "no truth is known" in text and "tabular" not in text
    rows[0]["w_S"] = 0.7
    table = contact_fragment(pd.DataFrame(rows))
    assert "\\begin{tabular}" in table and "$0.700$" in table and "tab:contact" in table


def _summary(cases, validation):
    return {
        "natural_frequencies_hz": [54.0],
        "stiction": {"k_t": 1e7, "k_t_interval": [9e6, 1.1e7], "k_n_lower_bound": 1e6},
        "contact_forces": {c: {"normal_stiffness_from_n_eta_n_per_m": 1e7 * (i + 1)} for i, c in enumerate(cases)},
        "contact_forces_paper": {
            c: {"nnm_phase_spread_deg": [1.0, 10.0 * (i + 1)], "reconstruction_nrmse": 0.01 * (i + 1)}
            for i, c in enumerate(cases)
        },
        "validation_nrmse": validation,
    }


def test_the_text_quotes_the_configured_calibration_and_figure_cases_for_any_set_of_load_cases():
    import pandas as pd
    from contactid.latex import macros
    from contactid.report_text import report_values

    cons = pd.DataFrame(columns=["scenario", "max_abs_err_pct", "k_t_n_per_m", "tangential_lever_arm_m"])
    cons["youngs_modulus_pa"] = []
    cases = ["lc2", "lc10", "lc4"]
    v = report_values(
        _summary(cases, {"lc2": 0.01, "lc4": 0.02, "lc10": 0.03}), cons, calibration_case="lc4", figure_case="lc2"
    )
    assert v["calcase"] == "load case 4" and v["figcase"] == "load case 2"
    assert v["calknfromneta"] == 3e7  # lc4's own value, not the first case's
    assert v["figcaserecon"] == 1.0 and v["figcasephase"] == 10.0
    # the cases the law was not fitted on, in their numeric order, with their own NRMSE
    assert v["validationtext"] == (
        "The law predicts the other load cases with NRMSE \\ensuremath{1.000}\\,\\% (load case 2) and "
        "\\ensuremath{3.000}\\,\\% (load case 10)"
    )
    assert "\\newcommand{\\validationtext}{The law predicts" in macros(v)
    one = report_values(_summary(["lc1"], {"lc1": 0.01}), cons, calibration_case="lc1", figure_case="lc3")
    assert one["figcase"] == "load case 1" and "no other" in one["validationtext"]


def test_k_n_is_said_as_a_bound_where_the_data_bound_it_from_one_side_only():
    # "interval 5.678e6--{--}" read as a typesetting slip: a lower bound says "k_n >= ...", a value its interval
    from contactid.report_text import report_values

    cons = pd.DataFrame(
        columns=["scenario", "max_abs_err_pct", "k_t_n_per_m", "tangential_lever_arm_m", "youngs_modulus_pa"]
    )
    below = report_values(_summary(["lc1"], {"lc1": 0.01}), cons, calibration_case="lc1", figure_case="lc1")
    assert below["knclause"] == r"$k_n \geq 1.000\times10^{6}$\,N/m: the frequencies bound it from below only"
    both = _summary(["lc1"], {"lc1": 0.01})
    both["stiction"] = {**both["stiction"], "k_n": 2.4e7, "k_n_interval": [2.0e7, 2.9e7]}
    v = report_values(both, cons, calibration_case="lc1", figure_case="lc1")
    assert v["knclause"] == (
        r"$k_n = 2.400\times10^{7}$\,N/m, bounded on both sides (interval $2.000\times10^{7}$--$2.900\times10^{7}$)"
    )
