/*
 * A sensor board's side of the device protocol (docs/robot.md, "A firmware example"): read
 * each unit's detectors in one of the drive schemes reflector-opt models and send one binary
 * frame of raw ADC codes per call, with the CRC-16/CCITT-FALSE the decoder checks.
 *
 * Configure with -D (or edit the defaults below), then implement the board functions declared
 * at the end for the board: board_arduino.ino for an Arduino-class board, board_host.h for a
 * PC (the tests).
 */
#ifndef RO_SENSOR_H
#define RO_SENSOR_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* The drive schemes (reflector_opt.model._drive, docs/conditions.md "Drive schemes"). */
#define RO_DC 0          /* every LED on all the time; the detectors read in turn */
#define RO_MULTIPLEXED 1 /* one LED on at a time, its own detector read while it is on */
#define RO_MODULATED 2   /* as multiplexed, read LED on and LED off; Vcc - (off - on) sent */

#ifndef RO_UNITS
#define RO_UNITS 2 /* units per frame, base first */
#endif
#ifndef RO_SENSORS
#define RO_SENSORS 2 /* sensors (LED and detector) per unit */
#endif
#ifndef RO_ADC_BITS
#define RO_ADC_BITS 10 /* the ADC's resolution, bits (1 ... 16) */
#endif
#ifndef RO_DRIVE
#define RO_DRIVE RO_MULTIPLEXED
#endif
#ifndef RO_TEMPERATURE
#define RO_TEMPERATURE 0 /* 1: each unit's temperature follows the readings */
#endif
#ifndef RO_VCC_CODE
#define RO_VCC_CODE ((1u << RO_ADC_BITS) - 1u) /* the supply as a code (ratiometric ADC) */
#endif
#ifndef RO_SETTLE_US
#define RO_SETTLE_US 0 /* wait after an LED changes before the conversion, us */
#endif
#ifndef RO_CRC_POLY
#define RO_CRC_POLY 0x1021u /* CRC-16/CCITT-FALSE: polynomial 0x1021, initial 0xFFFF */
#endif

#define RO_CHANNELS (RO_UNITS * RO_SENSORS)
/* Sync word, counter, one uint16 code per channel, int16 temperatures, CRC. */
#define RO_FRAME_BYTES (2 + 2 + 2 * RO_CHANNELS + 2 * RO_UNITS * RO_TEMPERATURE + 2)

/* The board: channel c = unit * RO_SENSORS + sensor is detector c's ADC input and LED c. */
uint16_t board_adc_read(uint8_t channel);
void board_led(uint8_t led, uint8_t on);
void board_wait_us(uint16_t us);
int16_t board_temperature_centi_c(uint8_t unit); /* 0.01 degC; read with RO_TEMPERATURE */
void board_serial_write(const uint8_t *data, uint16_t n);

/* CRC-16 (RO_CRC_POLY, initial 0xFFFF, no reflection) of n bytes. */
uint16_t ro_crc16(const uint8_t *data, uint16_t n);
/* Read every channel in the drive scheme into codes[RO_CHANNELS]. */
void ro_read(uint16_t *codes);
/* Read, build frame `counter` into frame[RO_FRAME_BYTES] and send it. */
void ro_send_frame(uint16_t counter, uint8_t *frame);

#ifdef __cplusplus
}
#endif

#endif
