"""The physical model: sensor-to-reflector distance, optical coupling and output voltage.

Layer 1, the lowest: imports nothing of the package but :mod:`reflector_opt.util`.

* :mod:`~reflector_opt.model.geometry` — Eq 1–3: the rotated sphere centre, the distance;
* :mod:`~reflector_opt.model.optics` — Eq 4 and its extension to a convex, tilted reflector;
* :mod:`~reflector_opt.model.kernel` — the per-pose formulas compiled into one pass (numba);
* :mod:`~reflector_opt.model.forward` — the forward model over every pose: :func:`respond`;
* :mod:`~reflector_opt.model.sensors` — the sensor model and its presets;
* :mod:`~reflector_opt.model.catalogue` — the sensor catalogue: real parts as data, with
  their datasheet figures and sources (``reflector_opt/data/sensor_catalogue.toml``);
* :mod:`~reflector_opt.model.catalogue_fit` — a part's model fitted to its datasheet figures;
* :mod:`~reflector_opt.model.electronics` — the circuit: coupling to output voltage and back;
* :mod:`~reflector_opt.model.flat_target` — a flat target's coupling, corrected to a
  measured curve;
* :mod:`~reflector_opt.model.sensor_file` — a sensor model's checks and dict form;
* :mod:`~reflector_opt.model.measured` — sensors described by a measured voltage curve;
* :mod:`~reflector_opt.model.flat_hankel` — flat-target couplings in closed form (any LED
  pattern, sub-surface spread);
* :mod:`~reflector_opt.model.flat_fit` — the joint fit of flat-target curves: sensor,
  offsets, a sample's surface;
* :mod:`~reflector_opt.model.material_fit` — a material's ρ, f and sub-surface spread from
  flat-sample curves;
* :mod:`~reflector_opt.model.noise` — voltage noise, ADC quantisation, gain and offset;
* :mod:`~reflector_opt.model.reference` — a direct, uncompiled reference of the model.
"""
