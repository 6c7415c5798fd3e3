/**
 * What each flight stack needs to be told, and what its own decoder will make of a stream.
 *
 * Every setting name and value below was checked against that stack's own source or
 * documentation (read 2026-11-23); the source is cited beside each entry. Settings change
 * between releases: the citations say which file to re-read when they do.
 */
import { systemInfo, type Resolution } from '../decoder/spec.js';

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
export type ForeignProtocol = 'srxl-v1' | 'srxl2' | 'ibus' | 'sbus' | 'crsf' | 'fport' | 'ghst';

/** The provider to select for a protocol in each stack: `null` where the stack has none. */
export const PROTOCOL_SETTINGS: Readonly<
  Record<ForeignProtocol, { name: string; betaflight: string | null; inav: string | null; ardupilot: boolean; px4: boolean }>
> = {
  // Betaflight "SRXL": its Spektrum reader (src/main/rx/spektrum.c) takes the 16 bytes after a
  // gap, and bytes 2–15 of an 0xA5 SRXL frame are the same seven channel words; iNav's serial_rx
  // table has no SRXL. ArduPilot reads 0xA5 frames ("Spk AR7700 etc.", SRXL_HEADER_V5 in
  // AP_RCProtocol_SRXL.h); PX4's rc_input list has none.
  'srxl-v1': { name: 'Spektrum SRXL (v1)', betaflight: 'SRXL', inav: null, ardupilot: true, px4: false },
  srxl2: { name: 'Spektrum SRXL2', betaflight: 'SRXL2', inav: 'SRXL2', ardupilot: true, px4: false },
  ibus: { name: 'FlySky IBUS', betaflight: 'IBUS', inav: 'IBUS', ardupilot: true, px4: false },
  sbus: { name: 'SBUS', betaflight: 'SBUS', inav: 'SBUS', ardupilot: true, px4: true },
  crsf: { name: 'CRSF (Crossfire / ExpressLRS)', betaflight: 'CRSF', inav: 'CRSF', ardupilot: true, px4: true },
  // Betaflight and iNav name both FPORT and GHST providers; ArduPilot has AP_RCProtocol_FPort and
  // AP_RCProtocol_GHST; PX4's rc_input reads neither.
  fport: { name: 'FrSky FPort', betaflight: 'FPORT', inav: 'FPORT', ardupilot: true, px4: false },
  ghst: { name: 'ImmersionRC Ghost (GHST)', betaflight: 'GHST', inav: 'GHST', ardupilot: true, px4: false },
};

/** The settings for a flight controller that should read `protocol` instead of a satellite. */
export function foreignSettings(protocol: ForeignProtocol): StackSetting[] {
  const p = PROTOCOL_SETTINGS[protocol];
  const bf: StackSetting =
    p.betaflight !== null
      ? {
          stack: 'Betaflight',
          lines: [`set serialrx_provider = ${p.betaflight}`, 'save'],
          note: `Ports tab: Serial RX on the receiver's UART; Receiver tab: ${p.betaflight}.`,
        }
      : { stack: 'Betaflight', lines: [], note: `Betaflight has no ${p.name} provider.` };
  const inav: StackSetting =
    p.inav !== null
      ? {
          stack: 'iNav',
          lines: ['set receiver_type = SERIAL', `set serialrx_provider = ${p.inav}`, 'save'],
          note: `Ports tab: Serial RX on the receiver's UART.`,
        }
      : {
          stack: 'iNav',
          lines: [],
          note: `iNav has no ${p.name} provider (its serial_rx table lists none): use SRXL2 or a satellite output instead.`,
        };
  return [
    bf,
    inav,
    {
      stack: 'ArduPilot',
      lines: [],
      note: p.ardupilot ? `Detected by itself on the RC input (RC_PROTOCOLS left to detect all).` : `Not among ArduPilot's RC protocols.`,
    },
    {
      stack: 'PX4',
      lines: [],
      note: p.px4
        ? `rc_input selects ${p.name} by itself.`
        : `PX4's rc_input does not read ${p.name} (it reads PPM, SBUS, DSM, SUMD, ST24, CRSF).`,
    },
  ];
}

/** The §7.2 bind pulses for a mode: DSMX 22 ms 7/8, DSMX 11 ms 9/10, DSM2 22 ms 3/4, DSM2 11 ms 5/6 (internal/external). */
export function bindPulses(protocol: 'DSM2' | 'DSMX', periodMs: 11 | 22, remote: 'internal' | 'external'): number {
  const base = protocol === 'DSMX' ? (periodMs === 11 ? 9 : 7) : periodMs === 11 ? 5 : 3;
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
    {
      stack: 'iNav',
      lines: ['set receiver_type = SERIAL', ...lines],
      note: `${provider} reads ${s.resolution}-resolution frames.${now} ${rebind}`,
    },
  ];
}

