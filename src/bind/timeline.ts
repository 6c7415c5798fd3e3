/**
 * The power-cycle timeline a WebSerial driver runs to bind: open at the pulse rate, switch the
 * satellite off through RTS or DTR, on again (t0), write the pulses in the bind window, then
 * reopen at 115200 to watch the bind take. Pure data: it says what to do and when; the driver
 * (src/worker/bind.ts) does it. Wiring: docs/bind-wiring.md.
 */
import { adapterChips, type UsbIds, type UsbSerialChip } from './chips.js';
import { BIND_WINDOW, bindMode, checkPulses } from './modes.js';
import { fmtUs, planPulses, type PulsePlan } from './plan.js';
import type { StopBits } from './uart.js';

/** The subset of WebSerial's SerialOutputSignals this module sets. */
export interface OutputSignals {
  dataTerminalReady?: boolean;
  requestToSend?: boolean;
  break?: boolean;
}

export type PowerLine = 'rts' | 'dtr';

/**
 * How the switch reacts to the modem line. USB-serial chips drive RTS#/DTR# active low:
 * `setSignals({ requestToSend: true })` asserts RTS, which puts the RTS# pin at 0 V;
 * `false` puts it at VCCIO. With the P-MOSFET high-side switch of docs/bind-wiring.md the
 * satellite is powered while the line is asserted ('asserted', the default); an NPN-inverted
 * switch or a regulator whose enable is active high powers it while deasserted.
 */
export type PowerPolarity = 'asserted' | 'deasserted';

/** The setSignals() argument that switches the satellite on or off. */
export function powerSignals(powerLine: PowerLine, on: boolean, polarity: PowerPolarity = 'asserted'): OutputSignals {
  const asserted = polarity === 'asserted' ? on : !on;
  return powerLine === 'rts' ? { requestToSend: asserted } : { dataTerminalReady: asserted };
}

interface StepBase {
  /** When to start the step, ms from the start of the sequence. */
  readonly atMs: number;
  /** The same time relative to power-on (t0); negative before it. */
  readonly sincePowerOnMs: number;
  readonly note: string;
}
export type BindStep =
  | (StepBase & {
      readonly action: 'open';
      readonly baudRate: number;
      readonly stopBits: StopBits;
      readonly dataBits: 8;
      readonly parity: 'none';
      readonly flowControl: 'none';
    })
  | (StepBase & { readonly action: 'power-off'; readonly signals: OutputSignals })
  | (StepBase & { readonly action: 'power-on'; readonly signals: OutputSignals })
  | (StepBase & { readonly action: 'write'; readonly bytes: Uint8Array; readonly durationUs: number })
  | (StepBase & { readonly action: 'reopen'; readonly baudRate: number; readonly signals: OutputSignals });

export interface TimelineOptions {
  /** Which modem line switches the satellite's 3.3 V. */
  powerLine: PowerLine;
  /** Default 'asserted' (P-MOSFET gate on the active-low pin). */
  polarity?: PowerPolarity;
  /**
   * Power off this long before power-on, ms (default 500, as PX4; at least 200). The satellite
   * must really reset; the gate hold-up of the recommended switch (1 MΩ · 100 nF) keeps it on
   * for ~50–170 ms after the line drops, so 500 ms leaves ≥ 330 ms really off.
   */
  offMs?: number;
  /** From power-on to the write, ms (default 60, as Betaflight; 20–~195 allowed). */
  settleMs?: number;
  /** From the end of the pulses to the reopen at `liveBaudRate`, ms (default 20). */
  reopenAfterMs?: number;
  /** Rate for watching the bind take (default 115200, spec §7.1). */
  liveBaudRate?: number;
  /**
   * Hold TX low (break) while the satellite is off, released at power-on. Only for the bare
   * series-resistor wiring, where an idle-high TX would feed the unpowered satellite through
   * its DATA pin's clamp diode; the diode wiring needs nothing.
   */
  holdTxLowWhileOff?: boolean;
  /** The pulses (default planPulses(n)). */
  plan?: PulsePlan;
}

/**
 * The steps a driver runs, in order, each no earlier than its `atMs` (and after the previous
 * one finished): open at the bind rate, power off, power on (t0), write the pulses t0 + settle,
 * then close and reopen at 115200 with the power line re-asserted at once.
 */
