"""The report's sensor-choice section: the catalogue parts ranked for this design's unit.

A design written by ``reflector-opt optimise --sensor`` carries ``predicted["sensor_choice"]``
(:mod:`reflector_opt.optimiser.sensor_choice`): the part chosen, its catalogue record and the
ranking of every part tried. :func:`ranking_blocks` turns it into report blocks; a design
without it gets none.
"""

from __future__ import annotations

from reflector_opt.optimiser.sensor_choice import RANKING_HEADER, ranking_rows

__all__ = ["ranking_blocks"]


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
    choice = (design.predicted or {}).get("sensor_choice")
    if not choice:
        return []
    return [
        ("h2", "Sensor choice"),
        ("p", _chosen_text(choice)),
        ("table", RANKING_HEADER, ranking_rows(choice)),
    ]
