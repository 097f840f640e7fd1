"""Numba's kernels compiled ahead of the workflow (``make env`` runs ``python -m contactid compile-kernels``).

Every kernel is ``@njit(cache=True)`` and cached per code digest (``contactid.NUMBA_CACHE_DIR``); without this
step the workflow's first jobs compile them (about 28 s of CPU, 10-13 s of the first run's wall time on two
cores). ``compile_kernels`` calls each kernel that Python code calls, through the functions the workflow uses, on
a problem a few steps long, so that numba compiles (or loads) the signatures the jobs use: float64 C arrays,
floats, ints and flags, whatever the configured values. tests/workflow/test_compile_kernels.py checks that the
signatures the acceptance run (the default target) compiles are among them.
"""

import dataclasses
from collections.abc import Iterable, Mapping

import numpy as np


def _structure_and_rig(config: Mapping) -> tuple[dict, dict]:
    from .schema import with_defaults

    filled = with_defaults(config)
    return filled["structure"], filled["rig"]


def _simulator(structure: Mapping, rig: Mapping):
    """Return the rig's dual-sine simulator of ``structure`` and ``rig`` and its excitation frequency (rad/s)."""
    from .rig.dual_sine import build_simulator, dual_sine_settings

    settings = dual_sine_settings(rig, {}, 5120.0)
    return build_simulator(structure, rig, settings), 2 * np.pi * float(settings["excitation_frequency_hz"])


def _rig_kernels(structure: Mapping, rig: Mapping) -> None:
    """Compile the rig's time integrator (``integrate`` and its callees) and its random test's modal filter."""
    from .beam_model import assemble
    from .rig.random_test import modal_acceleration_filters, modal_acceleration_sum
    from .rig.structure import rig_structure

    sim, w = _simulator(structure, rig)
    sim.start_from_linear(1.0, 0.2, w)
    sim.run(1.0, 0.2, w, 64, store_from=32)
    model = assemble(rig_structure(structure, rig))
    filters, sens = modal_acceleration_filters(model, lambda f: np.full(np.shape(f), 0.005), 1.0 / 20480.0)
    modal_acceleration_sum(np.linspace(0.0, 1.0, 64), filters, sens)


def _harmonic_balance_kernels(structure: Mapping, rig: Mapping) -> None:
    """Compile harmonic balance's contact paths and tangents (the gap diagnosis and the friction intervals)."""
    from .rig.harmonic_balance import HarmonicBalance
    from .rig.simulator import force_coefficients

    sim, w = _simulator(structure, rig)
    for contact in (sim.contact, dataclasses.replace(sim.contact, iwan_share=0.3)):  # with Iwan's sliders
        hb = HarmonicBalance(sim.red, contact, sim.zeta, w, 3, 16)
        hb.solve(force_coefficients(1.0, 0.2), max_iter=1)
        HarmonicBalance.forget()


def _friction_kernels() -> None:
    """Compile the friction law over a population (the fit), the gap's Iwan-augmented law, and Eq. 22 on arrays."""
    from .contact_laws import stiction_shear_stiffness
    from .gap.model import Augmentation
    from .gap.refit import law_friction_force

    t = np.linspace(0.0, 1.0, 64, endpoint=False)
    xi = 1e-6 * np.sin(2 * np.pi * t)
    N = 70.0 + 10.0 * np.cos(2 * np.pi * t)
    params = np.array([3.857e7, 2.547e5, 1.0e4, 0.284, 0.397])
    law_friction_force(xi, np.gradient(xi), N, params, Augmentation(iwan_share=0.3), "none")
    stiction_shear_stiffness(N, 3.857e7, 2.547e5)
    stiction_shear_stiffness(70.0, 3.857e7, 2.547e5)


def _contact_kernels(structure: Mapping, rig: Mapping) -> None:
    _harmonic_balance_kernels(structure, rig)
    _friction_kernels()


# the groups share only the friction law's small callees: ``make env`` compiles them on two processes
KERNEL_GROUPS = {"rig": _rig_kernels, "contact": _contact_kernels}


def compile_kernels(config: Mapping, groups: Iterable[str] | None = None) -> None:
    """Compile (or load from numba's cache) every kernel the workflow's jobs call.

    The kernels are called on a problem a few steps long built from the structure and rig of ``config``, so that
    numba compiles the signatures the jobs use.

    Parameters
    ----------
    config
        A config as the Snakefile reads it (the whole config file); its ``structure`` and ``rig`` blocks are read,
        the schema's defaults filling what it leaves out.
    groups
        Names of ``KERNEL_GROUPS`` ("rig", "contact") to compile; None for all of them.
    """
    structure, rig = _structure_and_rig(config)
    for name in groups or KERNEL_GROUPS:
        KERNEL_GROUPS[name](structure, rig)