// ---------------------------------------------------------------------------------------------
// ArduPilot's 10/11-bit guess
// ---------------------------------------------------------------------------------------------

/**
 * ArduPilot does not trust the system byte for the resolution ("The encoding of the first two
 * bytes is uncertain, so we're going to ignore them"): it decodes the slots of 6 frames both as
 * 10-bit and as 11-bit (channel = word >> 10 or >> 11, & 0xF; 0xFFFF skipped; the last two
 * slots of a VTX frame skipped) and keeps the reading whose channel set is 0…n−1 for some
 * n = 5…16 when the other's is not; otherwise it starts over. Replayed here as written in
 * libraries/AP_RCProtocol/AP_RCProtocol_DSM.cpp at commit 814bbe4f (`dsm_guess_format`).
 *
 * PX4 also guesses from the channel IDs (src/lib/rc/dsm.cpp), but its rule has changed across
 * releases (masks, then channel-count statistics) in ways the versions read for this module do
 * not settle, so it is not replayed; the doctor says only what PX4's own tests pin down.
 */
export const ARDUPILOT_GUESS_FRAMES = 6;
const VTX_MASK = 0xf000f000;
const VTX_MARKER = 0xe000e000;

export interface GuessTally {
  10: number;
  11: number;
  none: number;
}

/** 0…n−1 with min ≤ n ≤ max: n, else 0. */
function contiguous(mask: number, min: number, max: number): number {
  let n = 0;
  while (n < 32 && ((mask >>> n) & 1) === 1) n++;
  if (n < min || n > max) return 0;
  return mask >>> n === 0 ? n : 0;
}

/** `ArduPilotGuess.checkpoint()`. */
export interface ArduPilotGuessCheckpoint {
  readonly outcomes: GuessTally;
  readonly last10: number;
  readonly last11: number;
  readonly cs10: number;
  readonly cs11: number;
  readonly samples: number;
}

/** Replays ArduPilot's guess over a remote's frames, window after window, and counts the outcomes. */
export class ArduPilotGuess {
  readonly outcomes: GuessTally = { 10: 0, 11: 0, none: 0 };
  /** Channel sets of the last window, for the evidence. */
  last10 = 0;
  last11 = 0;
  #cs10 = 0;
  #cs11 = 0;
  #samples = 0;

  /** The outcomes and the window in progress, as a copy. */
  checkpoint(): ArduPilotGuessCheckpoint {
    return {
      outcomes: { ...this.outcomes },
      last10: this.last10,
      last11: this.last11,
      cs10: this.#cs10,
      cs11: this.#cs11,
      samples: this.#samples,
    };
  }

  /** Back to where `checkpoint()` was taken. */
  restore(cp: ArduPilotGuessCheckpoint): void {
    Object.assign(this.outcomes, cp.outcomes);
    this.last10 = cp.last10;
    this.last11 = cp.last11;
    this.#cs10 = cp.cs10;
    this.#cs11 = cp.cs11;
    this.#samples = cp.samples;
  }

  /** One frame's seven raw slot words, as sent (`DecodedFrame.words`: bytes 2–15, big-endian). */
  frame(w: ArrayLike<number>): void {
    const vtx = ((((w[5] ?? 0) << 16) | (w[6] ?? 0)) & VTX_MASK) >>> 0 === VTX_MARKER && ((w[0] ?? 0) & 0x8000) === 0;
    const slots = vtx ? 5 : 7;
    for (let i = 0; i < slots; i++) {
      const raw = w[i] ?? 0;
      if (raw === 0xffff) continue;
      this.#cs10 |= 1 << ((raw >> 10) & 0xf);
      this.#cs11 |= 1 << ((raw >> 11) & 0xf);
    }
    if (this.#samples++ < ARDUPILOT_GUESS_FRAMES - 1) return;
    const v10 = contiguous(this.#cs10, 5, 16) > 0;
    const v11 = contiguous(this.#cs11, 5, 16) > 0;
    this.outcomes[v11 && !v10 ? 11 : v10 && !v11 ? 10 : 'none']++;
    this.last10 = this.#cs10;
    this.last11 = this.#cs11;
    this.#cs10 = 0;
    this.#cs11 = 0;
    this.#samples = 0;
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
