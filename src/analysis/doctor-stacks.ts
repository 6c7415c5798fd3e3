/**
 * What each flight stack needs to be told, and what its own decoder will make of a stream.
 *
 * Every setting name and value below was checked against that stack's own source or
 * documentation (read 2026-11-23); the source is cited beside each entry. Settings change
 * between releases: the citations say which file to re-read when they do.
 */
import { systemInfo, type Resolution } from '../decoder/index.js';

export type FlightStack = 'Betaflight' | 'iNav' | 'ArduPilot' | 'PX4';

/** What one stack should be set to, as lines a user can paste, and a note. */
export interface StackSetting {
  stack: FlightStack;
  /** CLI lines (Betaflight, iNav) or parameter assignments (ArduPilot, PX4); empty when there is nothing to set. */
  lines: string[];
  note: string;
}

// Betaflight `serialrx_provider` values: lookupTableSerialRX in betaflight/betaflight
//   src/main/cli/settings.c ("SPEK1024", "SPEK2048", "SBUS", …, "IBUS", …, "CRSF", "SRXL", …, "SRXL2", …),
//   also `serialrx_inverted` (OFF/ON) and `spektrum_sat_bind` (SPEKTRUM_SAT_BIND_DISABLED 0 …
//   SPEKTRUM_SAT_BIND_MAX 10, src/main/rx/spektrum.h) in the same file's valueTable.
//   `spektrum_sat_bind` is the number of bind pulses sent at power-up (1–10), so the spec's §7.2
//   pulse counts are its values: https://betaflight.com/docs/development/Spektrum-bind
// iNav `serialrx_provider`: table `serial_rx` in iNavFlight/inav src/main/fc/settings.yaml
//   ["SPEK1024", "SPEK2048", "SBUS", "SUMD", "IBUS", "JETIEXBUS", "CRSF", "FPORT", "SBUS_FAST",
//   "FPORT2", "SRXL2", "GHST", "MAVLINK", "FBUS", "SBUS2"] (no SRXL v1), with `receiver_type`
//   SERIAL, `serialrx_inverted` and `spektrum_sat_bind` (0 … SPEKTRUM_SAT_BIND_MAX, condition
//   USE_SPEKTRUM_BIND) in group PG_RX_CONFIG of the same file.
// ArduPilot detects the serial RC protocol by itself ("ArduPilot automatically discovers the
//   serial protocol being used": https://ardupilot.org/copter/docs/common-spektrum-rc.html);
//   RC_PROTOCOLS only narrows it (https://ardupilot.org/copter/docs/common-rc-options.html).
//   Its DSM decoder: ArduPilot/ardupilot libraries/AP_RCProtocol/AP_RCProtocol_DSM.cpp.
// PX4's rc_input auto-selects among PPM, SBUS, DSM, SUMD, ST24 and CRSF
//   (https://docs.px4.io/main/en/modules/modules_driver_radio_control); its DSM decoder is
//   PX4/PX4-Autopilot src/lib/rc/dsm.cpp.

/** A foreign protocol the doctor can name. */
export type ForeignProtocol = 'srxl-v1' | 'srxl2' | 'ibus' | 'sbus' | 'crsf';

/** The provider to select for a protocol in each stack: `null` where the stack has none. */
export const PROTOCOL_SETTINGS: Readonly<Record<ForeignProtocol, { name: string; betaflight: string | null; inav: string | null; ardupilot: boolean; px4: boolean }>> = {
  // Betaflight "SRXL"; iNav's serial_rx table has no SRXL v1. ArduPilot has an SRXL decoder
  // (AP_RCProtocol_SRXL.cpp); PX4's rc_input list has none.
  'srxl-v1': { name: 'Spektrum SRXL (v1)', betaflight: 'SRXL', inav: null, ardupilot: true, px4: false },
  'srxl2': { name: 'Spektrum SRXL2', betaflight: 'SRXL2', inav: 'SRXL2', ardupilot: true, px4: false },
  'ibus': { name: 'FlySky IBUS', betaflight: 'IBUS', inav: 'IBUS', ardupilot: true, px4: false },
  'sbus': { name: 'SBUS', betaflight: 'SBUS', inav: 'SBUS', ardupilot: true, px4: true },
  'crsf': { name: 'CRSF (Crossfire / ExpressLRS)', betaflight: 'CRSF', inav: 'CRSF', ardupilot: true, px4: true },
};

