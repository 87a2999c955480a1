"""As-built identification and the print loop: what printed units say about their print.

Layer 5, above :mod:`reflector_opt.calibration` (the data formats) and
:mod:`reflector_opt.tolerance` (whose deviation model is the prior); below
:mod:`reflector_opt.optimiser`.

* :mod:`~reflector_opt.asbuilt.parameters` — the as-built parameters, their priors and the
  unit a parameter vector describes;
* :mod:`~reflector_opt.asbuilt.problem` — the weighted residuals and their Jacobian;
* :mod:`~reflector_opt.asbuilt.spread` — the fast model with the resin's sub-surface spread;
* :mod:`~reflector_opt.asbuilt.uncertainty` — covariance, determined combinations, profiles;
* :mod:`~reflector_opt.asbuilt.model_form_terms` — physics the model lacks: its bias and signatures;
* :mod:`~reflector_opt.asbuilt.identification` — the MAP identification of a batch;
* :mod:`~reflector_opt.asbuilt.result` — its result, each unit as built;
* :mod:`~reflector_opt.asbuilt.asbuiltfile` — the ``AS_BUILT.json`` document;
* :mod:`~reflector_opt.asbuilt.identify_files` — identification from the lab's CSV files;
* :mod:`~reflector_opt.asbuilt.estimator` — angles through an identified unit's own model;
* :mod:`~reflector_opt.asbuilt.doe` — Bayesian D-optimal design on information blocks;
* :mod:`~reflector_opt.asbuilt.poses` — candidate poses and what each says of a unit;
* :mod:`~reflector_opt.asbuilt.patterns` — plan patterns compared by their information;
* :mod:`~reflector_opt.asbuilt.modelunit` — the simulated units a plan is checked on;
* :mod:`~reflector_opt.asbuilt.plancheck` — plans checked by identifying simulated units;
* :mod:`~reflector_opt.asbuilt.planstudy` — calibration plans chosen for identification;
* :mod:`~reflector_opt.asbuilt.batch` — the identified units of one print batch, gathered;
* :mod:`~reflector_opt.asbuilt.pooling` — the batch mean (systematic) and the scatter;
* :mod:`~reflector_opt.asbuilt.model_form_bias` — the identification's model-form bias, simulated;
* :mod:`~reflector_opt.asbuilt.correction` — the print correction and the corrected design;
* :mod:`~reflector_opt.asbuilt.batchforecast` — the next batch predicted with and without it;
* :mod:`~reflector_opt.asbuilt.printprocess` — a simulated print process (tests, benchmark).
"""

import lazy_loader

#: The modules that define the public names, and the names each gives; a module is
#: imported the first time one of its names is used.
_MODULES = {
    "problem": ("Curve",),
    "result": ("Identification",),
    "identification": ("identify",),
    "asbuiltfile": ("load_as_built",),
    "printprocess": ("PrintProcess",),
    "correction": ("corrected_design", "plan_correction"),
    "batch": ("load_batch",),
    "pooling": ("pool",),
    "batchforecast": ("predict_next_batch",),
}

__getattr__, __dir__, __all__ = lazy_loader.attach(__name__, submod_attrs=_MODULES)
