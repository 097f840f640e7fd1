"""The report's LaTeX fragments: text cells escaped, numbers with the digits their uncertainty supports."""

import pandas as pd

from contactid.latex import escape, significant_digits, tabular


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
    assert r"mu & $0.3957$ & $0.394$ & $0.397$ \\" in lines
    assert r"e\_f & $3.8\times10^{7}$ & $2.94\times10^{7}$ & $5.85\times10^{7}$ \\" in lines


def test_a_plain_number_with_more_integer_digits_than_asked_is_rounded_to_them():
    # the model-form table's e_t interval bound 15875 N/m at 3 digits (it printed all five)
    from contactid.latex import _fmt

    assert _fmt(15875.000000002, 3) == "15900"
    assert _fmt(1968.9, 3) == "1970"
    assert _fmt(338.22, 3) == "338"
    assert _fmt(54.79, 4) == "54.79"
    assert _fmt(2.185776e5, 3) == r"2.19\times10^{5}"
