"""A calibration as C99 for the microcontroller: one header, float and fixed point.

:func:`firmware_header` writes, per unit, the calibration's coefficients and two evaluation
functions giving pitch and roll from the unit's two voltages (and its temperature where the
calibration is compensated, :mod:`~reflector_opt.calibration._temperature`):

* ``<name>_angles_f(unit, v1, v2, t_c, out)`` in ``RO_REAL`` (``float`` unless defined before
  the header): the form evaluated as ``predict`` does, in the scaled inputs
  u = (v − centre) · (1/scale), after Eq (2) of the compensation;
* ``<name>_angles_q(unit, v1_uv, v2_uv, t_mc, out)`` in integers: voltages in µV, the
  temperature in m°C, the angles in Q11.20 degrees (int32, LSB 2⁻²⁰° ≈ 9.5e-7°, magnitude
  below 2048°). The voltages are carried in µV·2⁸ (int64), u in Q3.28 (int32, magnitude below
  8; the calibration's own range is −1 … 1), each product of two Q3.28 numbers in int64 rounded
  back to Q3.28, the coefficients in Q11.20 and their sum in Q.48 (int64), rounded once.

The fixed-point function's error against the exact evaluation is bounded per unit by
:func:`fixed_point_bound` (the rounding of u, of each power and product, of each coefficient
and of the sum; the compensation's roundings, below 0.05 µV, enter through u); the header
states it for inputs within the calibration's range. The physical model is refused: it inverts
the forward model per sample, which is not a formula to compile.
"""

import shutil
import subprocess
import tempfile
from pathlib import Path

import numpy as np

from reflector_opt.calibration._temperature import TemperatureCompensated
from reflector_opt.calibration._terms import to_scaled
from reflector_opt.util._errors import InputError

#: Fraction bits: u and the powers (Q3.28), the coefficients and the angles (Q11.20).
FRACTION_BITS = {"u": 28, "angle": 20}

#: The compensation's rounding carried into V0, V (the truncated division, 2⁻⁸ µV, and the
#: rounded gain, offset and reference temperature for a temperature change of at most 50 K:
#: each below 0.02 µV).
COMPENSATION_ERROR_V = 0.05e-6


def unit_forms(calibrations):
    """(label, form, thermal model or None) per unit; InputError for a form C cannot hold."""
    out = []
    for calibration in calibrations:
        model = calibration.model
        form = model.form_ if isinstance(model, TemperatureCompensated) else model
        if not hasattr(form, "terms") or not hasattr(form, "coef_"):
            raise InputError(
                f"unit {calibration.unit}: a {type(form).__name__} calibration cannot be compiled "
                "to C (it inverts the forward model per sample); calibrate with eq5, eq6 or polyN"
            )
        out.append((calibration.unit, form, model if form is not model else None))
    return out


def _scaled(form):
    """The coefficients as ``predict`` applies them, in u = (v − centre) / scale: (2, n_terms)."""
    return to_scaled(form.coef_, form.terms, form.centre_v_, form.scale_v_)


def _lit(value):
    return f"{float(value):.17g}"


def _q(value, bits):
    """``value`` · 2^bits rounded, as a C int64 literal; InputError past int64."""
    number = round(float(value) * 2.0**bits)
    if abs(number) >= 2**63:
        raise InputError(f"firmware: {value:g} does not fit the fixed-point format")
    return f"INT64_C({number})"


