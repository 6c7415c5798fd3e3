/**
 * Binding a Spektrum satellite through a USB-serial adapter: the §7.2 bind modes, the UART
 * bytes that draw the bind pulses, the chips' real baud rates, and the power-cycle timeline a
 * WebSerial driver runs. Pure ECMAScript. Wiring: docs/bind-wiring.md and ./wiring.svg.
 */
export {
  BIND_MODES, BIND_WINDOW, DEFAULT_CHIPS, MAX_BIND_PULSES, MIN_BIND_PULSES, BIND_PULSE_MAX_US, BIND_PULSE_MIN_US,
  BIND_PULSE_TARGET_US, USB_SERIAL_CHIPS,
  bindMode, bindPulsesFor, bindTimeline, chipBaudRate, chipsForUsbId, countFallingEdges, frameLevels,
  measurePulses, planPulses, powerSignals, uartWaveform, validatePlan,
  type BindMode, type BindStep, type ChipRate, type LineSegment, type OutputSignals, type PlanCheck,
  type PlanOptions, type PowerLine, type PowerPolarity, type PulseMeasurement, type PulsePlan, type StopBits,
  type TimelineOptions, type UsbSerialChip, type ValidateOptions,
} from './pulses.js';
