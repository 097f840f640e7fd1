"""Benchmark: the inverse identification and the stiffness fit's frequency map (issue 14: a compound benchmark item
calls the one about 300 times and the other 7-9 thousand times).

Each package function is timed beside the plain version it replaced, run in the same process on the same input, and
the two results are compared (the change is one of speed only):
- ``identification.inverse_harmonics``: its nonlinear term on 4K points with the real FFT, against 8K points with the
  complex FFT (the harmonics must agree within 1e-12 of their norm);
- ``beam_model.ContactFrequencyMap`` on a structure whose Ritz basis the Cholesky factor of V^T M V could not make
  (transducer masses 7.5 % heavy), against the full eigenproblem it then fell back to (within 1e-8).

Usage: .venv/bin/python benchmarks/identification_kernels.py
"""

import os
import sys
import time
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "workflow"))
sys.path.insert(0, str(ROOT / "tests"))

import contactid.identification as ident  # noqa: E402
from contactid.beam_model import ContactFrequencyMap, all_modes, assemble  # noqa: E402
from contactid.identification import inverse_harmonics, modal_damping_vector  # noqa: E402
from structures import configured_structure, dual_sine_harmonics, mass_candidate_structure  # noqa: E402


def best_of(f, repeat=5, number=20) -> float:
    """The fastest of ``repeat`` runs of ``number`` calls, per call (s)."""
    out = []
    for _ in range(repeat):
        t = time.perf_counter()
        for _ in range(number):
            f()
        out.append((time.perf_counter() - t) / number)
    return min(out)


def complex_fft_spectrum(x, H):
    """The bins 1..H by the complex FFT, as period_coefficients computed them before."""
    return np.fft.fft(x, axis=-1)[..., 1 : H + 1]


def main() -> None:
    # the inverse identification on the configured structure, a dual-sine-like record's 25 harmonics
    p = configured_structure()
    model = assemble(p)
    all_modes(model)
    zeta = modal_damping_vector(model, np.array([0.004, 0.003, 0.002]))
    f0 = 54.38
    F, A = dual_sine_harmonics(1)
    now = inverse_harmonics(model, zeta, F, A, f0)
    t_now = best_of(lambda: inverse_harmonics(model, zeta, F, A, f0))
    real_fft, ident.positive_spectrum = ident.positive_spectrum, complex_fft_spectrum
    try:
        plain = inverse_harmonics(model, zeta, F, A, f0, grid_factor=8)
        t_plain = best_of(lambda: inverse_harmonics(model, zeta, F, A, f0, grid_factor=8))
    finally:
        ident.positive_spectrum = real_fft
    dev = max(
        np.linalg.norm(getattr(now, k) - getattr(plain, k)) / np.linalg.norm(getattr(plain, k))
        for k in ("S", "N_dyn", "xi", "eta", "xi_dot", "q")
    )
    print(
        f"inverse_harmonics: {t_now * 1e3:.2f} ms now, {t_plain * 1e3:.2f} ms plain (8K points, complex FFT): "
        f"x{t_plain / t_now:.2f}; results within {dev:.1e} (goal 1e-12: {'met' if dev <= 1e-12 else 'NOT met'})"
    )
    # the map on a mass candidate's structure: the Ritz basis kept, against the full eigenproblem (over the fit's box)
    grid = [(kt, kn) for kt in np.logspace(5, 9, 5) for kn in np.logspace(5, 11, 5)]
    q = mass_candidate_structure()
    ritz = ContactFrequencyMap(q, 3)
    full = ContactFrequencyMap(q, 3)
    full._basis = None  # what the map did on this structure before: the full eigenproblem at every call
    dev = max(np.max(np.abs(ritz(kt, kn) / full(kt, kn) - 1)) for kt, kn in grid)
    t_now = best_of(lambda: ritz(1.49e7, 2.37e7), number=500)
    t_plain = best_of(lambda: full(1.49e7, 2.37e7), number=100)
    print(
        f"ContactFrequencyMap on a mass candidate's structure: {t_now * 1e6:.0f} us with the Ritz basis, "
        f"{t_plain * 1e6:.0f} us with the full eigenproblem: x{t_plain / t_now:.1f}; frequencies within {dev:.1e} "
        f"(goal 1e-8: {'met' if dev <= 1e-8 else 'NOT met'})"
    )


if __name__ == "__main__":
    main()
