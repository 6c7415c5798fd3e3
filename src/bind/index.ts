/**
 * Binding a Spektrum satellite through a USB-serial adapter (spec Rev G §7.2). Within 200 ms of
 * power-up the satellite's DATA line must get N falling pulses (3–10); N picks the bind mode. A
 * page cannot bit-bang them, but the adapter's TX line can draw them with well-chosen bytes, and
 * its RTS or DTR line can switch the satellite's power. Pure ECMAScript: no DOM, no Node, no
 * timers. Wiring: docs/bind-wiring.md and ./wiring.svg. One file per concept:
 *
 * - modes.ts: the §7.2 bind modes, and the pulse widths and window the satellite accepts.
 * - chips.ts: USB-serial adapters: the one table of USB IDs and names, each chip's real baud rate.
 * - uart.ts: the TX line bit by bit: frames, waveform, edges, pulse widths.
 * - plan.ts: the bytes and baud rate that draw the pulses on every chip, and checking a plan.
 * - timeline.ts: the power-cycle timeline, the power line's signals, and the bind an adapter gets.
 *
 * Every export is named here; the few helpers the files share among themselves are not.
 */
export {
  BIND_MODES,
  BIND_PULSE_MAX_US,
  BIND_PULSE_MIN_US,
  BIND_PULSE_TARGET_US,
  BIND_WINDOW,
  MAX_BIND_PULSES,
  MIN_BIND_PULSES,
  bindMode,
  bindPulsesFor,
  type BindMode,
} from './modes.js';
export {
  CHIP_NAMES,
  DEFAULT_CHIPS,
  USB_SERIAL_CHIPS,
  USB_SERIAL_VENDORS,
  adapterChips,
  chipBaudRate,
  chipsForUsbId,
  portName,
  type UsbIds,
  type UsbSerialChip,
  type UsbSerialVendor,
} from './chips.js';
export {
  countFallingEdges,
  frameLevels,
  measurePulses,
  uartWaveform,
  type LineSegment,
  type PulseMeasurement,
  type StopBits,
} from './uart.js';
export { planPulses, type ChipRate, type PlanOptions, type PulsePlan } from './plan.js';
export { validatePlan, type PlanCheck, type ValidateOptions } from './check.js';
export {
  bindForAdapter,
  bindTimeline,
  powerSignals,
  type AdapterBind,
  type BindStep,
  type OutputSignals,
  type PowerLine,
  type PowerPolarity,
  type TimelineOptions,
} from './timeline.js';
