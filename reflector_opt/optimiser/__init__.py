"""Design optimisation: variables, objective and constraints, search, Pareto front, robust design.

>>> from reflector_opt.optimiser import optimise
>>> result = optimise(seed=0)            # doctest: +SKIP
>>> result.design.save("design.json")    # doctest: +SKIP
"""

from reflector_opt.util.lazy import lazy_exports

#: The modules that define the public names, and the names each gives; a module is
#: imported the first time one of its names is used.
_MODULES = {
    ".variables": ("VARIABLES", "Variable", "default_bounds"),
    ".constraints": ("Constraint",),
    ".evaluation": ("Evaluation", "objective_value"),
    ".result": ("OptimisationResult",),
    ".problem": ("Problem",),
    ".search": ("SearchBudget", "optimise"),
}

__all__, __getattr__, __dir__ = lazy_exports(__name__, _MODULES)
