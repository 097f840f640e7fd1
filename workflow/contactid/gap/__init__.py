"""Sim-to-real gap diagnosis (issue 7): the identified model (the "sim") against the records
(the "real"): where they disagree, which unmodelled effect explains it, how far the gap shrinks.

Modules: ``records`` (harmonics of the measured records, block-wise for the uncertainty),
``model`` (the identified model and its forward simulation under the measured force),
``candidates`` (the library of effects that can be added to the model), ``refit`` (the
calibration refit of a candidate), ``diagnosis`` (gap, localisation, ranking, verdict),
``benchmark`` (the blind check on rig data with a hidden effect).
"""
