"""What every command does around its workflow: the output folder refused before any work, the
progress display, the command line recorded in the folder's manifest, and the run printed
(its text and the files written, or ``--json``)."""

from reflector_opt.cli._arguments import output_folder
from reflector_opt.cli._output import folder_lines, print_json, progress_for, written_lines


def call_into_folder(args, workflow, *inputs, **options):
    """Make a run and write it into its output folder, as a command does.

    ``--out`` is refused before any work, named by its option
    (:func:`~reflector_opt.cli._arguments.output_folder`); the progress is shown unless
    ``--quiet``; the command line goes to the folder's manifest.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line (``out``, ``quiet``, ``argv``).
    workflow : callable
        ``workflow(*inputs, progress=…, **options)``, returning a run computed in memory
        with ``write(folder, command=…)``.
    *inputs
        The workflow's positional arguments.
    **options
        Its other keyword arguments.

    Returns
    -------
    object
        The run, written.
    """
    out = output_folder(args.out)
    with progress_for(args) as progress:
        run = workflow(*inputs, progress=progress, **options)
        return run.write(out, command=args.argv)


def print_run(args, run, files=None, folder=None):
    """Print a command's run; returns the exit code, 0.

    With ``--json``, the run's ``to_dict()`` (:func:`~reflector_opt.cli._output.print_json`);
    else its ``text()``, then the files written and the command's wall time.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line (``json``, ``started``).
    run : object
        A workflow's run: ``text()`` and ``to_dict()``.
    files : iterable of str or pathlib.Path, optional
        The files to list (default the run's ``files``).
    folder : str or pathlib.Path, optional
        The output folder the files are in, listed with its manifest
        (:func:`~reflector_opt.cli._output.folder_lines`); None for files written alone
        (:func:`~reflector_opt.cli._output.written_lines`).

    Returns
    -------
    int
    """
    if args.json:
        print_json(run.to_dict())
        return 0
    print(run.text())
    files = run.files if files is None else files
    if folder is None:
        print(written_lines(files, args.started))
    else:
        print(folder_lines(folder, files, args.started))
    return 0
