"""Names of the calibration choices, importable without the numerical stack.

The command line lists them in its help, which must start at once; the modules that
implement them import them from here.
"""

#: The fits of a calibration's coefficients (:func:`~reflector_opt.calibration._fitting.solve`).
FITS = ("lsq", "huber", "minimax")
