/*
 * ro_sensor.c on an Arduino-class board (an Uno, a Nano: 10-bit ADC, 5 V): detector c on
 * analog input A0 + c, LED c on digital pin 2 + c, frames at 115200 Bd every 10 ms. Copy
 * ro_sensor.h and ro_sensor.c next to this sketch; the pins and the temperature are the board's
 * to adapt (here no temperature: RO_TEMPERATURE 0).
 */
#include "ro_sensor.h"

uint16_t board_adc_read(uint8_t channel) { return (uint16_t)analogRead(A0 + channel); }
void board_led(uint8_t led, uint8_t on) { digitalWrite(2 + led, on ? HIGH : LOW); }
void board_wait_us(uint16_t us) { delayMicroseconds(us); }
int16_t board_temperature_centi_c(uint8_t unit) { (void)unit; return 2500; }
void board_serial_write(const uint8_t *data, uint16_t n) { Serial.write(data, n); }

static uint8_t frame[RO_FRAME_BYTES];

void setup()
{
    for (uint8_t c = 0; c < RO_CHANNELS; c++)
        pinMode(2 + c, OUTPUT);
    Serial.begin(115200);
}

void loop()
{
    static unsigned long sent = (unsigned long)-1;
    unsigned long slot = millis() / 10; /* a frame every 10 ms, the counter its slot: */
    if (slot == sent)                   /* a missed slot is a gap the receiver counts */
        return;
    sent = slot;
    ro_send_frame((uint16_t)slot, frame);
}
