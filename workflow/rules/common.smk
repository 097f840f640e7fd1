# Shared helpers: config checks and path functions, so that rules stay declarative.

from contactid.config import check_config

check_config(config)


def random_test_raw():
    """The random-test record: the rig's output or the user's measured file."""
    rt = config.get("random_test", {})
    if rt.get("source", "rig") == "measured":
        return rt["file"]
    return "data/raw/random_test.nc"


def random_test_truth():
    """Truth of the random test, only where the rig produced it."""
    if config.get("random_test", {}).get("source", "rig") == "measured":
        return []
    return "data/truth/random_test.nc"


def rig_outputs():
    """Every raw record the config asks the rig to produce."""
    out = []
    if config.get("random_test", {}).get("source", "rig") == "rig":
        out.append("data/raw/random_test.nc")
    return out


def all_outputs():
    return [
        "results/linear/linear_modes.nc",
        "results/tables/table1.csv",
        "results/tables/table3.csv",
        "results/tables/paper_consistency.csv",
        "results/figures/fig03_frf.png",
        "results/figures/fig03_frf.pdf",
        "results/summary.json",
    ]
