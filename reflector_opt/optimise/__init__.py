"""Design optimisation: variables, objective and constraints, search, Pareto front, robust design.

>>> from reflector_opt.optimise import optimise
>>> result = optimise(seed=0)            # doctest: +SKIP
>>> result.design.save("design.json")    # doctest: +SKIP
"""

from reflector_opt.util.lazy import lazy_exports

#: Each public name and the module that defines it, imported on first use.
_SOURCES = {
    "VARIABLES": "reflector_opt.optimise.variables",
    "Constraint": "reflector_opt.optimise.constraints",
    "Evaluation": "reflector_opt.optimise.evaluation",
    "OptimisationResult": "reflector_opt.optimise.result",
    "Problem": "reflector_opt.optimise.problem",
    "SearchBudget": "reflector_opt.optimise.search",
    "Variable": "reflector_opt.optimise.variables",
    "default_bounds": "reflector_opt.optimise.variables",
    "objective_value": "reflector_opt.optimise.evaluation",
    "optimise": "reflector_opt.optimise.search",
}

__all__ = list(_SOURCES)
__getattr__, __dir__ = lazy_exports(__name__, _SOURCES)
