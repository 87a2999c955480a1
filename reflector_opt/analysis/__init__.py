"""Metrics of a design over its workspace: distance window, Jacobian, conditioning,
Cramér–Rao resolution, uniqueness and printed-wall margins.

Layer 3: imports :mod:`reflector_opt.model`, :mod:`reflector_opt.design` and
:mod:`reflector_opt.util`.

* :mod:`~reflector_opt.analysis._jacobian` — ∂(outputs)/∂(pitch, roll) by central differences;
* :mod:`~reflector_opt.analysis._resolution` — conditioning, Cramér–Rao bound, folds, uniqueness;
* :mod:`~reflector_opt.analysis._metrics` — distance window, shell wall and reach, and every
  metric of a design: :func:`~reflector_opt.analysis._metrics.evaluate_metrics`.
"""

import lazy_loader

__getattr__, __dir__, __all__ = lazy_loader.attach(
    __name__, submod_attrs={"_metrics": ("evaluate_metrics",)}
)
