"""The virtual rig: the simulated test bench whose raw records the identification chain reads.

``structure`` holds the rig's true structure and contact springs; ``damping`` its true damping's form over the modes;
``effects`` the switchable unmodelled effects; ``random_test`` the low-level random test (the linear part);
``nonlinear`` the reduced model, the contact laws and the bounds on the step and memory; ``simulator`` the dual-sine
time integration and ``integrator`` its numba kernels; ``harmonic_balance`` the periodic steady state by harmonic
balance, ``periodic_path`` the contact laws' kernels along its path and ``periodic_response`` its result; ``control``
the tuning of the dual-sine force amplitudes to the target response; ``dual_sine`` one response-controlled dual-sine
test, raw record and truth; ``frontend`` the acquisition front end (channel delays, anti-alias filtering and decimation,
sensor noise); and ``checks`` the checks on the rig itself (convergence, agreement with the linear FRF, each effect's
change).
"""
