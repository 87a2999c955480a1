"""The earlier names of the runs, kept for one release: ``optimise_run(options, out=…)`` and
the like computed and wrote in one call; each is now the run's function and its ``write``."""

import importlib
import warnings

#: Each earlier name, the run's function it calls, and how many positional inputs come before
#: the output (a folder or a file; none for ``evaluate_run``).
DEPRECATED = {
    "optimise_run": ("optimise", 1),
    "evaluate_run": ("evaluate", 1),
    "report_run": ("report", 1),
    "export_run": ("export", 1),
    "compare_run": ("compare", 2),
    "smallest_run": ("smallest", 1),
    "calibrate_run": ("calibrate", 1),
    "estimate_run": ("estimate", 2),
    "identify_run": ("identify", 1),
    "plan_calibration_run": ("plan_calibration", 1),
    "tolerance_run": ("tolerance", 1),
    "sweep_run": ("sweep", 2),
    "correct_run": ("correct", 1),
    "fit_sensor_run": ("fit_sensor", 1),
}


def deprecated_alias(name):
    """The earlier function ``name``: it warns (DeprecationWarning), makes the run and, given
    an output (positional after the inputs, or ``out=``/``output=``), writes it there.

    Parameters
    ----------
    name : str
        A key of :data:`DEPRECATED`.

    Returns
    -------
    callable
    """
    new_name, inputs = DEPRECATED[name]

    def alias(*args, out=None, output=None, command=None, part_file=None, **options):
        warnings.warn(
            f"{name} is deprecated and goes in the next release: use "
            f"reflector_opt.{new_name}(…) and the run's write(…)",
            DeprecationWarning,
            stacklevel=2,
        )
        target = out if out is not None else output
        if len(args) > inputs:
            args, target = args[:inputs], args[inputs]
        run = getattr(importlib.import_module("reflector_opt.workflow"), new_name)(*args, **options)
        if target is None and part_file is None:
            return run
        extra = {"command": command, "part_file": part_file}
        return run.write(target, **{key: value for key, value in extra.items() if value})

    alias.__name__ = alias.__qualname__ = name
    alias.__doc__ = f"Deprecated: ``{new_name}(…).write(…)``."
    return alias
