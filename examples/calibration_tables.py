"""The predicted figures quoted in docs/calibration.md, printed as Markdown.

Every number there comes from this script on the default design, seed 0:

- the model table (Eq 5 with and without intercept, Eq 6 by least squares, Huber and
  minimax, full polynomials of degree 3 to 5), from the paper's protocol on the forward model,
  with the derived figures its reading quotes;
- the Fig. 5 check (Eq 5 on the model's optical coupling, 1° grid, 2000 random poses);
- the Table-I-style segment table with Eq 6, and the same motions with poly4;
- the ``reflector-opt calibrate`` example: synthetic measured-style CSVs and the command's
  output on them.

Run from the repository root:  python examples/calibration_tables.py [--step-deg 0.1]
"""

import argparse
import contextlib
import tempfile
from dataclasses import replace
from pathlib import Path

import numpy as np

import reflector_opt as ro
from reflector_opt.calibration._files import write_calibration_csv, write_voltage_log
from reflector_opt.calibration._models import Eq5, make_model
from reflector_opt.calibration._segment import table_one
from reflector_opt.calibration._simulation import assess, run_protocol
from reflector_opt.calibration._synthetic import built_units, calibration_data, voltage_log
from reflector_opt.cli import main as cli_main

#: Rows of the model table: label, model name, fit, extra constructor parameters.
MODELS = (
    ("eq5 (paper, no intercept)", "eq5", "lsq", {}),
    ("eq5 + intercept", "eq5", "lsq", {"intercept": True}),
    ("eq6", "eq6", "lsq", {}),
    ("eq6, Huber", "eq6", "huber", {}),
    ("eq6, minimax", "eq6", "minimax", {}),
    ("poly3", "poly3", "lsq", {}),
    ("poly4", "poly4", "lsq", {}),
    ("poly5", "poly5", "lsq", {}),
)


def compute(step_deg=0.1, seed=0):
    """Fit every model of the table and run the segment motions with eq6 and poly4.

    Parameters
    ----------
    step_deg : float
        Calibration grid step, degrees (the paper's 0.1°; coarser is faster).
    seed : int

    Returns
    -------
    dict
        ``design`` (the default design with this grid step), ``models`` (label ->
        :class:`CalibrationResult`) and ``segment`` (``eq6`` and
        ``poly4`` -> :func:`~reflector_opt.calibration._segment.table_one` output).
    """
    design = ro.default_design()
    design = design.replace(workspace=replace(design.workspace, step_deg=step_deg))
    protocol = run_protocol(design, seed=seed)
    models = {
        label: assess(make_model(name, fit, **params), protocol)
        for label, name, fit, params in MODELS
    }
    segment = {key: table_one(design, models[key].model, seed=seed) for key in ("eq6", "poly4")}
    return {"design": design, "models": models, "segment": segment}


def fig5_check(design, step_deg=1.0, n_test=2000, seed=0):
    """Eq 5 fitted to the model's optical coupling η (the paper's Fig. 5 check).

    Returns
    -------
    dict
        RMS error (pitch, roll), degrees, with and without intercept; the correlation of the
        intercept form's estimates with the true angles; the RMS of the test angles.
    """
    pitch, roll = np.meshgrid(*design.workspace.axes(step_deg), indexing="ij")
    train = np.column_stack([pitch.ravel(), roll.ravel()])
    lo, hi = np.transpose([design.workspace.pitch_deg, design.workspace.roll_deg])
    test = np.random.default_rng(seed).uniform(lo, hi, size=(n_test, 2))

    def coupling(poses):
        return ro.respond(design, poses[:, 0], poses[:, 1]).coupling

    def rms(values):
        return np.sqrt(np.mean(np.square(values), axis=0))

    affine = Eq5(intercept=True).fit(coupling(train), train).predict(coupling(test))
    literal = Eq5().fit(coupling(train), train).predict(coupling(test))
    return {
        "intercept_rms_deg": rms(affine - test),
        "correlation": np.array([np.corrcoef(affine[:, j], test[:, j])[0, 1] for j in (0, 1)]),
        "no_intercept_rms_deg": rms(literal - test),
        "angle_rms_deg": rms(test),
    }


def pair(values, digits=3):
    """'a / b' for a (pitch, roll) pair."""
    return " / ".join(f"{v:.{digits}f}" for v in values)


