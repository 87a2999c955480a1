"""``reflector-opt report DESIGN.json [-o DIR] [--as-built AS_BUILT.json] [--conditions COND.toml]
[--no-cad] [--seed N] [--json] [--quiet]``.

Parses the options and calls :func:`reflector_opt.workflow.report`, which writes the
report; prints where it went.
"""

from __future__ import annotations

from reflector_opt.cli._arguments import DEFAULT_OUT, add_output_folder
from reflector_opt.cli._command import call_into_folder
from reflector_opt.cli._output import folder_lines, print_json
from reflector_opt.util._declared import add_options, options_of
from reflector_opt.workflow._report import ReportOptions


def register(subparsers):
    """Add the ``report`` subcommand."""
    p = subparsers.add_parser(
        "report",
        help="write a design report (Markdown with PNG figures, self-contained HTML) and the parts",
        description=(
            "Write report.md with its PNG figures and report.html, one file with its images "
            "inside: the design, its constraints and their slack (zero slack flagged), sensor "
            "windows with a section through each sensor's plane, resolution maps, the predicted "
            "calibration and segment errors beside the paper's, the printability of the parts "
            "with links to their files, and print and material notes; with --as-built, how "
            "each printed unit was built and which of its deviations cost resolution. The "
            "parts (STL, 3MF) are written too when the design passes the printability checks."
        ),
    )
    p.add_argument("design", metavar="DESIGN.json", help="the design to report")
    add_output_folder(p, f"{DEFAULT_OUT}/report", "the report, its figures and the parts")
    add_options(p, ReportOptions)
    p.add_argument("--json", action="store_true", help="print the summary as JSON")
    p.set_defaults(handler=run)


def run(args):
    """Write the report through :func:`~reflector_opt.workflow.report` and print where it
    went (or ``--json``); returns the exit code."""
    from reflector_opt.workflow import report

    result = call_into_folder(
        args,
        report,
        args.design,
        options_of(args, ReportOptions),
    )
    if args.json:
        print_json(result.to_dict())
        return 0
    if result.cad is not None and result.cad.error is not None:
        print(result.cad.summary())
    print(folder_lines(result.out, result.files, args.started))
    return 0
