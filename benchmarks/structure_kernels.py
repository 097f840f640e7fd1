"""Benchmark: the structure's assembly and the random test's modal sum (issue 14: every benchmark item and the
model updating build a few hundred structures; every item simulates a 130 s random test).

Each package function is timed beside the plain version it replaced, run in the same process on the same input, and
the two results are compared bit for bit (they must be equal: the change is one of speed only):
- the beam elements' stiffness, mass and shortening matrices scattered by one np.add.at call against the
  element-by-element loop over the 16 entries of each element;
- the random test's accelerations in one numba pass over the record against scipy.signal.lfilter per mode and a
  multiply-add per channel.

Usage: .venv/bin/python benchmarks/structure_kernels.py
"""

import os
import sys
import time
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np
import scipy.signal

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "workflow"))
sys.path.insert(0, str(ROOT / "tests"))

from contactid.beam_model import _element_matrices, assemble, shortening_matrix  # noqa: E402
from contactid.rig.random_test import modal_acceleration_filters, modal_acceleration_sum  # noqa: E402
from structures import configured_structure  # noqa: E402


def scalar_element_matrices(EI, rhoA, le):
    """One element's stiffness and mass matrices as the package built them before (scalar, np.array)."""
    k = (
        EI
        / le**3
        * np.array(
            [
                [12, 6 * le, -12, 6 * le],
                [6 * le, 4 * le**2, -6 * le, 2 * le**2],
                [-12, -6 * le, 12, -6 * le],
                [6 * le, 2 * le**2, -6 * le, 4 * le**2],
            ]
        )
    )
    m = (
        rhoA
        * le
        / 420.0
        * np.array(
            [
                [156, 22 * le, 54, -13 * le],
                [22 * le, 4 * le**2, 13 * le, -3 * le**2],
                [54, 13 * le, 156, -22 * le],
                [-13 * le, -3 * le**2, -22 * le, 4 * le**2],
            ]
        )
    )
    return k, m


def scalar_element_shortening(le):
    """One element's shortening matrix as the package built it before."""
    return (
        1.0
        / (30.0 * le)
        * np.array(
            [
                [36, 3 * le, -36, 3 * le],
                [3 * le, 4 * le**2, -3 * le, -(le**2)],
                [-36, -3 * le, 36, -3 * le],
                [3 * le, -(le**2), -3 * le, 4 * le**2],
            ]
        )
    )


def loop_element_matrices(m, p):
    """The elements' part of K and M by the element loop (the package before the scatter)."""
    K, M = np.zeros_like(m.stiffness), np.zeros_like(m.mass)
    for e in range(m.nodes.size - 1):
        ke, me = scalar_element_matrices(p.bending_stiffness, p.mass_per_length, m.nodes[e + 1] - m.nodes[e])
        dofs = [m.w_dof[e], m.theta_dof[e], m.w_dof[e + 1], m.theta_dof[e + 1]]
        for a, da in enumerate(dofs):
            if da < 0:
                continue
            for b, db in enumerate(dofs):
                if db < 0:
                    continue
                K[da, db] += ke[a, b]
                M[da, db] += me[a, b]
    return K, M


def loop_shortening(m):
    """G by the element loop (the package before the scatter)."""
    G = np.zeros((m.n_dof, m.n_dof))
    for e in range(m.nodes.size - 1):
        ge = scalar_element_shortening(m.nodes[e + 1] - m.nodes[e])
        dofs = [m.w_dof[e], m.theta_dof[e], m.w_dof[e + 1], m.theta_dof[e + 1]]
        for a, da in enumerate(dofs):
            for b, db in enumerate(dofs):
                if da >= 0 and db >= 0:
                    G[da, db] += ge[a, b]
    return G * m.params.shortening_scale


def lfilter_modal_sum(f, filters, sens):
    """The random test's accelerations by lfilter per mode (the package before the numba pass)."""
    acc = np.zeros((sens.shape[0], f.size))
    term = np.empty(f.size)
    for (num, den), part in zip(filters, sens.T):
        qdd = scipy.signal.lfilter(num, den, f)
        for channel, weight in enumerate(part):
            np.multiply(qdd, weight, out=term)
            acc[channel] += term
    return acc


def timed(fn, reps):
    t0 = time.perf_counter()
    for _ in range(reps):
        out = fn()
    return (time.perf_counter() - t0) / reps, out


def row(name, plain, fast, equal, unit="ms", scale=1e3):
    print(
        f"{name:46s} plain {plain * scale:8.2f} {unit}   package {fast * scale:8.2f} {unit}   x{plain / fast:5.1f}   "
        f"bit-identical: {equal}"
    )


def main():
    p = configured_structure()
    m = assemble(p)
    t_asm, _ = timed(lambda: assemble(p), 200)
    t_loop, (K, M) = timed(lambda: loop_element_matrices(m, p), 200)
    t_elements, (K1, M1) = timed(lambda: _scatter_elements(m, p), 200)
    print(f"structure: {m.n_dof} dofs, {m.nodes.size - 1} elements")
    equal = bool(np.array_equal(K, K1) and np.array_equal(M, M1))
    row("beam elements' K and M (loop -> np.add.at)", t_loop, t_elements, equal)
    print(f"{'':46s} (the whole assemble now {t_asm * 1e3:.2f} ms)")
    t_gl, G0 = timed(lambda: loop_shortening(m), 200)
    t_gs, G1 = timed(lambda: shortening_matrix(m), 200)
    row("shortening matrix G (loop -> np.add.at)", t_gl, t_gs, bool(np.array_equal(G0, G1)))
    filters, sens = modal_acceleration_filters(m, 0.005, 1.0 / 20480.0)
    n = int(130 * 20480)  # the default random test: 128 s recorded + 2 s settling, at 4 x 5120 Hz
    f = scipy.signal.sosfilt(
        scipy.signal.butter(8, [5, 1000], "bandpass", fs=20480, output="sos"),
        np.random.default_rng(1).standard_normal(n),
    )
    modal_acceleration_sum(f[:1000], filters, sens)  # compile (or load from the cache)
    t_lf, a0 = timed(lambda: lfilter_modal_sum(f, filters, sens), 3)
    t_nb, a1 = timed(lambda: modal_acceleration_sum(f, filters, sens), 3)
    row(
        f"random test's modal sum ({len(filters)} modes, {n} samples)", t_lf, t_nb, bool(np.array_equal(a0, a1)), "s", 1
    )


def _scatter_elements(m, p):
    from contactid.beam_model import _element_scatter

    K, M = np.zeros_like(m.stiffness), np.zeros_like(m.mass)
    rows, cols, sel = _element_scatter(m.w_dof, m.theta_dof)
    ke, me = _element_matrices(p.bending_stiffness, p.mass_per_length, np.diff(m.nodes))
    np.add.at(K, (rows, cols), ke.reshape(-1)[sel])
    np.add.at(M, (rows, cols), me.reshape(-1)[sel])
    return K, M


if __name__ == "__main__":
    main()
