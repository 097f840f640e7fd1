"""Benchmark: the inverse identification, the stiffness fit's frequency map and the random test's FRF (issue 14: a
compound benchmark item calls the first about 300 times, the second 7-9 thousand times, the third five times on
the random test's 655360 samples).

Each package function is timed beside the plain version it replaced, run in the same process on the same input, and
the two results are compared (the change is one of speed only):
- ``identification.inverse_harmonics``: its nonlinear term on 4K points with the real FFT, against 8K points with the
  complex FFT (the harmonics must agree within 1e-12 of their norm);
- ``beam_modes.ContactFrequencyMap`` on a structure whose Ritz basis the Cholesky factor of V^T M V could not make
  (transducer masses 7.5 % heavy), against the full eigenproblem it then fell back to (within 1e-8);
- ``signals.h1_frf`` on a random-test-sized record (a force and three responses), from each channel's segment spectra
  computed once, against scipy.signal.welch and csd per response as it was computed before (H1 and coherence within
  1e-11).

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
from contactid.beam_model import assemble  # noqa: E402
from contactid.beam_modes import ContactFrequencyMap, all_modes  # noqa: E402
from contactid.identification import inverse_harmonics  # noqa: E402
from contactid.modal_damping import modal_damping_vector  # noqa: E402
from contactid.signals import h1_frf  # noqa: E402
from structures import (  # noqa: E402
    configured_structure,
    dual_sine_harmonics,
    mass_candidate_structure,
    welch_csd_frf,
)


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


def frf_comparison() -> None:
    """h1_frf against welch and csd on 128 s at 5120 Hz, segments of 65536 samples (the default config's)."""
    rng = np.random.default_rng(7)
    force = rng.standard_normal(655360)
    responses = np.array([np.convolve(force, rng.standard_normal(40), "same") for _ in range(3)])
    responses += 0.05 * rng.standard_normal(responses.shape)
    now = h1_frf(force, responses, 5120.0, 65536)
    plain = welch_csd_frf(force, responses, 5120.0, 65536)
    t_now = best_of(lambda: h1_frf(force, responses, 5120.0, 65536), repeat=3, number=3)
    t_plain = best_of(lambda: welch_csd_frf(force, responses, 5120.0, 65536), repeat=3, number=3)
    dev = max(
        np.max(np.abs(now.h1[:, 1:] / plain[1][:, 1:] - 1)), np.max(np.abs(now.coherence[:, 1:] - plain[2][:, 1:]))
    )
    print(
        f"h1_frf on 655360 samples, 4 channels: {t_now * 1e3:.0f} ms now, {t_plain * 1e3:.0f} ms plain (welch + csd "
        f"per response): x{t_plain / t_now:.1f}; H1 and coherence within {dev:.1e} "
        f"(goal 1e-11: {'met' if dev <= 1e-11 else 'NOT met'})"
    )


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
    frf_comparison()


if __name__ == "__main__":
    main()
