"""Reproduce the paper's theoretical check (Osman et al. 2024, Fig. 5).

Theoretical intensities of the two sensors (paper Eq 4 through the extended optics) are
computed on a grid of pitch and roll; the 2×2 linear calibration of Eq 5 (no intercept, as
in the paper) is fitted by least squares; a separate simulated motion is then estimated with
it and plotted against the true angles. The RMS error is printed.

Eq 5 maps intensities to angles with no intercept, so the zero pose must map to zero. With
raw intensities and two sensors that see the zero pose alike, that forces both angles to
depend on i1 − i2 alone and pitch cannot be told from roll; the paper's Fig. 8 plots
*relative* intensity, and with intensities taken relative to the zero pose (i / i0 − 1)
Eq 5 works as the paper found. Both are printed; the figure shows the relative form.

Run:  python examples/fig5_linear_calibration.py [-o cad_out/fig5_linear_calibration.png]
"""

import argparse
from pathlib import Path

import numpy as np

import reflector_opt as ro
from reflector_opt.calibration._models import Eq5
from reflector_opt.report._plots import angle_traces_figure, save_figure


def intensities(design, pitch_deg, roll_deg):
    """Relative reflected intensity of each sensor (detected over emitted power)."""
    return ro.respond(design, pitch_deg, roll_deg).coupling


def run(out):
    """Fit Eq 5, estimate the simulated motion, write the figure; return the RMS errors.

    Returns
    -------
    dict
        ``raw`` and ``relative``: RMS (pitch, roll) error in degrees of Eq 5 on raw
        intensities and on intensities relative to the zero pose.
    """
    design = ro.default_design()
    # calibration: the workspace grid at 1°
    pitch, roll = np.broadcast_arrays(*design.workspace.grid(1.0))
    angles_cal = np.column_stack([pitch.ravel(), roll.ravel()])
    i_cal = intensities(design, pitch, roll).reshape(-1, 2)
    i_zero = intensities(design, 0.0, 0.0)
    # validation: a simulated motion through the workspace, different from the grid
    t = np.linspace(0.0, 2.0 * np.pi, 400)
    motion = np.column_stack([15.0 * np.sin(t), 15.0 * np.sin(2.0 * t + 0.6)])
    i_motion = intensities(design, motion[:, 0], motion[:, 1])

    def eq5(train, test):
        """Fit [pitch, roll]ᵀ = K [i1, i2]ᵀ by least squares (no intercept) and estimate."""
        model = Eq5(loss="lsq").fit(train, angles_cal)
        return model.coef_, model.predict(test)

    _, raw_estimate = eq5(i_cal, i_motion)
    k_matrix, estimate = eq5(i_cal / i_zero - 1.0, i_motion / i_zero - 1.0)
    raw_rms = np.sqrt(np.mean((raw_estimate - motion) ** 2, axis=0))
    rms = np.sqrt(np.mean((estimate - motion) ** 2, axis=0))
    print(f"Eq 5 on raw intensities: RMS pitch {raw_rms[0]:.2f}°, roll {raw_rms[1]:.2f}°")
    print(f"Eq 5 on relative intensities, K (deg):\n{np.array2string(k_matrix, precision=2)}")
    print(f"RMS error over the simulated motion: pitch {rms[0]:.2f}°, roll {rms[1]:.2f}°")

    fig = angle_traces_figure(
        motion, estimate, title="Eq 5 on intensities relative to the zero pose (paper Fig. 5)"
    )
    save_figure(fig, out, dpi=120)
    print(f"wrote {out}")
    return {"raw": raw_rms, "relative": rms}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("-o", "--output", default="cad_out/fig5_linear_calibration.png")
    run(Path(parser.parse_args().output))


if __name__ == "__main__":
    main()
