"""Known Eq 6 calibration data for the model tests: exact angles from known coefficients."""

import numpy as np

# Known Eq 6 coefficients, the paper's order: v1, v2, v1², v2², v1·v2, v1·v2², v2·v1², 1.
K_PITCH = np.array([-40.0, -2.0, 13.0, 0.4, 1.4, -0.26, -0.04, 17.0])
J_ROLL = np.array([-6.6, 38.0, 1.7, -14.0, 2.0, 0.2, -0.6, -10.0])


def eq6_by_hand(volts, k):
    """Paper Eq 6 written out term by term (independent of the package's monomials)."""
    v1, v2 = volts[:, 0], volts[:, 1]
    return (
        k[0] * v1
        + k[1] * v2
        + k[2] * v1**2
        + k[3] * v2**2
        + k[4] * v1 * v2
        + k[5] * v1 * v2**2
        + k[6] * v2 * v1**2
        + k[7]
    )


def synthetic(n, seed=0, sigma_deg=0.0):
    """Voltages in the sensors' range and the exact Eq 6 angles (plus optional noise)."""
    rng = np.random.default_rng(seed)
    volts = rng.uniform(1.3, 2.9, size=(n, 2))
    angles = np.column_stack([eq6_by_hand(volts, K_PITCH), eq6_by_hand(volts, J_ROLL)])
    return volts, angles + sigma_deg * rng.standard_normal(angles.shape)
