"""Files of a tolerance study: per-sample CSV and summary JSON, written atomically
(:mod:`reflector_opt.util._fileio`). The figures are in
:mod:`reflector_opt.report.figures._tolerance`."""

import math

from reflector_opt.util._fileio import write_csv, write_json


def _cell(value):
    if isinstance(value, float):
        return "" if math.isnan(value) else repr(value)
    return value


def write_records(path, records):
    """Write records (dicts with the same keys) as CSV, one row each; NaN as an empty cell."""
    columns = list(records[0]) if records else []
    write_csv(path, columns, ([_cell(r[c]) for c in columns] for r in records))


def write_study(out, study):
    """Write ``samples.csv`` (one row per sample) and ``summary.json`` into folder ``out``.

    Returns
    -------
    list of pathlib.Path
        The files written.
    """
    written = [out / "samples.csv", out / "summary.json"]
    write_records(written[0], study.records)
    write_json(written[1], study.to_dict())
    return written