def _polynomial(terms, coef, real):
    """C statements: powers of u1, u2 and out[0], out[1] of the form; float or fixed point."""
    top = [max(t[i] for t in terms) for i in (0, 1)]
    lines = []
    for i in (0, 1):
        for k in range(2, top[i] + 1):
            prev = f"u{i + 1}_{k - 1}" if k > 2 else f"u{i + 1}"
            lines.append(
                f"const RO_REAL u{i + 1}_{k} = {prev} * u{i + 1};"
                if real
                else f"const int32_t u{i + 1}_{k} = ro_mul({prev}, u{i + 1});"
            )
    power = ["", "u{}", "u{}_2", *(f"u{{}}_{k}" for k in range(3, 11))]
    for angle in (0, 1):
        sums = []
        for (a, b), c in zip(terms, coef[angle], strict=True):
            factors = [power[a].format(1)] * bool(a) + [power[b].format(2)] * bool(b)
            if real:
                sums.append(" * ".join([f"(RO_REAL){_lit(c)}", *factors]))
            else:
                mono = (
                    "ro_mul({}, {})".format(*factors)
                    if len(factors) == 2
                    else (factors or ["(INT64_C(1) << 28)"])[0]
                )
                sums.append(f"{_q(c, FRACTION_BITS['angle'])} * (int64_t){mono}")
        joined = "\n        + ".join(sums)
        lines.append(
            f"out[{angle}] = {joined};"
            if real
            else f"out[{angle}] = (int32_t)((({joined}) + (INT64_C(1) << 27)) >> 28);"
        )
    return lines


def _inputs(form, thermal, real):
    """C statements: each voltage compensated (Eq 2) where the unit's calibration is, then u."""
    lines = []
    if thermal is not None:
        t0 = thermal.reference_temperature_c_
        q = np.zeros(2) if thermal.gain_per_k2_ is None else thermal.gain_per_k2_
        if real:
            lines.append(f"const RO_REAL dt = t_c - (RO_REAL){_lit(t0)};")
        else:  # mK·2^16; the factor F in Q.30; N and V0 in µV·2^8
            lines.append(f"const int64_t dt = ((int64_t)t_mc << 16) - {_q(t0 * 1e3, 16)};")
        sensors = (thermal.gain_per_k_, thermal.offset_v_per_k_, thermal.supply_v_, q)
        for i, (c, d, vcc, qq) in enumerate(zip(*sensors, strict=True)):
            if real:
                lines.append(
                    f"v{i + 1} = (RO_REAL){_lit(vcc)} - ((RO_REAL){_lit(vcc)} - v{i + 1} - "
                    f"(RO_REAL){_lit(d)} * dt) / ((RO_REAL)1 + dt * ((RO_REAL){_lit(c)} + "
                    f"(RO_REAL){_lit(qq)} * dt));"
                )
                continue
            unit = 1e3 * 2**16  # dt's units per kelvin
            lines += [
                f"const int64_t k{i + 1} = {_q(c / unit, 62)} + ((({_q(qq / unit**2, 90)}) * dt)"
                " >> 28);",
                f"const int64_t f{i + 1} = (INT64_C(1) << 30) + ((k{i + 1} * dt) >> 32);",
                f"const int64_t n{i + 1} = {_q(vcc * 1e6, 8)} - x{i + 1}"
                f" - (({_q(d * 1e6 / unit, 38)} * dt) >> 30);",
                f"x{i + 1} = {_q(vcc * 1e6, 8)} - (n{i + 1} << 30) / f{i + 1};",
            ]
    for i in (0, 1):
        centre, scale = form.centre_v_[i], form.scale_v_[i]
        if real:
            lines.append(
                f"const RO_REAL u{i + 1} = (v{i + 1} - (RO_REAL){_lit(centre)}) * "
                f"(RO_REAL){_lit(1 / scale)};"
            )
        else:
            lines.append(
                f"const int32_t u{i + 1} = (int32_t)(((x{i + 1} - {_q(centre * 1e6, 8)}) * "
                f"{_q(1 / (scale * 1e6), 60 - 8)} + (INT64_C(1) << 31)) >> 32);"
            )
    return lines


#: Per evaluation: the function's suffix, its parameters and their names.
_SIGNATURES = {
    True: ("f", "RO_REAL v1, RO_REAL v2, RO_REAL t_c, RO_REAL out[2]", "v1, v2, t_c, out"),
    False: (
        "q",
        "int32_t v1_uv, int32_t v2_uv, int32_t t_mc, int32_t out[2]",
        "v1_uv, v2_uv, t_mc, out",
    ),
}