/** The settings for a flight controller that should read `protocol` instead of a satellite. */
export function foreignSettings(protocol: ForeignProtocol): StackSetting[] {
  const p = PROTOCOL_SETTINGS[protocol];
  const bf: StackSetting = p.betaflight !== null
    ? { stack: 'Betaflight', lines: [`set serialrx_provider = ${p.betaflight}`, 'save'], note: `Ports tab: Serial RX on the receiver's UART; Receiver tab: ${p.betaflight}.` }
    : { stack: 'Betaflight', lines: [], note: `Betaflight has no ${p.name} provider.` };
  const inav: StackSetting = p.inav !== null
    ? { stack: 'iNav', lines: ['set receiver_type = SERIAL', `set serialrx_provider = ${p.inav}`, 'save'], note: `Ports tab: Serial RX on the receiver's UART.` }
    : { stack: 'iNav', lines: [], note: `iNav has no ${p.name} provider (its serial_rx table lists none): use SRXL2 or a satellite output instead.` };
  return [
    bf,
    inav,
    { stack: 'ArduPilot', lines: [], note: p.ardupilot ? `Detected by itself on the RC input (RC_PROTOCOLS left to detect all).` : `Not among ArduPilot's RC protocols.` },
    { stack: 'PX4', lines: [], note: p.px4 ? `rc_input selects ${p.name} by itself.` : `PX4's rc_input does not read ${p.name} (it reads PPM, SBUS, DSM, SUMD, ST24, CRSF).` },
  ];
}

/** The §7.2 bind pulses for a mode: DSMX 22 ms 7/8, DSMX 11 ms 9/10, DSM2 22 ms 3/4, DSM2 11 ms 5/6 (internal/external). */
export function bindPulses(protocol: 'DSM2' | 'DSMX', periodMs: 11 | 22, remote: 'internal' | 'external'): number {
  const base = protocol === 'DSMX' ? (periodMs === 11 ? 9 : 7) : (periodMs === 11 ? 5 : 3);
  return base + (remote === 'external' ? 1 : 0);
}

/** What the doctor knows of a satellite stream when it gives settings. */
export interface StreamFacts {
  resolution: Resolution;
  /** 11000 or 22000 µs, or NaN. */
  periodUs: number;
  remote: 'internal' | 'external';
  /** The internal remote's system byte, or null. */
  system: number | null;
}

/**
 * The satellite settings for Betaflight and iNav: the provider that matches the stream's
 * resolution, and the bind number for the mode §7.2 recommends (DSMX 11 ms: 9 internal,
 * 10 external). A DSM2-only satellite (SPM9545) cannot bind DSMX: the note says so.
 */
export function satelliteSettings(s: StreamFacts): StackSetting[] {
  const provider = s.resolution === 2048 ? 'SPEK2048' : 'SPEK1024';
  const recommended = bindPulses('DSMX', 11, s.remote);
  const info = s.system !== null ? systemInfo(s.system) : undefined;
  const current = info !== undefined ? bindPulses(info.protocol, info.periodMs, s.remote) : null;
  const rebind = `To bind again in DSMX 11 ms (spec §7.2), set spektrum_sat_bind = ${recommended} (${s.remote}), save, power-cycle the flight controller, bind, then set it back to 0.`;
  const now = current !== null ? ` It is bound now as ${info?.name ?? '?'} ${s.remote} (${current} pulses).` : '';
  const lines = [`set serialrx_provider = ${provider}`, 'save'];
  return [
    { stack: 'Betaflight', lines, note: `${provider} reads ${s.resolution}-resolution frames.${now} ${rebind}` },
    { stack: 'iNav', lines: ['set receiver_type = SERIAL', ...lines], note: `${provider} reads ${s.resolution}-resolution frames.${now} ${rebind}` },
  ];
}

// ---------------------------------------------------------------------------------------------
// The 10/11-bit guess ArduPilot and PX4 make
// ---------------------------------------------------------------------------------------------

