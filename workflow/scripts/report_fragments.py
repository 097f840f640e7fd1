"""Rule report_fragments: LaTeX macros and tables from the results (no number typed by hand)."""

import json
from pathlib import Path

import pandas as pd
from contactid.gap.report import explained_law_note, updated_law_note
from contactid.latex import macros, tabular
from contactid.logs import setup_logging
from contactid.report_text import (
    contact_fragment,
    data_checks_text,
    records_alert_text,
    report_values,
    setup_table,
)

setup_logging(snakemake.log[0])


inp, out = snakemake.input, snakemake.output
summary = json.loads(Path(inp.summary).read_text())
cons = pd.read_csv(inp.consistency)
Path(out.numbers).write_text(
    macros(report_values(summary, cons, snakemake.params.calibration_case, snakemake.params.figure_case))
)
Path(out.setup).write_text(setup_table(snakemake.params.structure))
Path(out.datachecks).write_text(data_checks_text(summary))
Path(out.alerts).write_text(records_alert_text(summary))
Path(out.table1).write_text(
    tabular(
        pd.read_csv(inp.table1),
        {
            "mode": "mode",
            "identified_hz": "identified (Hz)",
            "paper_hz": "paper (Hz)",
            "truth_hz": "rig truth (Hz)",
            "diff_vs_paper_pct": "vs paper (\\%)",
            "diff_vs_truth_pct": "vs truth (\\%)",
            "damping_ratio": "damping",
        },
        "Natural frequencies at low-level random excitation (paper, Table 1).",
        "tab:t1",
        decimals={"identified_hz": 2, "paper_hz": 2, "truth_hz": 2},
    )
)
Path(out.table3).write_text(
    tabular(
        pd.read_csv(inp.table3),
        {
            "parameter": "",
            "identified_n_per_m": "identified (N/m)",
            "interval_low_n_per_m": "interval low",
            "interval_high_n_per_m": "interval high",
            "reported_as": "reported as",
            "paper_n_per_m": "paper",
            "truth_n_per_m": "rig truth",
        },
        "Contact stiffness at stiction (paper, Table 3).",
        "tab:t3",
        intervals={"identified_n_per_m": ("interval_low_n_per_m", "interval_high_n_per_m")},
    )
)
Path(out.table4).write_text(
    tabular(
        pd.read_csv(inp.table4),
        {
            "parameter": "",
            "identified": "identified",
            "interval_low": "interval low",
            "interval_high": "interval high",
            "reported_as": "reported as",
            "paper_value": "paper",
            "truth": "rig truth",
        },
        "Friction-law parameters (paper, Table 4): working method with profile-likelihood intervals."
        + updated_law_note(json.loads(Path(inp.intervals).read_text()))
        + explained_law_note(json.loads(Path(inp.updated_model).read_text())),
        "tab:t4",
        intervals={"identified": ("interval_low", "interval_high")},
    )
)
Path(out.consistency).write_text(
    tabular(
        cons,
        {
            "scenario": "",
            "assumption": "assumption",
            "k_t_n_per_m": "$k_t$ (N/m)",
            "tangential_lever_arm_m": "$a$ (m)",
            "youngs_modulus_pa": "$E$ (Pa)",
            "max_abs_err_pct": "max err (\\%)",
        },
        "Table 1 against Tables 3 and 4 under candidate assumptions.",
        "tab:cons",
    ).replace("\\small", "\\scriptsize")
)
rows = []
for case, w in summary.get("contact_forces", {}).items():
    p = summary["contact_forces_paper"][case]
    rows.append(
        {
            "case": case,
            **{f"w_{q}": 100 * w.get(f"{q}_nrmse", float("nan")) for q in ("S", "N", "xi", "eta")},
            **{f"p_{q}": 100 * p.get(f"{q}_nrmse", float("nan")) for q in ("S", "N", "xi", "eta")},
        }
    )
Path(out.contact).write_text(contact_fragment(pd.DataFrame(rows)))
