"""Study: how the number of Fourier harmonics K kept in S(t), xi(t), N(t) biases the fitted
friction parameters (issue 5). Reads the default workflow's results/lc1/contact_forces.nc and
the rig truth from config/config.yaml; run the workflow first.

Usage: .venv/bin/python benchmarks/friction_harmonics.py
"""

import sys
from pathlib import Path

import xarray as xr
import yaml

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "workflow"))

from contactid.contact_laws import stiction_shear_stiffness  # noqa: E402
from contactid.friction_fit import FitSettings, fit_friction_law  # noqa: E402
from contactid.harmonics import fourier_series  # noqa: E402


def main():
    cfg = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())
    tr = cfg["rig"]["truth"]["friction"]
    truth = {
        "mu": tr["mu"],
        "kappa": tr["kappa"],
        "e0": stiction_shear_stiffness(cfg["structure"]["preload_n"], tr["e_f_n_per_m"], tr["k_c_per_m"]),
    }
    d = xr.load_dataset(ROOT / "results" / "lc1" / "contact_forces.nc", engine="netcdf4")
    fs = 1.0 / float(d["time"].values[1] - d["time"].values[0])
    f0 = d.attrs["excitation_frequency_hz"]
    print(" K   mu err %   kappa err %   e0 err %   misfit")
    for K in (5, 10, 15, 20, 25):
        c = [fourier_series(d[v].values, fs, f0, K)[0] for v in ("xi", "N_dyn", "S")]
        r = fit_friction_law(*c, f0, cfg["structure"]["preload_n"], FitSettings(), cfg["seed"], K)
        print(
            f"{K:2d}   {100 * (r.params[4] / truth['mu'] - 1):+7.2f}   {100 * (r.params[3] / truth['kappa'] - 1):+9.2f}"
            f"   {100 * (r.e0_at_preload / truth['e0'] - 1):+8.2f}   {r.misfit:.4f}"
        )


if __name__ == "__main__":
    main()
