"""Polynomial terms in the two sensor voltages and the change of variable used for fitting.

A term is the monomial v1^a·v2^b, given by its exponents ``(a, b)``; a calibration model is a
list of terms and one coefficient per term and angle.

For conditioning, the models fit in scaled inputs u_i = (v_i − c_i) / s_i, each voltage centred
and scaled to [−1, 1]. A polynomial in u is a polynomial in v with the same terms whenever the
term set is closed under lowering exponents (:func:`is_closed`), or when nothing is centred
(c = 0): :func:`to_raw` and :func:`to_scaled` convert the coefficients between the two forms by
binomial expansion, exactly up to round-off.
"""

import math

import numpy as np


def term_name(exponents):
    """Readable name of the monomial v1^a·v2^b, e.g. ``"v1^2*v2"``; ``"1"`` for the constant."""
    parts = [f"v{i + 1}" + (f"^{e}" if e > 1 else "") for i, e in enumerate(exponents) if e > 0]
    return "*".join(parts) or "1"


def monomials(volts, terms):
    """Evaluate monomials v1^a·v2^b.

    Parameters
    ----------
    volts : numpy.ndarray
        Shape ``P + (2,)``.
    terms : sequence of (int, int)
        Exponents (a, b) of each term.

    Returns
    -------
    numpy.ndarray
        Shape ``P + (n_terms,)``.
    """
    v1, v2 = volts[..., 0], volts[..., 1]
    return np.stack([v1**a * v2**b for a, b in terms], axis=-1)


def substitute(coef, terms, slope, intercept):
    """Coefficients in w of Σ c_t·x^t after x_i = slope_i·w_i + intercept_i (binomial expansion).

    ``coef`` has shape (n_outputs, n_terms). Every term the expansion produces must be in
    ``terms`` (true for a set closed under lowering exponents, and for any set when the
    intercepts are zero).
    """
    index = {t: i for i, t in enumerate(terms)}
    out = np.zeros_like(coef)
    for col, (a, b) in enumerate(terms):
        for p in range(a + 1):
            for q in range(b + 1):
                factor = (
                    math.comb(a, p)
                    * math.comb(b, q)
                    * slope[0] ** p
                    * intercept[0] ** (a - p)
                    * slope[1] ** q
                    * intercept[1] ** (b - q)
                )
                if factor != 0.0:
                    out[:, index[(p, q)]] += factor * coef[:, col]
    return out


def is_closed(terms):
    """True if lowering any exponent of a term gives another term of the set."""
    present = set(terms)
    return all((p, q) in present for a, b in terms for p in range(a + 1) for q in range(b + 1))


def input_normalisation(volts, centred):
    """Centre and scale of each voltage that map the samples onto [−1, 1] (or [−s, s] uncentred).

    Parameters
    ----------
    volts : numpy.ndarray
        Shape (n_samples, 2), V.
    centred : bool
        Centre the inputs; otherwise the centre is zero and the scale the largest magnitude.

    Returns
    -------
    tuple of numpy.ndarray
        ``(centre, scale)``, shape (2,) each; a constant input gets scale 1.
    """
    lo, hi = volts.min(axis=0), volts.max(axis=0)
    if centred:
        centre, scale = (hi + lo) / 2.0, (hi - lo) / 2.0
    else:
        centre, scale = np.zeros(2), np.abs(volts).max(axis=0)
    return centre, np.where(scale > 0, scale, 1.0)


def to_raw(coef_scaled, terms, centre, scale):
    """Raw-voltage coefficients of a polynomial fitted in u = (v − centre) / scale."""
    return substitute(coef_scaled, terms, 1.0 / scale, -centre / scale)


def to_scaled(coef, terms, centre, scale):
    """The inverse of :func:`to_raw`: coefficients in u = (v − centre) / scale."""
    return substitute(coef, terms, scale, centre)
