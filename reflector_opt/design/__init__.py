"""The design: reflector, sensors, workspace, mechanics, noise, and the printed parts' layout.

Layer 2: imports :mod:`reflector_opt.model` and :mod:`reflector_opt.util`.

* :mod:`~reflector_opt.design.design` — the :class:`Design` and ``design.json``;
* :mod:`~reflector_opt.design.parts` — the printed parts' dimensions (CAD parameters);
* :mod:`~reflector_opt.design.layout` — where the printed features go (windows, mounts,
  tendon holes), shared by the optimiser's wall check and the CAD export;
* :mod:`~reflector_opt.design.polar` — regions and directions about O (the layout's polar
  boxes).
"""
