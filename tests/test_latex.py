"""The report's LaTeX fragments: text cells escaped, numbers with the digits their uncertainty supports."""

import pandas as pd
from contactid.latex import contact_fragment, escape, macros, significant_digits, tabular


def test_every_special_character_of_a_cell_prints_as_itself():
    assert escape("a_b & 50% $x$ #1 {y} ~z ^w \\") == (
        r"a\_b \& 50\% \$x\$ \#1 \{y\} \textasciitilde{}z \textasciicircum{}w \textbackslash{}"
    )
    table = tabular(pd.DataFrame({"name": ["k_t & k_n"], "v": [1.0]}), {"name": "", "v": "v"}, "c", "tab:x")
    assert r"k\_t \& k\_n & $1.00$ \\" in table


def test_digits_follow_the_interval_and_a_value_lost_in_it_prints_as_zero():
    # mu = 0.3957 in [0.3941, 0.3973]: half-width 0.0016 -> digits to 1e-4: 0.3957 (4 significant digits)
    assert significant_digits(0.3957015, 0.3940929, 0.3972648) == 4
    # e_f = 3.835e7 in [2.94e7, 5.85e7]: half-width 1.5e7 -> 2 digits
    assert significant_digits(3.834779e7, 2.939276e7, 5.849455e7) == 2
    # e_t = 1.4e-10 N/m in [0, 1.6e4]: indistinguishable from zero
    assert significant_digits(1.351915e-10, 0.0, 1.6e4) == 0
    df = pd.DataFrame(
        {
            "parameter": ["e_t", "mu", "e_f"],
            "identified": [1.351915e-10, 0.3957015, 3.834779e7],
            "interval_low": [0.0, 0.3940929, 2.939276e7],
            "interval_high": [1.6e4, 0.3972648, 5.849455e7],
        }
    )
    cols = {"parameter": "", "identified": "identified", "interval_low": "low", "interval_high": "high"}
    lines = tabular(df, cols, "c", "tab:t4", intervals={"identified": ("interval_low", "interval_high")}).splitlines()
    assert r"e\_t & $0$ & $0$ & $16000$ \\" in lines
    # the bounds to the value's last digit: 0.3957 in 0.3941-0.3973 (at 3 digits, 0.394-0.397, the interval read
    # as twice its width and off-centre), 3.8e7 in 2.9e7-5.8e7
    assert r"mu & $0.3957$ & $0.3941$ & $0.3973$ \\" in lines
    assert r"e\_f & $3.8\times10^{7}$ & $2.9\times10^{7}$ & $5.8\times10^{7}$ \\" in lines


def test_mode_numbers_print_whole_and_frequencies_to_the_hundredth():
    # Table 1 of the report: a row read as one float Series printed the modes as 1.00, 2.00; 3 significant digits
    # printed 166.9153 Hz as 167 beside the paper's 166.2
    df = pd.DataFrame({"mode": [1, 2], "identified_hz": [54.7918, 166.9153], "diff_pct": [-0.106113, 0.000257]})
    cols = {"mode": "mode", "identified_hz": "f (Hz)", "diff_pct": "diff"}
    lines = tabular(df, cols, "c", "tab:x", decimals={"identified_hz": 2}).splitlines()
    assert r"$1$ & $54.79$ & $-0.106$ \\" in lines
    assert r"$2$ & $166.92$ & $2.57\times10^{-4}$ \\" in lines


def test_a_plain_number_with_more_integer_digits_than_asked_is_rounded_to_them():
    # the model-form table's e_t interval bound 15875 N/m at 3 digits (it printed all five)
    from contactid.latex import latex_number

    assert latex_number(15875.000000002, 3) == "15900"
    assert latex_number(1968.9, 3) == "1970"
    assert latex_number(338.22, 3) == "338"
    assert latex_number(54.79, 4) == "54.79"
    assert latex_number(2.185776e5, 3) == r"2.19\times10^{5}"


def test_a_boolean_is_a_tex_switch_and_a_number_a_macro():
    text = macros({"rigtruth": False, "freq1": 54.8})
    assert "\\newif\\ifrigtruth\\rigtruthfalse" in text
    assert "\\newcommand{\\freqone}{\\ensuremath{54.80}}" in text
    assert "\\rigtruthtrue" in macros({"rigtruth": True})


def test_a_truth_column_without_any_value_is_left_out_and_one_with_values_kept():
    df = pd.DataFrame({"mode": [1, 2], "identified_hz": [54.8, 166.9], "truth_hz": [float("nan")] * 2})
    cols = {"mode": "mode", "identified_hz": "identified (Hz)", "truth_hz": "rig truth (Hz)"}
    assert "rig truth" not in tabular(df, cols, "c", "tab:x")
    df["truth_hz"] = [54.9, float("nan")]
    out = tabular(df, cols, "c", "tab:x")
    assert "rig truth" in out and "$54.9$" in out and "--" in out


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
    from contactid.latex import macros, report_values

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
    from contactid.latex import report_values

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
