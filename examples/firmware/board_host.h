/*
 * A stand-in for the board on a PC, for building ro_sensor.c on the host (the tests): the LEDs
 * are a bit mask, the serial port is standard output, the wait is nothing, and the ADC and
 * the temperature are the functions host_adc and host_temperature_centi_c the program defines
 * (a simulated ADC). Include it in one source file of the host program.
 */
#ifndef RO_BOARD_HOST_H
#define RO_BOARD_HOST_H

#include <stdio.h>

#include "ro_sensor.h"

/* The LEDs lit, bit c for LED c. */
static uint32_t host_lit;

/* The simulated ADC: channel's code with the LEDs `lit` lit. */
uint16_t host_adc(uint8_t channel, uint32_t lit);
int16_t host_temperature_centi_c(uint8_t unit);

uint16_t board_adc_read(uint8_t channel) { return host_adc(channel, host_lit); }
void board_led(uint8_t led, uint8_t on)
{
    host_lit = on ? host_lit | (1ul << led) : host_lit & ~(1ul << led);
}
void board_wait_us(uint16_t us) { (void)us; }
int16_t board_temperature_centi_c(uint8_t unit) { return host_temperature_centi_c(unit); }
void board_serial_write(const uint8_t *data, uint16_t n) { fwrite(data, 1, n, stdout); }

#endif
