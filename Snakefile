# contactid: identification of frictional and normal contact forces at a
# micro-vibro-impacting joint (Pourahmadian, Ahmadian & Jalali, JSV 2012).
# The only Snakefile: it validates the config and includes the rule files.

import os
import sys

from snakemake.exceptions import WorkflowError
from snakemake.utils import min_version, validate

min_version("9.0")

# the jobs write Python's bytecode caches even where PYTHONDONTWRITEBYTECODE is set (containers often set it; the jobs
# inherit this process's environment): otherwise every job compiles again the package's sources and, since `make env`
# installs without compiling them, the libraries it imports (7 s a job where it had been 0.7 s)
os.environ.pop("PYTHONDONTWRITEBYTECODE", None)

# the package contactid lives in workflow/ (installed into .venv by `make env`; the
# rule files import it at parse time from the source tree as well)
sys.path.insert(0, os.path.join(workflow.basedir, "workflow"))


configfile: "config/config.yaml"


from contactid.config import duplicate_key_errors
from contactid.schema import numbers_written_as_text

# a key given twice in a config file (a second `lc2:`) is kept last by every YAML reader, silently: refused, with
# the file and lines (the config file and every --configfile merged over it)
_duplicates = [e for _path in workflow.configfiles for e in duplicate_key_errors(_path)]
if _duplicates:
    raise WorkflowError("config: duplicate keys:\n  - " + "\n  - ".join(_duplicates))

# 4e-05 is text to YAML 1.1 (4.0e-05 is a number): such values where the schema wants a number are read as numbers
for _key, _value in numbers_written_as_text(config, "workflow/schemas/config.schema.yaml"):
    print(
        f"config: {_key}: read as the number {_value!r} (YAML 1.1 reads exponent notation "
        "without a decimal point as text; 4.0e-05 is a number to every reader)",
        file=sys.stderr,
    )
validate(config, "workflow/schemas/config.schema.yaml")


from contactid import use_numba_cache_under
from contactid.io import package_digest

# every rule takes the package's code digest as a parameter: a changed contactid reruns what it computed
CODE_DIGEST = package_digest()

# numba's compiled kernels are cached per code digest in .snakemake/numba-cache/<digest>; the jobs inherit
# the directory (a SLURM job parses this file again in the same working directory): a new process loads the
# kernels instead of compiling them, and changed code never meets a kernel compiled from the old
use_numba_cache_under(os.path.join(".snakemake", "numba-cache"))


include: "workflow/rules/common.smk"
include: "workflow/rules/rig.smk"
include: "workflow/rules/import.smk"
include: "workflow/rules/linear.smk"
include: "workflow/rules/nonlinear.smk"
include: "workflow/rules/friction.smk"
include: "workflow/rules/outputs.smk"
include: "workflow/rules/report.smk"
include: "workflow/rules/gap.smk"
include: "workflow/rules/studies.smk"


rule all:
    """The default target: the paper's reproduction (Tables 1-4, Figs. 3-9), the gap diagnosis of the configured load cases and the PDF report."""
    input:
        all_outputs(),
    default_target: True