def model_table(models):
    """The model table and the figures its reading quotes, as Markdown lines."""
    lines = [
        "| model | RMS pitch / roll (°) | max (°) | % error | misfit RMS (°) | noise RMS (°) |",
        "| --- | --- | --- | --- | --- | --- |",
    ]
    for label, r in models.items():
        lines.append(
            f"| {label} | {pair(r.total.rms_deg)} | {pair(r.total.max_deg)} | "
            f"{pair(r.total.percent, 2)} | {pair(r.misfit.rms_deg)} | {pair(r.noise.rms_deg)} |"
        )
    eq6, huber, minimax = models["eq6"], models["eq6, Huber"], models["eq6, minimax"]
    noise_dominated = [
        k
        for k in ("poly3", "poly4", "poly5")
        if np.all(models[k].noise.rms_deg > models[k].misfit.rms_deg)
    ]
    lines += [
        "",
        f"- eq6: misfit RMS {pair(eq6.misfit.rms_deg)}° of total {pair(eq6.total.rms_deg)}°, "
        f"noise RMS {pair(eq6.noise.rms_deg)}°",
        "- total RMS / eq6 total RMS: "
        + ", ".join(
            f"{k} {pair(models[k].total.rms_deg / eq6.total.rms_deg, 2)}"
            for k in ("eq5 + intercept", "poly3", "poly4", "poly5")
        ),
        f"- minimax / lsq (eq6): max {pair(minimax.total.max_deg / eq6.total.max_deg, 2)}, "
        f"RMS {pair(minimax.total.rms_deg / eq6.total.rms_deg, 2)}",
        f"- Huber − lsq (eq6): RMS {pair(huber.total.rms_deg - eq6.total.rms_deg)}°, "
        f"max {pair(huber.total.max_deg - eq6.total.max_deg)}°",
        f"- noise RMS > misfit RMS (both angles): {', '.join(noise_dominated) or 'none'}",
    ]
    return lines


def fig5_lines(check):
    """The Fig. 5 figures as Markdown lines."""
    return [
        f"- with intercept: RMS {pair(check['intercept_rms_deg'], 2)}°, correlation "
        f"{pair(check['correlation'], 3)}",
        f"- RMS of the test angles themselves: {pair(check['angle_rms_deg'], 2)}°",
        f"- without intercept (the printed form): RMS {pair(check['no_intercept_rms_deg'], 2)}°",
    ]


def segment_lines(segment):
    """The Table-I-style table (eq6) and the poly4 sentence's figures, as Markdown lines."""
    lines = [
        "| motion | % error (ours / paper†) | RMS tip error (°) | max tip error (°) "
        "| tip position RMS / max (mm) |",
        "| --- | --- | --- | --- | --- |",
    ]
    for axis, row in segment["eq6"].items():
        ours, paper = row["predicted"], row["paper"]
        lines.append(
            f"| {axis} ±{row['amplitude_deg']:g}° | {ours['percent_error']:.2f} / "
            f"{paper['percent_error']:.2f} | {ours['rms_deg']:.2f} (paper {paper['rms_deg']:.2f})"
            f" | {ours['max_deg']:.2f} (paper {paper['max_deg']:.2f}) | "
            f"{ours['position_rms_mm']:.2f} / {ours['position_max_mm']:.2f} |"
        )
    poly4 = [segment["poly4"][axis]["predicted"] for axis in ("pitch", "roll")]
    lines += [
        "",
        f"poly4, pitch / roll motion: RMS tip error {pair([p['rms_deg'] for p in poly4], 2)}°, "
        f"max {pair([p['max_deg'] for p in poly4], 2)}°",
    ]
    return lines


def cli_example(design, seed=0):
    """Write synthetic lab CSVs, show their first rows and run ``reflector-opt calibrate``."""
    units = built_units(design, seed=seed)
    data = calibration_data(design, units, step_deg=0.5, seed=seed)
    log = voltage_log(design, units, "pitch", seed=seed)
    with tempfile.TemporaryDirectory() as folder, contextlib.chdir(folder):
        write_calibration_csv("data.csv", data["unit"], data["volts"], data["angles_deg"])
        write_voltage_log("log.csv", log["sample"], log["unit"], log["volts"])
        rows = Path("data.csv").read_text().splitlines()
        first_of_unit_2 = next(row for row in rows if row.startswith("2,"))
        print("```", *rows[:3], "...", first_of_unit_2, "```", sep="\n")
        print("```", *Path("log.csv").read_text().splitlines()[:3], "...", "```", sep="\n")
        print("```")
        code = cli_main(["calibrate", "data.csv", "-o", "coefficients.json"])
        print("```")
    if code != 0:
        raise SystemExit(code)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--step-deg", type=float, default=0.1, help="grid step (default 0.1)")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    results = compute(args.step_deg, args.seed)
    design = results["design"]
    noise = design.noise
    print(
        f"# Predicted figures (default design, σ = {noise.sigma_v * 1e3:g} mV, "
        f"{noise.adc_bits}-bit ADC at {noise.vref:g} V, grid step {args.step_deg:g}°, "
        f"seed {args.seed})\n\n## Calibration models\n"
    )
    print("\n".join(model_table(results["models"])))
    print("\n## Fig. 5 check (Eq 5 on the optical coupling)\n")
    print("\n".join(fig5_lines(fig5_check(design, seed=args.seed))))
    print("\n## Segment (Eq 6), Table I style\n")
    print("\n".join(segment_lines(results["segment"])))
    print("\n## reflector-opt calibrate on synthetic lab data\n")
    cli_example(design, args.seed)


if __name__ == "__main__":
    main()