def _unit_function(name, j, label, form, thermal, real):
    suffix, args, call = _SIGNATURES[real]
    body = [f"(void){call.split(', ')[2]};"] if thermal is None else []
    if not real:
        body += ["int64_t x1 = (int64_t)v1_uv << 8;", "int64_t x2 = (int64_t)v2_uv << 8;"]
    body += _inputs(form, thermal, real) + _polynomial(form.terms, _scaled(form), real)
    text = "\n    ".join(body)
    head = f"static inline void {name}_u{j}_{suffix}({args})"
    return f"/* unit {label}: {form.name} */\n{head}\n{{\n    {text}\n}}\n"


def _dispatch(name, n, real):
    suffix, args, call = _SIGNATURES[real]
    cases = "\n".join(f"    case {j}: {name}_u{j}_{suffix}({call}); return 0;" for j in range(n))
    return (
        f"static inline int {name}_angles_{suffix}(int unit, {args})\n{{\n"
        f"    switch (unit) {{\n{cases}\n    default: return -1;\n    }}\n}}\n"
    )


def firmware_header(calibrations, name="ro"):
    """The calibrations as a C99 header.

    Parameters
    ----------
    calibrations : list of reflector_opt.calibration._unit_calibration.UnitCalibration
        Base first; unit ``j`` of the C functions is the ``j``-th.
    name : str
        Prefix of the C names (a C identifier).

    Returns
    -------
    str

    Raises
    ------
    InputError
        A physical model, or a prefix that is not a C identifier.
    """
    if not name.isidentifier() or not name.isascii():
        raise InputError(f"name: {name!r} is not a C identifier")
    forms = unit_forms(calibrations)
    guard = f"{name.upper()}_CALIBRATION_H"
    rows = "\n".join(
        f" *   {j}: unit {label}, {form.name}{' compensated' if th is not None else ''}, "
        f"fixed-point error ≤ {fixed_point_bound(form, th):.2g}°"
        for j, (label, form, th) in enumerate(forms)
    )
    functions = "\n".join(
        _unit_function(name, j, label, form, th, real)
        for real in (True, False)
        for j, (label, form, th) in enumerate(forms)
    )
    return f"""/* Calibration of {len(forms)} unit(s) as C99, written by reflector-opt firmware.
 * {name}_angles_f(unit, v1, v2, t_c, out): V, °C -> out[0] pitch, out[1] roll, degrees.
 * {name}_angles_q(unit, v1_uv, v2_uv, t_mc, out): µV, m°C -> Q11.20 degrees (LSB 2^-20°).
 * Both return 0, or -1 for an unknown unit; t is read only by compensated units.
 * Fixed-point error bounds hold for inputs within each calibration's voltage range:
{rows}
 */
#ifndef {guard}
#define {guard}
#include <stdint.h>
#ifndef RO_REAL
#define RO_REAL float
#endif
#define {name.upper()}_N_UNITS {len(forms)}

/* (a * b) rounded, both Q3.28 */
static inline int32_t ro_mul(int32_t a, int32_t b)
{{
    return (int32_t)(((int64_t)a * b + (INT64_C(1) << 27)) >> 28);
}}

{functions}
{_dispatch(name, len(forms), True)}
{_dispatch(name, len(forms), False)}
#endif
"""


