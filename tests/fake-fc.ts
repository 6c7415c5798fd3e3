/**
 * A flight controller's Spektrum input, as Betaflight documents and implements it (src/main/rx/
 * spektrum.c, rx.c): bytes frame by silence (a gap over 5 ms starts a frame; its 16th byte
 * completes it), the resolution is the user's setting (no detection), channel IDs 12 and over
 * and 0xFFFF slots are dropped, the value is 988 + v/2 µs (2048) or 988 + v (1024), channels
 * are remapped by `rcmap` (AETR order inside: roll, pitch, yaw, throttle, aux…), and RXLOSS is
 * set 100 ms after the last frame and cleared after `recoveryMs` of frames again. For tests of
 * Drive's grading, and the browser test's fake flight controller.
 */
import { BYTE_TIME_US } from '../src/decoder/spec.js';
import { encodeMsp, MSP, MspParser } from '../src/drive/msp.js';

export interface FakeFcOptions {
  /** The serialrx_provider setting. */
  resolution: 1024 | 2048;
  /** `map` as the CLI sets it (default "TAER1234", what a Spektrum user sets). */
  map?: string;
  recoveryMs?: number;
  /**
   * Whose DSM decoder: Betaflight's (above), or the one ArduPilot and PX4 share (their dsm.cpp:
   * 1500 + (v − 1024) × 1000 / 1700 µs in integers, 10-bit values doubled first, throttle moved to
   * channel 3: RC1 aileron, RC2 elevator, RC3 throttle, RC4 rudder, then the rest in order; as
   * many channels as the highest id seen).
   */
  decoder?: 'betaflight' | 'dsm';
  /** No frame for this long: the receiver is lost (Betaflight's rx.c: 100 ms). */
  signalTimeoutMs?: number;
}

/** What the flight controller reads at a moment: its channels (µs, its own order), and RXLOSS. */
export interface FcState {
  atUs: number;
  channels: number[];
  rxLoss: boolean;
}

/** Betaflight's frame gap (SPEKTRUM_NEEDED_FRAME_INTERVAL). */
const FRAME_GAP_US = 5_000;
/** rx.c: a frame must come within 100 ms, else the signal is lost. */
const SIGNAL_TIMEOUT_US = 100_000;

export class FakeFc {
  readonly #shift: number;
  readonly #mask: number;
  readonly #count: number;
  readonly #rcmap: number[];
  readonly #recoveryUs: number;
  readonly #raw: number[];
  readonly #frame = new Uint8Array(16);
  #pos = 0;
  #lastByteUs = Number.NEGATIVE_INFINITY;
  #lastFrameUs = Number.NEGATIVE_INFINITY;
  #goodSinceUs = Number.NaN;
  #rxLoss = true;
  readonly #dsm: boolean;
  readonly #timeoutUs: number;
  #highest = -1;

  constructor(options: FakeFcOptions) {
    this.#dsm = options.decoder === 'dsm';
    this.#timeoutUs = (options.signalTimeoutMs ?? SIGNAL_TIMEOUT_US / 1000) * 1000;
    const bits11 = options.resolution === 2048;
    this.#shift = bits11 ? 3 : 2;
    this.#mask = bits11 ? 0x07 : 0x03;
    this.#count = bits11 ? 12 : 7;
    this.#raw = new Array(this.#count).fill(0);
    // rcmap[i]: the receiver channel that feeds internal channel i (A, E, R, T, aux 1–4).
    const map = (options.map ?? 'TAER1234').toUpperCase();
    this.#rcmap = ['A', 'E', 'R', 'T', '1', '2', '3', '4'].map((c) => map.indexOf(c));
    this.#recoveryUs = (options.recoveryMs ?? 500) * 1000;
  }

