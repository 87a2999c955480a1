"""As-built identification and the print loop: what printed units say about their print.

Layer 5, above :mod:`reflector_opt.calibration` (the data formats) and
:mod:`reflector_opt.tolerance` (whose deviation model is the prior); below
:mod:`reflector_opt.optimiser`.

* :mod:`~reflector_opt.asbuilt._parameters` — the as-built parameters, their priors and the
  unit a parameter vector describes;
* :mod:`~reflector_opt.asbuilt._problem` — the weighted residuals and their Jacobian;
* :mod:`~reflector_opt.asbuilt._spread` — the fast model with the resin's sub-surface spread;
* :mod:`~reflector_opt.asbuilt._uncertainty` — covariance, determined combinations, profiles;
* :mod:`~reflector_opt.asbuilt._model_form_terms` — physics the model lacks: its bias and
  signatures;
* :mod:`~reflector_opt.asbuilt._identification` — the MAP identification of a batch;
* :mod:`~reflector_opt.asbuilt._result` — its result, each unit as built;
* :mod:`~reflector_opt.asbuilt._asbuiltfile` — the ``AS_BUILT.json`` document;
* :mod:`~reflector_opt.asbuilt._identify_files` — identification from the lab's CSV files;
* :mod:`~reflector_opt.asbuilt._estimator` — angles through an identified unit's own model;
* :mod:`~reflector_opt.asbuilt._doe` — Bayesian D-optimal design on information blocks;
* :mod:`~reflector_opt.asbuilt._poses` — candidate poses and what each says of a unit;
* :mod:`~reflector_opt.asbuilt._patterns` — plan patterns compared by their information;
* :mod:`~reflector_opt.asbuilt._modelunit` — the simulated units a plan is checked on;
* :mod:`~reflector_opt.asbuilt._plancheck` — plans checked by identifying simulated units;
* :mod:`~reflector_opt.asbuilt._planstudy` — calibration plans chosen for identification;
* :mod:`~reflector_opt.asbuilt._batch` — the identified units of one print batch, gathered;
* :mod:`~reflector_opt.asbuilt._pooling` — the batch mean (systematic) and the scatter;
* :mod:`~reflector_opt.asbuilt._model_form_bias` — the identification's model-form bias, simulated;
* :mod:`~reflector_opt.asbuilt._correction` — the print correction and the corrected design;
* :mod:`~reflector_opt.asbuilt._batchforecast` — the next batch predicted with and without it;
* :mod:`~reflector_opt.asbuilt._printprocess` — a simulated print process (tests, benchmark).
"""

import lazy_loader

#: The modules that define the public names, and the names each gives; a module is
#: imported the first time one of its names is used.
_MODULES = {
    "_problem": ("Curve",),
    "_result": ("Identification",),
    "_identification": ("identify",),
    "_asbuiltfile": ("load_as_built",),
    "_printprocess": ("PrintProcess",),
    "_correction": ("corrected_design", "plan_correction"),
    "_batch": ("load_batch",),
    "_pooling": ("pool",),
    "_batchforecast": ("predict_next_batch",),
}

__getattr__, __dir__, __all__ = lazy_loader.attach(__name__, submod_attrs=_MODULES)
