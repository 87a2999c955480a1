"""Calibration: the paper's Eq 5 and Eq 6 and polynomial forms, their fits, file formats,
the simulated protocol, the multi-unit segment and the lab workflow.

Layer 4: imports :mod:`reflector_opt.model`, :mod:`reflector_opt.design`,
:mod:`reflector_opt.analysis` and :mod:`reflector_opt.util`.

* :mod:`~reflector_opt.calibration._models` — the calibration models (scikit-learn style);
* :mod:`~reflector_opt.calibration._terms` — their polynomial terms and change of variable;
* :mod:`~reflector_opt.calibration._fitting` — least squares, Huber and minimax fits;
* :mod:`~reflector_opt.calibration._choices` — the names of those fits, for the command line;
* :mod:`~reflector_opt.calibration._coefficients` — one fitted model as a JSON file;
* :mod:`~reflector_opt.calibration._validation` — k-fold cross-validation;
* :mod:`~reflector_opt.calibration._files` — calibration data and voltage log CSV files;
* :mod:`~reflector_opt.calibration._simulation` — the paper's protocol on the forward model;
* :mod:`~reflector_opt.calibration._segment` — a segment of units, Table-I-style errors;
* :mod:`~reflector_opt.calibration._unit_calibration` — calibrate printed units from measured data;
* :mod:`~reflector_opt.calibration._synthetic` — synthetic lab data for examples and tests;
* :mod:`~reflector_opt.calibration._selection` — form and order chosen by cross-validation;
* :mod:`~reflector_opt.calibration._physical` — a few forward-model parameters fitted per unit,
  inverted per sample;
* :mod:`~reflector_opt.calibration._plans` — calibration plans: raster, grid, Sobol, spiral;
* :mod:`~reflector_opt.calibration._temperature` — a form applied to voltages mapped back to the
  calibration temperature, each sensor's gain and offset change per kelvin fitted with it.

The models and their files are re-exported here: ``from reflector_opt.calibration import Eq6,
save_model, load_model``.
"""

import lazy_loader

#: The modules that define the public names, and the names each gives; a module is
#: imported the first time one of its names is used.
_MODULES = {
    "_models": ("Eq5", "Eq6", "Polynomial", "make_model"),
    "_validation": ("cross_validate",),
    "_coefficients": ("load_model", "save_model"),
    "_temperature": ("TemperatureCompensated",),
    "_files": ("read_plan_csv", "write_calibration_csv", "write_voltage_log"),
    "_synthetic": ("built_units", "calibration_data", "voltage_log"),
    "_simulation": ("simulate_calibration",),
    "_segment": ("simulate_segment",),
}

__getattr__, __dir__, __all__ = lazy_loader.attach(__name__, submod_attrs=_MODULES)
