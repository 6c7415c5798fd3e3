/**
 * What the Bind panel shows before a bind, in a hobbyist's words: the bind the worker will run
 * on the chosen port (the same `bindForAdapter` call, with the port's USB IDs), the adapter it
 * was made for, and each step as "Power off", "Power on", "9 pulses".
 */
import {
  CHIP_NAMES,
  DEFAULT_CHIPS,
  bindForAdapter,
  type AdapterBind,
  type BindStep,
  type PowerLine,
  type PowerPolarity,
  type UsbIds,
} from '../../../bind/index.js';

export interface BindPreview extends AdapterBind {
  /** Which adapter the pulses were made for, and why, in plain words. */
  readonly adapter: string;
}

const names = (chips: readonly string[]) =>
  chips.length <= 1 ? (chips[0] ?? '') : `${chips.slice(0, -1).join(', ')} or ${chips.at(-1) ?? ''}`;

/**
 * The bind the worker will run for `pulses` on the port with these USB IDs (`port.getInfo()`),
 * or, with `usb` null (no port chosen yet), the one that works on every common adapter.
 */
export function bindPreview(pulses: number, usb: UsbIds | null, powerLine: PowerLine, polarity: PowerPolarity): BindPreview {
  const bind = bindForAdapter(pulses, usb ?? {}, { powerLine, polarity });
  const chips = bind.chips.map((c) => CHIP_NAMES[c]);
  const common = names(DEFAULT_CHIPS.map((c) => CHIP_NAMES[c]));
  let adapter: string;
  if (usb === null) {
    adapter =
      `No port chosen yet, so these pulses are the ones that work on every common adapter (${common}). ` +
      'Once you choose the port, they are made for its chip and shown here.';
  } else if (!bind.chipsKnown) {
    adapter = `SatScope does not know this adapter's chip, so the pulses are the ones that work on every common adapter (${common}).`;
  } else if (chips.length > 1) {
    adapter = `Pulses made for this adapter: a ${names(chips)} (they look the same over USB), so they suit each.`;
  } else {
    adapter = `Pulses made for this adapter's ${chips[0] ?? ''} chip.`;
  }
  return { ...bind, adapter };
}

/** A time on the bind's clock: "t0 + 60 ms", "t0 − 500 ms". */
export const sincePowerOn = (ms: number) => (ms >= 0 ? `t0 + ${ms.toFixed(0)} ms` : `t0 − ${(-ms).toFixed(0)} ms`);

/** A step as a hobbyist says it: what to call it, and what happens to the satellite. */
export function plainStep(step: BindStep, steps: readonly BindStep[], pulses: number): { name: string; what: string } {
  switch (step.action) {
    case 'open':
      return { name: 'Open the adapter', what: `The adapter is set up to draw the pulses (${step.baudRate} baud).` };
    case 'power-off': {
      const on = steps.find((x) => x.action === 'power-on');
      const offMs = on === undefined ? 0 : on.atMs - step.atMs;
      return { name: 'Power off', what: `The satellite is switched off for ${offMs.toFixed(0)} ms, so it starts afresh.` };
    }
    case 'power-on':
      return { name: 'Power on', what: 'The satellite is switched on. The time of every later step counts from here (t0).' };
    case 'write':
      return {
        name: `${pulses} pulses`,
        what: `${pulses} short pulses on the DATA wire, ${(step.durationUs / 1000).toFixed(1)} ms in all: the satellite enters bind mode and its light blinks fast.`,
      };
    case 'reopen':
      return {
        name: 'Back to reading',
        what: 'The adapter goes back to reading frames. Now put the transmitter in bind mode; frames appear once the bind takes.',
      };
  }
}