export function bindTimeline(n: number, options: TimelineOptions): BindStep[] {
  checkPulses(n);
  const polarity = options.polarity ?? 'asserted';
  const offMs = options.offMs ?? 500;
  const settleMs = options.settleMs ?? BIND_WINDOW.recommendedMs;
  const reopenAfterMs = options.reopenAfterMs ?? 20;
  const liveBaudRate = options.liveBaudRate ?? 115_200;
  const plan = options.plan ?? planPulses(n);
  if (options.powerLine !== 'rts' && options.powerLine !== 'dtr')
    throw new RangeError(`power line must be 'rts' or 'dtr', not ${String(options.powerLine)}`);
  if (plan.pulses !== n) throw new RangeError(`the plan is for ${plan.pulses} pulses, not ${n}`);
  if (!(offMs >= 200)) throw new RangeError(`power must stay off ≥ 200 ms, not ${offMs}`);
  const pulsesMs = plan.totalUs / 1000;
  if (!(settleMs >= 0) || settleMs + pulsesMs > BIND_WINDOW.latestMs) {
    throw new RangeError(
      `pulses must start after power-on and end within ${BIND_WINDOW.latestMs} ms; settle ${settleMs} ms + ${pulsesMs.toFixed(2)} ms does not`,
    );
  }
  if (!(reopenAfterMs >= 0)) throw new RangeError(`reopenAfterMs must be ≥ 0, not ${reopenAfterMs}`);

  const line = options.powerLine === 'rts' ? 'RTS' : 'DTR';
  const holdBreak = options.holdTxLowWhileOff === true;
  const off = { ...powerSignals(options.powerLine, false, polarity), ...(holdBreak ? { break: true } : {}) };
  const on = { ...powerSignals(options.powerLine, true, polarity), ...(holdBreak ? { break: false } : {}) };
  const t0 = offMs;
  const writeAt = t0 + settleMs;
  const reopenAt = writeAt + Math.ceil(pulsesMs) + reopenAfterMs;
  const selected = bindMode(n);
  const pinLevel = (powered: boolean) => ((polarity === 'asserted') === powered ? 'low (asserted)' : 'high (deasserted)');
  return [
    {
      atMs: 0,
      sincePowerOnMs: -t0,
      action: 'open',
      baudRate: plan.baudRate,
      stopBits: plan.stopBits,
      dataBits: 8,
      parity: 'none',
      flowControl: 'none',
      note:
        `Close the port if it is open, then open it at ${plan.baudRate} baud 8${plan.stopBits === 1 ? 'N1' : 'N2'}. ` +
        'Opening asserts DTR and RTS (the OS does it on Linux and macOS, Chromium on Windows), which may switch the satellite on for a moment; the next step switches it off.',
    },
    {
      atMs: 0,
      sincePowerOnMs: -t0,
      action: 'power-off',
      signals: off,
      note:
        `setSignals(${JSON.stringify(off)}): ${line}# pin ${pinLevel(false)}, satellite off for ${offMs} ms so it really resets` +
        (holdBreak ? '; break holds TX low so it cannot feed the unpowered satellite.' : '.'),
    },
    {
      atMs: t0,
      sincePowerOnMs: 0,
      action: 'power-on',
      signals: on,
      note: `t0. setSignals(${JSON.stringify(on)}): ${line}# pin ${pinLevel(true)}, satellite powered. Time the next step from when this promise resolves.`,
    },
    {
      atMs: writeAt,
      sincePowerOnMs: settleMs,
      action: 'write',
      bytes: plan.bytes,
      durationUs: plan.totalUs,
      note:
        `One write() of ${plan.bytes.length} byte${plan.bytes.length === 1 ? '' : 's'} (one USB packet): ${n} low pulses of ${fmtUs(plan.lowUs[0]!)} µs, ` +
        `${pulsesMs.toFixed(2)} ms on the wire, ending ${(settleMs + pulsesMs).toFixed(1)} ms after power-on (window ${BIND_WINDOW.earliestMs}–${BIND_WINDOW.latestMs} ms). ${selected.description}`,
    },
    {
      atMs: reopenAt,
      sincePowerOnMs: reopenAt - t0,
      action: 'reopen',
      baudRate: liveBaudRate,
      signals: on,
      note:
        `await writer.close() (drains the bytes), close(), open at ${liveBaudRate} 8N1 and at once setSignals(${JSON.stringify(on)}). ` +
        `close() drops DTR and RTS (HUPCL on Linux and macOS, most Windows drivers): the switch's gate hold-up must bridge the gap, or the bind is cancelled. ` +
        'The satellite blinks while it waits for the transmitter; frames appear once the bind takes.',
    },
  ];
}

/** The bind an adapter gets: its pulse plan, its steps, and the chips they were made for. */
export interface AdapterBind {
  readonly plan: PulsePlan;
  readonly steps: BindStep[];
  /** The chips the plan was made for: the adapter's, or DEFAULT_CHIPS when its USB IDs are unknown. */
  readonly chips: readonly UsbSerialChip[];
  /** Whether the USB IDs named the chips (false: DEFAULT_CHIPS stood in). */
  readonly chipsKnown: boolean;
}

/**
 * The bind for the adapter with these USB IDs (`port.getInfo()`): pulses planned for the chips
 * the IDs name (DEFAULT_CHIPS when they name none), and the timeline around them. The worker
 * runs exactly this and the page previews exactly this, so what the page shows is what goes on
 * the wire.
 */
export function bindForAdapter(n: number, usb: UsbIds, options: Omit<TimelineOptions, 'plan'>): AdapterBind {
  const { chips, known } = adapterChips(usb);
  const plan = planPulses(n, { chips });
  return { plan, steps: bindTimeline(n, { ...options, plan }), chips, chipsKnown: known };
}