def fixed_point_bound(form, thermal=None, u_max=1.0):
    """The largest error of the fixed-point angles against the exact evaluation, degrees.

    With U = ``u_max`` bounding the magnitude of u and ε = 2⁻²⁹ (half an LSB of Q3.28): u is off by
    δu = ε + U·2⁻³³ (the rounded 1/scale) + the compensation's 0.05 µV / scale; a power u^k by
    e_k ≤ U·e_{k−1} + U^{k−1}·δu + ε; a product u1^a·u2^b by U^b·e_a + U^a·e_b + ε; each term by
    abs(c)·e + 2⁻²¹·U^(a+b) (the coefficient's rounding) and the sum by 2⁻²¹ once.

    Parameters
    ----------
    form : Eq5, Eq6 or Polynomial
        Fitted.
    thermal : TemperatureCompensated, optional
    u_max : float
        The largest magnitude of u over the inputs (1: within the calibration's range).

    Returns
    -------
    float
        Per angle's worst of pitch and roll, degrees.
    """
    eps, half = 2.0**-29, 2.0**-21
    U = float(u_max)
    du = eps + U * 2.0**-33 + (0 if thermal is None else COMPENSATION_ERROR_V / form.scale_v_.min())
    top = max(max(t) for t in form.terms)
    e = [0.0, du]
    for k in range(2, top + 1):
        e.append(U * e[-1] + U ** (k - 1) * du + eps)
    bounds = [
        sum(
            abs(c) * (U**b * e[a] + U**a * e[b] + (eps if a and b else 0.0)) + half * U ** (a + b)
            for (a, b), c in zip(form.terms, coef, strict=True)
        )
        + half
        for coef in _scaled(form)
    ]
    return max(bounds)


def operations(calibrations):
    """Arithmetic per frame of the float evaluation: multiplications, additions (and
    subtractions) and divisions, summed over the units.

    Returns
    -------
    dict
        ``mul``, ``add``, ``div``.
    """
    counts = {"mul": 0, "add": 0, "div": 0}
    for _, form, thermal in unit_forms(calibrations):
        terms = form.terms
        top = [max(t[i] for t in terms) for i in (0, 1)]
        counts["mul"] += 2 + sum(max(k - 1, 0) for k in top)  # u, powers
        counts["add"] += 2  # v - centre
        counts["mul"] += 2 * sum(bool(a) + bool(b) for a, b in terms)  # coefficient × powers
        counts["add"] += 2 * (len(terms) - 1)
        if thermal is not None:  # per sensor: Vcc − (Vcc − v − d·dt) / (1 + dt·(c + q·dt))
            counts["add"] += 1 + 2 * 5
            counts["mul"] += 2 * 3
            counts["div"] += 2
    return counts


def code_size(header, name="ro"):
    """Bytes of machine code of the header's functions, compiled with ``-Os``.

    ``arm-none-eabi-gcc -mcpu=cortex-m4 -mthumb -mfloat-abi=hard -mfpu=fpv4-sp-d16`` where it is
    installed, else the system's ``cc`` for the host.

    Returns
    -------
    (str, dict) or None
        The compiler as run and the text bytes of each of the float and the fixed-point
        dispatch with their unit functions; None without a C compiler.
    """
    arm = shutil.which("arm-none-eabi-gcc")
    cc = arm or shutil.which("cc")
    size = shutil.which("arm-none-eabi-size" if arm else "size")
    if cc is None or size is None:
        return None
    flags = ["-mcpu=cortex-m4", "-mthumb", "-mfloat-abi=hard", "-mfpu=fpv4-sp-d16"] if arm else []
    out = {}
    with tempfile.TemporaryDirectory() as work:
        (Path(work) / "calibration.h").write_text(header, encoding="utf-8")
        for kind, call in (
            ("float", f"return {name}_angles_f(u, a[0], a[1], a[2], o);"),
            ("fixed", f"return {name}_angles_q(u, b[0], b[1], b[2], p);"),
        ):
            source = Path(work) / f"{kind}.c"
            source.write_text(
                '#include "calibration.h"\n'
                "int eval(int u, const RO_REAL *a, const int32_t *b, RO_REAL *o, int32_t *p)\n"
                f"{{ (void)a; (void)b; (void)o; (void)p; {call} }}\n",
                encoding="utf-8",
            )
            obj = source.with_suffix(".o")
            subprocess.run([cc, "-std=c99", "-Os", *flags, "-c", source, "-o", obj], check=True)
            text = subprocess.run([size, obj], check=True, capture_output=True, text=True).stdout
            out[kind] = int(text.splitlines()[1].split()[0])
    return (f"{Path(cc).name} -Os {' '.join(flags)}".strip(), out)
