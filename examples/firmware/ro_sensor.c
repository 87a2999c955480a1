/* The sensor board's frames (ro_sensor.h). C99, no allocation, no floating point. */
#include "ro_sensor.h"

uint16_t ro_crc16(const uint8_t *data, uint16_t n)
{
    uint16_t crc = 0xFFFFu;
    for (uint16_t i = 0; i < n; i++) {
        crc ^= (uint16_t)(data[i] << 8);
        for (uint8_t bit = 0; bit < 8; bit++)
            crc = (crc & 0x8000u) ? (uint16_t)((crc << 1) ^ RO_CRC_POLY) : (uint16_t)(crc << 1);
    }
    return crc;
}

#define RO_MAX_CODE ((1L << RO_ADC_BITS) - 1)

#if RO_DRIVE == RO_DC
void ro_read(uint16_t *codes)
{
    for (uint8_t c = 0; c < RO_CHANNELS; c++)
        board_led(c, 1); /* every LED on, and left on */
    board_wait_us(RO_SETTLE_US);
    for (uint8_t c = 0; c < RO_CHANNELS; c++)
        codes[c] = board_adc_read(c);
}
#elif RO_DRIVE == RO_MULTIPLEXED || RO_DRIVE == RO_MODULATED
void ro_read(uint16_t *codes)
{
    for (uint8_t c = 0; c < RO_CHANNELS; c++) {
        board_led(c, 1); /* LED c alone */
        board_wait_us(RO_SETTLE_US);
        int32_t code = board_adc_read(c);
        board_led(c, 0);
#if RO_DRIVE == RO_MODULATED
        board_wait_us(RO_SETTLE_US);
        code = (int32_t)RO_VCC_CODE - ((int32_t)board_adc_read(c) - code); /* Vcc - (off - on) */
        code = code < 0 ? 0 : code > RO_MAX_CODE ? RO_MAX_CODE : code;
#endif
        codes[c] = (uint16_t)code;
    }
}
#else
#error "RO_DRIVE: RO_DC, RO_MULTIPLEXED or RO_MODULATED"
#endif

static uint8_t *put16(uint8_t *p, uint16_t v)
{
    p[0] = (uint8_t)(v & 0xFFu); /* little-endian */
    p[1] = (uint8_t)(v >> 8);
    return p + 2;
}

void ro_send_frame(uint16_t counter, uint8_t *frame)
{
    uint16_t codes[RO_CHANNELS];
    uint8_t *p = frame;
    ro_read(codes);
    *p++ = 0xA5; /* the sync word */
    *p++ = 0x5A;
    p = put16(p, counter);
    for (uint8_t c = 0; c < RO_CHANNELS; c++)
        p = put16(p, codes[c]);
#if RO_TEMPERATURE
    for (uint8_t u = 0; u < RO_UNITS; u++)
        p = put16(p, (uint16_t)board_temperature_centi_c(u));
#endif
    put16(p, ro_crc16(frame + 2, (uint16_t)(p - frame - 2)));
    board_serial_write(frame, RO_FRAME_BYTES);
}
