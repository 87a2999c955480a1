"""Metrics of a design over its workspace: distance window, Jacobian, conditioning,
Cramér–Rao resolution, uniqueness and printed-wall margins.

Layer 3: imports :mod:`reflector_opt.model`, :mod:`reflector_opt.design` and
:mod:`reflector_opt.util`.
"""
