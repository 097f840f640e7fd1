"""Rule report: build the LaTeX report with latexmk; a clear message if TeX is missing."""

import logging
import shutil
import subprocess
import tempfile
from pathlib import Path

from contactid.logs import setup_logging

log = setup_logging(snakemake.log[0])
latexmk_log = logging.getLogger("latexmk")  # its output goes to the log file, not the console
if shutil.which("latexmk") is None or shutil.which("pdflatex") is None:
    raise SystemExit(
        "TeX Live is missing, so the report cannot be built (everything else is). Install it with "
        "`make env` or `apt-get install texlive-latex-base texlive-latex-recommended "
        "texlive-latex-extra latexmk`, then rerun snakemake."
    )
out = Path(snakemake.output.pdf)
dirs = {
    Path(f).resolve().parent
    for f in [snakemake.input.figures[0], *snakemake.input.gap_figures, *snakemake.input.benchmark_figure]
}
graphicspath = "".join(f"{{{d}/}}" for d in sorted(dirs))
with tempfile.TemporaryDirectory(dir=out.parent) as build:
    build = Path(build)
    shutil.copy(snakemake.input.tex, build / "report.tex")
    for frag in [*snakemake.input.fragments, snakemake.input.gap, snakemake.input.noise]:
        shutil.copy(frag, build / Path(frag).name)
    tex = (build / "report.tex").read_text()
    (build / "report.tex").write_text(
        tex.replace("\\begin{document}", f"\\graphicspath{{{graphicspath}}}\n\\begin{{document}}", 1)
    )
    res = subprocess.run(
        ["latexmk", "-pdf", "-interaction=nonstopmode", "-halt-on-error", "report.tex"],
        cwd=build,
        capture_output=True,
        text=True,
    )
    latexmk_log.info("%s", res.stdout[-5000:])
    if res.returncode:
        raise SystemExit(f"latexmk failed (see {snakemake.log[0]}):\n{res.stdout[-3000:]}")
    shutil.move(build / "report.pdf", out)
