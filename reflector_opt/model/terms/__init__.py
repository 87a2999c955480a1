"""The terms of the voltage pipeline (:mod:`reflector_opt.model._operating`), registered once.

Each term is a module with ``FIELDS``, the :class:`~reflector_opt.model._operating.OperatingState`
fields it reads, and ``apply(circuit, model, state)``, which returns the sensor's
:class:`~reflector_opt.model._operating.Circuit` changed by what the term describes (the
circuit unchanged where the state leaves the term at rest). A term changes the photocurrent,
adds collector current, or moves the supply and the read-out; the pipeline turns the result
into the output voltage. Every state field is read by exactly one term
(tests/model/terms/test_registry.py).
"""

from reflector_opt.model.terms import _light as light
from reflector_opt.model.terms import _settling as settling
from reflector_opt.model.terms import _stray as stray
from reflector_opt.model.terms import _supply as supply
from reflector_opt.model.terms import _temperature as temperature

__all__ = ["TERMS"]

#: The pipeline's terms in the order they act (their effects multiply or add, so the order
#: changes the result only by rounding).
TERMS = (temperature, light, settling, stray, supply)
