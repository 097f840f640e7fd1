"""Sim-to-real gap diagnosis: the identified model (the "sim") against the records (the "real").

Where they disagree, which unmodelled effect explains it, how far the gap shrinks, and what the records cannot tell.

Modules, by role:
- settings and the run: ``settings`` (GapSettings, read once from the config), ``diagnosis`` (the Diagnosis and
  ``diagnose``, which calls the rest in order),
  ``numerics`` (Numerics: how the steady states are found and the searches run, handed down the calls);
- records and evidence: ``records`` (the records' harmonics, block-wise for the uncertainty), ``record_checks`` (units,
  signs, channel order), ``localise`` (where the gap lies: stages, sensors, harmonics, cycle parts), ``evidence``
  (held-out gaps, bootstrap, the records' tests of an update), ``isolability`` (which candidates the records cannot
  tell apart), ``uncertainty`` (the friction law's intervals with a model-form term);
- model, candidates and searches: ``model`` (the identified model and its augmentations), ``simulation`` (its
  steady-state simulation under the measured force), ``candidates`` (the library of effects), ``refit`` (the chain
  redone with an effect in the model, and the gap), ``calibration`` and ``search`` (a candidate's calibration
  searches), ``workers`` (the candidates' refits in worker processes), ``ranking`` (the first pass's rows),
  ``pipeline`` (the identified model and the records a diagnosis starts from: the chain run in one process, or the
  workflow's files), ``base_model`` (the structure updated from the random test before the candidates, the friction
  law refitted), ``damping`` (the damping at test level, in the form the held-out records choose);
- decisions: ``place`` (where the gap lies, where an effect acts), ``verdict`` (whether a step or a model update
  explains the gap), ``explain`` (the additive explanation and the model it arrives at), ``story`` (the verdict told
  from the explanation, with its trace), ``story_decisions`` (the decisions of the trace, and the resolution);
- outputs: ``output`` (diagnosis.json, gap.nc), ``figures``, ``report`` (the report's section: its assembly, the
  candidates' table, the friction law's notes), ``report_diagnosis`` (the diagnosis in words), ``report_base_model``
  (the base model's update in words), ``report_benchmark`` (the benchmarks' paragraphs), ``report_format`` (their
  shared number formatting);
- evaluation, the only part that builds records with the rig: ``bench_items`` (what the blind, compound and ladder
  items are), ``benchmark`` (running an item: its rig records, diagnosis and result row), ``bench_scores`` (the
  items' scores), ``floor`` (the identification's own floor).
"""
