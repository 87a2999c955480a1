"""Design optimisation: variables, objective and constraints, search, Pareto front, robust design.

>>> from reflector_opt.optimiser import optimise
>>> result = optimise(seed=0)            # doctest: +SKIP
>>> result.design.save("design.json")    # doctest: +SKIP
"""

import lazy_loader

#: The modules that define the public names, and the names each gives; a module is
#: imported the first time one of its names is used.
_MODULES = {
    "_variables": ("VARIABLES", "Variable", "default_bounds"),
    "_constraints": ("Constraint",),
    "_evaluation": ("Evaluation", "objective_value"),
    "_result": ("OptimisationResult",),
    "_problem": ("Problem",),
    "_search": ("SearchBudget", "optimise"),
    "_config": ("OptimiseConfig",),
}

__getattr__, __dir__, __all__ = lazy_loader.attach(__name__, submod_attrs=_MODULES)
