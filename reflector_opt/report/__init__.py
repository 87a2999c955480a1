"""The design report and its figures.

Output layer: imports every layer below it (model to optimise, and :mod:`reflector_opt.cad`)
but never :mod:`reflector_opt.cli`.

* :mod:`~reflector_opt.report.figures` — every figure, one function each, one module per
  domain; :mod:`~reflector_opt.report.plots` gathers them in one namespace;
* :mod:`~reflector_opt.report.report` — the report of a design, as blocks, and its files;
* :mod:`~reflector_opt.report.render` — the blocks as Markdown and HTML, from the Jinja
  templates in ``report/templates``;
* :mod:`~reflector_opt.report.asbuilt` — its as-built section (``report --as-built``);
* :mod:`~reflector_opt.report.correction` — its print-correction section (a corrected design).
* :mod:`~reflector_opt.report.view3d` — the interactive 3D view, in the report and alone.
"""
