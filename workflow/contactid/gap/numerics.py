"""The gap diagnosis's numerical settings: how a steady state is found and how a candidate's calibration search runs.

``Numerics`` is handed down explicitly, from the diagnosis's settings (``GapSettings.numerics``, built from the
config's ``gap`` block) through the candidates' workers, ``calibration.calibrate``, ``refit.evaluate`` / ``baseline``
and the searches, to ``simulation.simulate``. None of its fields changes what the diagnosis models; each trades time
against how closely the diagnosis follows its time-marching reference. Fields (the default first):

steady_state ("harmonic_balance"): how ``simulation.simulate`` finds a steady state where it is not given
    ``method``.
    "harmonic_balance" solves the periodic state directly (``rig.harmonic_balance``; within about 1e-3 of the
    integrator's orbit) and, where a simulation is polished, lets the integrator settle from it; "time_marching" (the
    reference, several times slower) integrates from the stuck linear system's state until the harmonics settle.
closed_contact_hb (True): an unpolished simulation (a calibration search's) of a contact that may open (a unilateral
    normal law) takes its periodic state where the contact stays closed all period long (N above a tenth of the
    preload); False: such a model is always marched from the linear state, as the reference does (slower, the
    same where the contact opens).
settling_tol (2e-5): the integrator's settling test where ``simulation.simulate`` is given no ``tol``: the relative
    change of the harmonics between 8-period chunks. Smaller: the reference's own scatter shrinks, at more periods per
    simulation (benchmarks/gap_diagnosis.py --reference-scatter halves and doubles it, --tight-tolerance sets it).
polish_searches (True, config ``gap.polish_searches``): every state a candidate's calibration search compares is
    polished by the integrator, so that the search sees the reference's gaps (held-out gaps within 0.01-0.08 % of
    the time-marching diagnosis's on benchmarks/gap_diagnosis.py's four data sets) for 25-90 % more diagnosis time;
    False compares the periodic states alone (faster; the searches stop elsewhere where the calibration gap is flat,
    held-out gaps 2.4-8.6 % apart). Either way the optimum itself is evaluated polished. The records' test of a model
    update (``evidence.records_test_of_update``) searches its drift with it False.
search ("residual"): a one-parameter candidate's search models the gap's residual vector by quadratics
    (``search.residual_line_search``) and a joint refit takes least-squares steps on it; "gap": the searches see the
    gap alone (Brent's bounded search, Nelder-Mead; the plain reference of the benchmarks, more simulations).
memo (True): the inverse identification and the friction refit are memoised (``refit.identified_forces``,
    ``refit.refit_friction``: pure results keyed by value); False computes them anew at every call (the plain
    baseline the benchmark times against). The results are the same either way.
"""

from __future__ import annotations

from dataclasses import dataclass

STEADY_STATES = ("harmonic_balance", "time_marching")
SEARCHES = ("residual", "gap")


@dataclass(frozen=True)
class Numerics:
    """How the gap diagnosis computes (see the module's docstring for each field and what it trades).

    Attributes
    ----------
    steady_state
        How ``simulation.simulate`` finds a steady state where it is not given ``method``: "harmonic_balance" or
        "time_marching" (``STEADY_STATES``).
    closed_contact_hb
        Whether an unpolished simulation of a contact that may open takes its periodic state where the contact stays
        closed all period long.
    settling_tol
        The integrator's settling test where ``simulation.simulate`` is given no ``tol``: the relative change of the
        harmonics between 8-period chunks [-], positive.
    polish_searches
        Whether every state a candidate's calibration search compares is polished by the integrator (config
        ``gap.polish_searches``).
    search
        How a candidate's search runs: "residual" (quadratic models of the gap's residual vector, least-squares
        steps) or "gap" (the gap alone: Brent's bounded search, Nelder-Mead) (``SEARCHES``).
    memo
        Whether the inverse identification and the friction refit are memoised.
    """

    steady_state: str = "harmonic_balance"
    closed_contact_hb: bool = True
    settling_tol: float = 2e-5
    polish_searches: bool = True
    search: str = "residual"
    memo: bool = True

    def __post_init__(self):
        """Check the fields: a known steady state and search, a positive settling tolerance.

        Raises
        ------
        ValueError
            When ``steady_state`` or ``search`` is not one of the known names, or ``settling_tol`` is not positive.
        """
        if self.steady_state not in STEADY_STATES:
            raise ValueError(f"Numerics.steady_state = {self.steady_state!r}; give one of {', '.join(STEADY_STATES)}")
        if self.search not in SEARCHES:
            raise ValueError(f"Numerics.search = {self.search!r}; give one of {', '.join(SEARCHES)}")
        if not self.settling_tol > 0:
            raise ValueError(f"Numerics.settling_tol = {self.settling_tol!r}; give a positive relative change")


DEFAULT = Numerics()