  /** A byte on the line at `atUs`. */
  byte(b: number, atUs: number): void {
    if (atUs - this.#lastByteUs > FRAME_GAP_US) this.#pos = 0;
    this.#lastByteUs = atUs;
    if (this.#pos < 16) this.#frame[this.#pos++] = b;
    if (this.#pos === 16) {
      this.#pos = 17; // the rest up to the next gap is ignored
      this.#decode(atUs);
    }
  }

  /** Bytes written at `atUs`, back to back. */
  write(bytes: Uint8Array, atUs: number): void {
    for (let i = 0; i < bytes.length; i++) this.byte(bytes[i] as number, atUs + i * BYTE_TIME_US);
  }

  /** What MSP_RC and the arming-disable flags say at `atUs`. */
  state(atUs: number): FcState {
    if (atUs - this.#lastFrameUs > this.#timeoutUs) {
      this.#rxLoss = true;
      this.#goodSinceUs = Number.NaN;
    } else if (this.#rxLoss && atUs - this.#goodSinceUs >= this.#recoveryUs) this.#rxLoss = false;
    if (this.#dsm) {
      const eleven = (v: number) => (this.#shift === 3 ? v : v * 2);
      const us = (v: number) => 1500 + Math.trunc(((eleven(v) - 1024) * 1000) / 1700);
      // Its channel i takes receiver channel: RC1 ← 1, RC2 ← 2, RC3 ← 0, the rest their own.
      const from = (i: number) => (i === 0 ? 1 : i === 1 ? 2 : i === 2 ? 0 : i);
      const channels = Array.from({ length: this.#highest + 1 }, (_, i) => us(this.#raw[from(i)] ?? 0));
      return { atUs, channels, rxLoss: this.#rxLoss };
    }
    const us = (v: number) => (this.#shift === 3 ? 988 + v / 2 : 988 + v);
    const channels: number[] = [];
    for (let i = 0; i < this.#count; i++) {
      const raw = i < this.#rcmap.length ? (this.#rcmap[i] as number) : i;
      channels.push(Math.trunc(us(this.#raw[raw] ?? 0)));
    }
    return { atUs, channels, rxLoss: this.#rxLoss };
  }

  #decode(atUs: number): void {
    const f = this.#frame;
    for (let b = 3; b < 16; b += 2) {
      const id = 0x0f & ((f[b - 1] as number) >> this.#shift);
      if (id < this.#count && id < 12) {
        this.#raw[id] = (((f[b - 1] as number) & this.#mask) << 8) | (f[b] as number);
        if (id > this.#highest) this.#highest = id;
      }
    }
    if (Number.isNaN(this.#goodSinceUs)) this.#goodSinceUs = atUs;
    this.#lastFrameUs = atUs;
  }
}

const le16 = (values: number[]) => new Uint8Array(values.flatMap((v) => [v & 0xff, v >> 8]));

/** Betaflight's MSP_STATUS_EX reply: armed in the flight-mode flags (offset 6), no extra mode bytes, then the arming-disable flags (RXLOSS is bit 2). */
export function statusEx(armed: boolean, rxLoss: boolean): Uint8Array {
  const p = new Uint8Array(22);
  const v = new DataView(p.buffer);
  v.setUint32(6, armed ? 1 : 0, true);
  p[15] = 0;
  p[16] = 26;
  v.setUint32(17, rxLoss ? 1 << 2 : 0, true);
  return p;
}

/**
 * The same Betaflight's USB port: MSP requests in, replies out (its variant, its receiver setting,
 * MSP_RC and MSP_STATUS_EX from what its UART read by then). Requests it does not know go unanswered.
 */
export class FakeBetaflightUsb {
  readonly #requests = new MspParser();

  constructor(
    readonly fc: FakeFc,
    readonly resolution: 1024 | 2048,
  ) {}

  /** Bytes from the page at `nowUs`; the replies to send back. */
  push(bytes: Uint8Array, nowUs: number): Uint8Array[] {
    const replies: Uint8Array[] = [];
    this.#requests.push(bytes);
    for (let m = this.#requests.next(); m !== undefined; m = this.#requests.next()) {
      const state = this.fc.state(nowUs);
      const payload =
        m.cmd === MSP.FC_VARIANT
          ? new TextEncoder().encode('BTFL')
          : m.cmd === MSP.RX_CONFIG
            ? new Uint8Array([this.resolution === 2048 ? 1 : 0])
            : m.cmd === MSP.RC
              ? le16(state.channels)
              : m.cmd === MSP.STATUS_EX
                ? statusEx(false, state.rxLoss)
                : null;
      if (payload !== null) replies.push(encodeMsp(m.cmd, payload, { direction: 'reply' }));
    }
    return replies;
  }
}
