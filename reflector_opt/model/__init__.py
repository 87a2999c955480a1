"""The physical model: sensor-to-reflector distance, optical coupling and output voltage.

Layer 1, the lowest: imports nothing of the package but :mod:`reflector_opt.util`.

* :mod:`~reflector_opt.model._geometry` — Eq 1–3: the rotated sphere centre, the distance;
* :mod:`~reflector_opt.model._optics` — Eq 4 and its extension to a convex, tilted reflector;
* :mod:`~reflector_opt.model._kernel` — the per-pose formulas compiled into one pass (numba);
* :mod:`~reflector_opt.model._forward` — the forward model over every pose: :func:`respond`;
* :mod:`~reflector_opt.model._sensors` — the sensor model and its presets;
* :mod:`~reflector_opt.model._catalogue` — the sensor catalogue: real parts as data, with
  their datasheet figures and sources (``reflector_opt/data/sensor_catalogue.toml``);
* :mod:`~reflector_opt.model._catalogue_fit` — a part's model fitted to its datasheet figures;
* :mod:`~reflector_opt.model._electronics` — the circuit: coupling to output voltage and back;
* :mod:`~reflector_opt.model._flat_target` — a flat target's coupling, corrected to a
  measured curve;
* :mod:`~reflector_opt.model._sensor_file` — a sensor model's checks and dict form;
* :mod:`~reflector_opt.model._measured` — sensors described by a measured voltage curve;
* :mod:`~reflector_opt.model._flat_hankel` — flat-target couplings in closed form (any LED
  pattern, sub-surface spread);
* :mod:`~reflector_opt.model._flat_fit` — the joint fit of flat-target curves: sensor,
  offsets, a sample's surface;
* :mod:`~reflector_opt.model._material_fit` — a material's ρ, f and sub-surface spread from
  flat-sample curves;
* :mod:`~reflector_opt.model._noise` — voltage noise, ADC quantisation, gain and offset;
* :mod:`~reflector_opt.model._reference` — a direct, uncompiled reference of the model.
"""
