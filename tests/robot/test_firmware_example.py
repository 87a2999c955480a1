"""The firmware example (examples/firmware): ro_sensor.c built on the host with the system's C
compiler against the board stand-in (board_host.h) and a simulated ADC, its output decoded by
the package's decoder."""

import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from reflector_opt.robot import Protocol

FIRMWARE = Path(__file__).resolve().parents[2] / "examples" / "firmware"
CC = shutil.which("cc")
pytestmark = pytest.mark.skipif(CC is None, reason="no system C compiler (cc)")
UNITS, SENSORS, BITS, VCC_CODE = 2, 2, 10, 1023

#: The simulated ADC: channel c reads its dark level less what each lit LED l drops it by, both
#: changing with the frame k; prints frames k = 0 … n − 1 with counters from `start`.
DRIVER = r"""
#include <stdlib.h>
#include <string.h>
#include "board_host.h"
static uint32_t k;
static int32_t dark(uint8_t c) { return 900 + 7 * c + (int32_t)(k % 50); }
static int32_t drop(uint8_t c, uint8_t l)
{
    return l == c ? 200 + 10 * c + (int32_t)(k % 100) : 5 + l;
}
uint16_t host_adc(uint8_t c, uint32_t lit)
{
    int32_t code = dark(c);
    for (uint8_t l = 0; l < RO_CHANNELS; l++)
        if (lit & (1ul << l))
            code -= drop(c, l);
    return (uint16_t)code;
}
int16_t host_temperature_centi_c(uint8_t unit) { return (int16_t)(2500 + 10 * unit - k % 7); }
int main(int argc, char **argv)
{
    uint8_t frame[RO_FRAME_BYTES];
    uint32_t n = (uint32_t)atol(argv[1]), start = (uint32_t)atol(argv[2]);
    if (argc > 3) { /* the CRC of argv[3] */
        printf("%04X", (unsigned)ro_crc16((const uint8_t *)argv[3], (uint16_t)strlen(argv[3])));
        return 0;
    }
    for (k = 0; k < n; k++)
        ro_send_frame((uint16_t)(start + k), frame);
    return 0;
}
"""


def _expected(scheme, k):
    """Each channel's code by hand: dc, every LED lit (its own and every other's drop);
    multiplexed, its own LED only; modulated, Vcc − (dark − (dark − own drop))."""
    channels = np.arange(UNITS * SENSORS)
    dark = 900 + 7 * channels + k % 50
    own = 200 + 10 * channels + k % 100
    others = np.array([sum(5 + m for m in channels if m != c) for c in channels])
    code = {"dc": dark - own - others, "multiplexed": dark - own, "modulated": VCC_CODE - own}
    return code[scheme].reshape(UNITS, SENSORS)


def _run(tmp_path, scheme, n, start=0, *defines, crc_of=()):
    (tmp_path / "driver.c").write_text(DRIVER, encoding="utf-8")
    exe = tmp_path / f"sensor_{scheme}"
    flags = ["-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic", f"-I{FIRMWARE}"]
    config = [f"-DRO_UNITS={UNITS}", f"-DRO_ADC_BITS={BITS}", "-DRO_TEMPERATURE=1"]
    config += [f"-DRO_DRIVE=RO_{scheme.upper()}", *defines]
    sources = [tmp_path / "driver.c", FIRMWARE / "ro_sensor.c"]
    subprocess.run([CC, *flags, *config, *sources, "-o", exe], check=True)
    argv = [exe, str(n), str(start), *crc_of]
    return subprocess.run(argv, capture_output=True, check=True).stdout


@pytest.mark.parametrize("scheme", ["dc", "multiplexed", "modulated"])
def test_each_drive_scheme_s_frames_decode_to_the_simulated_adc(tmp_path, scheme):
    """300 frames from counter 65,400 (so the counter wraps): every frame decodes with no fault,
    its counter the slot's modulo 65,536, its codes the scheme's by hand, its temperatures the
    simulated 0.01 °C."""
    protocol = Protocol(UNITS, SENSORS, temperature=True, adc_bits=BITS)
    data = _run(tmp_path, scheme, 300, 65_400)
    assert len(data) == 300 * protocol.frame_bytes
    decoder = protocol.decoder()
    frames = decoder.feed(data)
    decoder.close()
    assert [f.counter for f in frames] == [(65_400 + k) % 65_536 for k in range(300)]
    assert not any(decoder.faults.values()), decoder.faults
    for k, frame in enumerate(frames):
        np.testing.assert_array_equal(frame.readings, _expected(scheme, k))
        np.testing.assert_allclose(
            frame.temperature_c, (2500 + 10 * np.arange(UNITS) - k % 7) / 100
        )


def test_a_wrong_crc_polynomial_fails_every_frame(tmp_path):
    """The CRC is CRC-16/CCITT-FALSE: its check value for ``123456789`` is 0x29B1 (and
    :func:`binascii.crc_hqx`'s). The same firmware with CRC-16's other common polynomial
    (0x8005; check value 0xAEE7): no frame decodes, and each of the 50 is a checksum fault."""
    assert _run(tmp_path, "dc", 0, crc_of=["123456789"]) == b"29B1"
    wrong = _run(tmp_path, "dc", 0, 0, "-DRO_CRC_POLY=0x8005u", crc_of=["123456789"])
    assert wrong == b"AEE7"
    protocol = Protocol(UNITS, SENSORS, temperature=True, adc_bits=BITS)
    decoder = protocol.decoder()
    assert decoder.feed(_run(tmp_path, "multiplexed", 50, 0, "-DRO_CRC_POLY=0x8005u")) == []
    assert decoder.faults["checksum"] >= 50 and decoder.frames == 0
