"""Calibration: the paper's Eq 5 and Eq 6 and polynomial forms, their fits, file formats,
the simulated protocol, the multi-unit segment and the lab workflow.

Layer 4: imports :mod:`reflector_opt.model`, :mod:`reflector_opt.design`,
:mod:`reflector_opt.analysis` and :mod:`reflector_opt.util`.

* :mod:`~reflector_opt.calibration.models` — the calibration models (scikit-learn style);
* :mod:`~reflector_opt.calibration.files` — calibration data and coefficient files;
* :mod:`~reflector_opt.calibration.simulation` — the paper's protocol on the forward model;
* :mod:`~reflector_opt.calibration.segment` — a segment of units, Table-I-style errors;
* :mod:`~reflector_opt.calibration.lab` — calibrate printed units from measured data;
* :mod:`~reflector_opt.calibration.synthetic` — synthetic lab data for examples and tests;
* :mod:`~reflector_opt.calibration.prediction` — a design's windows and predicted errors.
"""
