"""The design report and its figures.

Output layer: imports every layer below it (model to optimise, and :mod:`reflector_opt.cad`)
but never :mod:`reflector_opt.cli`.

* :mod:`~reflector_opt.report.figures` — every figure, one function each, one module per
  domain; :mod:`~reflector_opt.report._plots` gathers them in one namespace;
* :mod:`~reflector_opt.report._report` — the report of a design, as blocks, and its files;
* :mod:`~reflector_opt.report._render` — the blocks as Markdown and HTML, from the Jinja
  templates in ``report/templates``;
* :mod:`~reflector_opt.report._asbuilt` — its as-built section (``report --as-built``);
* :mod:`~reflector_opt.report._correction` — its print-correction section (a corrected design).
* :mod:`~reflector_opt.report._view3d` — the interactive 3D view, in the report and alone.
"""

__all__ = ["plots"]


def __getattr__(name):
    """``plots``, every figure in one namespace (:mod:`reflector_opt.report._plots`), imported
    when first asked for: matplotlib is not loaded with the package."""
    if name == "plots":
        import importlib

        return importlib.import_module("reflector_opt.report._plots")
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
