"""The report's sensor-choice section: the catalogue parts ranked for this design's unit.

A design written by ``reflector-opt optimise --sensor`` carries ``predicted["sensor_choice"]``
(:mod:`reflector_opt.optimiser._sensor_choice`): the part chosen, its catalogue record and the
ranking of every part tried. :func:`ranking_blocks` turns it into report blocks; a design
without it gets none.
"""

#: Columns of :func:`ranking_rows`.
RANKING_HEADER = (
    "rank",
    "part",
    "package (mm)",
    "in-use worst case (°)",
    "white-noise worst pitch 1σ (°)",
    "white-noise worst roll 1σ (°)",
    "calibration RMS pitch / roll (°)",
    "margin (mm)",
    "body radius (mm)",
)


def ranking_rows(record):
    """The ranking of a :class:`~reflector_opt.optimiser._sensor_choice.SensorChoice` record
    as rows of text, ranked parts first.

    Parameters
    ----------
    record : dict
        ``predicted["sensor_choice"]`` of a design.

    Returns
    -------
    list of tuple of str
        One per part, the columns of :data:`RANKING_HEADER` (the in-use worst case ``n/a``
        for a ranking without conditions); a skipped part has ``-`` for its rank and its
        reason in the third column, the others empty.
    """
    rows = []
    for row in record["ranking"]:
        package = " × ".join(f"{v:g}" for v in row["package_mm"])
        if row["status"] != "ranked":
            rows.append(("-", row["part"], f"skipped: {row['reason']}", *[""] * 6))
            continue
        rows.append(
            (
                str(row["rank"]),
                row["part"],
                package,
                _deg(row["worst_case_deg"]) if "worst_case_deg" in row else "n/a",
                _deg(row["worst_pitch_deg"]),
                _deg(row["worst_roll_deg"]),
                _calibration(row.get("calibration_rms_deg")),
                f"{row['margin_mm']:.3f}",
                f"{row['body_radius_mm']:.3f}",
            )
        )
    return rows


def _deg(value):
    return "inf" if value is None else f"{value:.4f}"


def _calibration(error):
    """``pitch / roll`` of a predicted calibration error, or ``n/a``."""
    return "n/a" if error is None else f"{error['pitch']:.3f} / {error['roll']:.3f}"


def _chosen_text(choice):
    part = choice["part"]
    ranked = sum(1 for r in choice["ranking"] if r["status"] == "ranked")
    return (
        f"The design uses the {choice['chosen']} ({part.get('maker', 'maker not stated')}; "
        f"{part.get('datasheet', 'no datasheet stated')}), chosen by the optimiser from "
        f"{len(choice['ranking'])} part(s), {ranked} of which fit the unit (seed "
        f"{choice['seed']}). Ranked by {choice['criteria']}. Predicted calibration error: "
        f"{choice.get('calibration', 'the recommended calibration of built units')}, RMS over "
        "the validation poses. Each part's figures, their sources and whether each is "
        "measured, published or assumed are in the design's sensor_choice record "
        "(docs/optimiser.md)."
    )


def ranking_blocks(design):
    """Report blocks of a design's sensor choice (none if it carries none).

    Parameters
    ----------
    design : reflector_opt.design._design.Design

    Returns
    -------
    list of tuple
        Blocks as :func:`reflector_opt.report._report.report_blocks` returns them: a heading,
        a paragraph naming the chosen part and the criteria, and the ranking as a table
        (resolutions and calibration errors in degrees, margin and body radius in mm).
    """
    choice = design.predicted.sensor_choice
    if not choice:
        return []
    return [
        ("h2", "Sensor choice"),
        ("p", _chosen_text(choice)),
        ("table", RANKING_HEADER, ranking_rows(choice)),
    ]
