"""The figures, one module per domain; each function returns a
:class:`matplotlib.figure.Figure` on an Agg canvas (no pyplot, no global state), and
single-panel figures take an optional ``ax`` to draw into. Angles are in degrees, lengths in
mm, voltages in V, on every axis label. :mod:`reflector_opt.report._plots` gathers them all in
one namespace for scripts and notebooks.

* :mod:`~reflector_opt.report.figures._base` — the shared helpers: a figure on its own canvas,
  the map over pitch × roll, the worst pose marked, atomic saving;
* :mod:`~reflector_opt.report.figures._response` — each sensor's voltage and distance;
* :mod:`~reflector_opt.report.figures._resolution` — the Cramér–Rao resolution;
* :mod:`~reflector_opt.report.figures._sections` — sections through the unit and the sensors;
* :mod:`~reflector_opt.report.figures._planes` — the section planes: a sensor's plane and the
  circle a sphere cuts from it;
* :mod:`~reflector_opt.report.figures._calibration` — calibration errors, motions, plans;
* :mod:`~reflector_opt.report.figures._tolerance` — a tolerance study's errors, yield and
  sensitivities;
* :mod:`~reflector_opt.report.figures._optimiser` — the Pareto front and sweeps;
* :mod:`~reflector_opt.report.figures._asbuilt` — the as-built identification's deviations.
"""