/**
 * ArduPilot (AP_RCProtocol_DSM.cpp `dsm_guess_format`) and PX4 (dsm.cpp `dsm_guess_format`)
 * do not trust the system byte for the resolution: they decode every slot of a few frames both
 * as 10-bit (channel = word >> 10 & 0xF) and as 11-bit (word >> 11 & 0xF; PX4 adds the X-Plus
 * sub-ID), OR the channel numbers into a bit set each, and accept a reading only when its set is
 * one of these: 6, 7, 8, 9, 10, 13 or 14 channels from 0 up. Anything else resets the guess.
 */
export const GUESS_MASKS: readonly number[] = [0x3f, 0x7f, 0xff, 0x1ff, 0x3ff, 0x1fff, 0x3fff];

/** Which reading a guess over some frames settles on. */
export type GuessOutcome = 10 | 11 | 'none';

/**
 * Replays both stacks' guess over the frames a remote sends. ArduPilot decides after 6 frames
 * (`samples++ < 5`), PX4 after 5 (`samples < 5` after the increment); both start over when no
 * reading or both match. The last outcome of each, and how often each settled, are kept.
 */
export class StackGuess {
  #cs10 = 0;
  #cs11 = 0;
  #cs11px4 = 0;
  #samples = 0;
  /** Decisions made so far, by outcome, per stack. */
  readonly ardupilot = { 10: 0, 11: 0, none: 0 };
  readonly px4 = { 10: 0, 11: 0, none: 0 };
  /** Channel sets of the last decision window, for the evidence. */
  last10 = 0;
  last11 = 0;

  /** One frame's seven raw slot words. */
  frame(words: ArrayLike<number>): void {
    for (let i = 0; i < 7; i++) {
      const raw = words[i] as number;
      if (raw === 0xffff) continue;
      this.#cs10 |= 1 << ((raw >> 10) & 0xf);
      const c11 = (raw >> 11) & 0xf;
      this.#cs11 |= 1 << c11;
      // PX4 decodes X-Plus in its 11-bit reading: channel 12 + sub-ID (bits 9–10).
      this.#cs11px4 |= 1 << (c11 === 12 ? 12 + ((raw >> 9) & 3) : c11);
    }
    this.#samples++;
    if (this.#samples === 5) this.#decide(this.px4, this.#cs10, this.#cs11px4);
    if (this.#samples === 6) {
      this.#decide(this.ardupilot, this.#cs10, this.#cs11);
      this.last10 = this.#cs10;
      this.last11 = this.#cs11;
      this.#cs10 = 0;
      this.#cs11 = 0;
      this.#cs11px4 = 0;
      this.#samples = 0;
    }
  }

  #decide(into: { 10: number; 11: number; none: number }, cs10: number, cs11: number): void {
    const v10 = GUESS_MASKS.includes(cs10) ? 1 : 0;
    const v11 = GUESS_MASKS.includes(cs11) ? 1 : 0;
    if (v11 === 1 && v10 === 0) into[11]++;
    else if (v10 === 1 && v11 === 0) into[10]++;
    else into.none++;
  }
}

/** The channel numbers in a bit set, e.g. "0–11" or "0–9, 12". */
export function channelSetText(mask: number): string {
  const parts: string[] = [];
  for (let c = 0; c < 16; c++) {
    if (((mask >> c) & 1) === 0) continue;
    let end = c;
    while (end + 1 < 16 && ((mask >> (end + 1)) & 1) === 1) end++;
    parts.push(end === c ? `${c}` : `${c}–${end}`);
    c = end;
  }
  return parts.join(', ') || 'none';
}

/**
 * PX4 (dsm.cpp `dsm_decode`) checks byte 1 of every frame against the system values it knows
 * (0x01 needs the 10-bit reading, 0x12/0xA2/0xB2 the 11-bit one; a mismatch resets its guess)
 * and drops any frame whose byte 1 is another value, such as an external remote's fade count.
 */
export function px4AcceptsSystemByte(byte1: number): boolean {
  return byte1 === 0x01 || byte1 === 0x12 || byte1 === 0xa2 || byte1 === 0xb2;
}
