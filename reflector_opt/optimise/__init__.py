"""Design optimisation: variables, objective and constraints, search, Pareto front, robust design.

>>> from reflector_opt.optimise import optimise
>>> result = optimise(seed=0)            # doctest: +SKIP
>>> result.design.save("design.json")    # doctest: +SKIP
"""

from reflector_opt.optimise.constraints import Constraint
from reflector_opt.optimise.evaluation import Evaluation, objective_value
from reflector_opt.optimise.problem import Problem
from reflector_opt.optimise.result import OptimisationResult
from reflector_opt.optimise.search import SearchBudget, optimise
from reflector_opt.optimise.variables import VARIABLES, Variable, default_bounds

__all__ = [
    "VARIABLES",
    "Constraint",
    "Evaluation",
    "OptimisationResult",
    "Problem",
    "SearchBudget",
    "Variable",
    "default_bounds",
    "objective_value",
    "optimise",
]
