"""The report's LaTeX fragments: text cells escaped, numbers with the digits their uncertainty supports."""

import pandas as pd
from contactid.latex import escape, macros, significant_digits, tabular


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
