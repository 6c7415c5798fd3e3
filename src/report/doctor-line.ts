/**
 * What is on the line when it is not a satellite: packet recognisers for the RC protocols a
 * user may have plugged in instead (run on the bytes as they arrive), and the rule that names
 * a line from its read errors.
 *
 * Pure ECMAScript; nothing allocated per byte.
 */

/** Packets recognised by their own structure and checksum. */
export const PACKET_KINDS = ['ibus', 'srxl-v1', 'srxl2', 'crsf', 'sbus', 'fport', 'ghst'] as const;
export type PacketKind = (typeof PACKET_KINDS)[number];

/** IBUS: 0x20 0x40, 32 bytes, checksum 0xFFFF − sum of the first 30, little-endian. */
const IBUS_LENGTH = 32;
/** SRXL v1 (0xA5, Spektrum AR7700 and others): 18 bytes, CRC-16/XMODEM over the first 16 (ArduPilot's SRXL_FRAMELEN_V5). */
const SRXL_V1_LENGTH = 18;
/** SRXL2 (0xA6): byte 2 is the whole packet's length, ≤ 80 (SRXL_MAX_BUFFER_SIZE). */
const SRXL_MAX_LENGTH = 80;
const SRXL_MIN_LENGTH = 5;
/** CRSF: sync, length (type + payload + CRC, 2…62), type, payload, CRC-8/DVB-S2. */
const CRSF_MAX_LENGTH = 62;
/** GHST (ImmersionRC Ghost): an address 0x80…0x8A, then as CRSF, the length at most 22 (Betaflight's GHST_FRAME_SIZE_MAX 24 less address and length). */
const GHST_MAX_LENGTH = 22;
const GHST_FIRST_ADDRESS = 0x80;
const GHST_LAST_ADDRESS = 0x8a;
/**
 * FPort (FrSky): 0x7E, length, type, payload, checksum, 0x7E, with 0x7D escaping 0x7E and 0x7D
 * (the next byte XOR 0x20); the bytes from the length to the checksum sum to 0xFF, carries
 * folded in. A control frame is 29 bytes unescaped (length 0x19).
 */
const FPORT_FLAG = 0x7e;
const FPORT_ESCAPE = 0x7d;
const FPORT_MAX_LENGTH = 40;
/** SBUS: 25 bytes, 0x0F … footer 0x00 (or an SBUS2 telemetry slot footer 0x04/0x14/0x24/0x34). */
const SBUS_LENGTH = 25;
const HISTORY = 128;
const MAX_PENDING = 16;
/**
 * The candidate a byte starts, by byte value: 0 SRXL v1 (0xA5), 1 SRXL2 (0xA6), 2 CRSF (its
 * sync bytes), 3 GHST (its addresses), 4 an FPort flag (0x7E), −1 none. Built on first use.
 */
let startKinds: Int8Array | undefined;
const START_GHST = 3;
const START_FPORT = 4;

function buildStartKinds(): Int8Array {
  const t = new Int8Array(256).fill(-1);
  t[0xa5] = 0;
  t[0xa6] = 1;
  for (const sync of [0xc8, 0xee, 0xea]) t[sync] = 2;
  for (let a = GHST_FIRST_ADDRESS; a <= GHST_LAST_ADDRESS; a++) t[a] = START_GHST;
  t[FPORT_FLAG] = START_FPORT;
  return t;
}

/** CRC-16/XMODEM (poly 0x1021) and CRC-8/DVB-S2 (poly 0xD5), MSB first: one table lookup a byte. */
let crcTables: { c16: Uint16Array; c8: Uint8Array } | undefined;

/** Built on first use, so importing the module does no work. */
function buildCrcTables(): { c16: Uint16Array; c8: Uint8Array } {
  const c16 = new Uint16Array(256);
  const c8 = new Uint8Array(256);
  for (let n = 0; n < 256; n++) {
    let a = n << 8;
    let b = n;
    for (let k = 0; k < 8; k++) {
      a = a & 0x8000 ? ((a << 1) ^ 0x1021) & 0xffff : (a << 1) & 0xffff;
      b = b & 0x80 ? ((b << 1) ^ 0xd5) & 0xff : (b << 1) & 0xff;
    }
    c16[n] = a;
    c8[n] = b;
  }
  return { c16, c8 };
}

function crc16Xmodem(ring: Uint8Array, start: number, length: number): number {
  const table = (crcTables ??= buildCrcTables()).c16;
  let crc = 0;
  for (let i = 0; i < length; i++)
    crc = ((crc << 8) & 0xffff) ^ (table[((crc >>> 8) ^ (ring[(start + i) & (HISTORY - 1)] ?? 0)) & 0xff] ?? 0);
  return crc;
}

function crc8DvbS2(ring: Uint8Array, start: number, length: number): number {
  const table = (crcTables ??= buildCrcTables()).c8;
  let crc = 0;
  for (let i = 0; i < length; i++) crc = table[(crc ^ (ring[(start + i) & (HISTORY - 1)] ?? 0)) & 0xff] ?? 0;
  return crc;
}

/**
 * How far back a scanner looks: what it finds at a byte depends on the `SCAN_MEMORY` bytes
 * before it (the longest packet it can still be pending on, and its ring) and on nothing earlier.
 * After a stretch of `SCAN_MEMORY` bytes none of which starts a candidate (`startsCandidate`), it
 * holds no candidate, so its state there is those bytes alone.
 */
export const SCAN_MEMORY = HISTORY - 1;

/** Whether a byte starts a candidate the scanner keeps pending (SRXL v1 0xA5, SRXL2 0xA6, CRSF's sync bytes, GHST's addresses, FPort's flag). */
export function startsCandidate(byte: number): boolean {
  return ((startKinds ??= buildStartKinds())[byte] ?? -1) >= 0;
}

/**
 * Finds IBUS, SRXL v1, SRXL2, CRSF, SBUS, FPort and GHST packets in a byte stream, fed in any chunking.
 * Each packet is checked by its checksum (SBUS, which has none, by its header and footer and
 * the next header 25 bytes on). `onPacket` is called once per packet with its kind and the
 * stream index of its last byte.
 */
/** `PacketScanner.checkpoint()`. */
export interface PacketScannerCheckpoint {
  readonly ring: Uint8Array;
  readonly n: number;
  readonly pendingAt: Float64Array;
  readonly pendingKind: Uint8Array;
  readonly pending: number;
  readonly lastSrxl2Type: number;
  readonly fport: Uint8Array;
  readonly fportLength: number;
  readonly fportEscape: boolean;
}

export class PacketScanner {
  readonly #ring = new Uint8Array(HISTORY);
  /** Stream index of the next byte. */
  #n = 0;
  /** Candidate starts: stream index, and kind code (0 SRXL v1, 1 SRXL2, 2 CRSF, 3 GHST). */
  readonly #pendingAt = new Float64Array(MAX_PENDING);
  readonly #pendingKind = new Uint8Array(MAX_PENDING);
  #pending = 0;
  /** The FPort frame since the last flag, unescaped (`#fportLength` bytes; −1: none open). */
  readonly #fport = new Uint8Array(FPORT_MAX_LENGTH);
  #fportLength = -1;
  #fportEscape = false;
  /** Whether bytes were scanned since the last `pass` (else the ring is still clear). */
  #scanned = true;
  /** Last SRXL2 packet type seen (0x21 handshake, 0xCD control data…). */
  lastSrxl2Type = -1;

  constructor(readonly onPacket: (kind: PacketKind, endIndex: number) => void) {}

  /** The scanner's whole state (the last bytes, the candidates pending, the stream index), as copies. */
  checkpoint(): PacketScannerCheckpoint {
    return {
      ring: this.#ring.slice(),
      n: this.#n,
      pendingAt: this.#pendingAt.slice(),
      pendingKind: this.#pendingKind.slice(),
      pending: this.#pending,
      lastSrxl2Type: this.lastSrxl2Type,
      fport: this.#fport.slice(),
      fportLength: this.#fportLength,
      fportEscape: this.#fportEscape,
    };
  }

  /** Back to where `checkpoint()` was taken (on this scanner or another); `onPacket` stays its own. */
  restore(cp: PacketScannerCheckpoint): void {
    this.#ring.set(cp.ring);
    this.#n = cp.n;
    this.#pendingAt.set(cp.pendingAt);
    this.#pendingKind.set(cp.pendingKind);
    this.#pending = cp.pending;
    this.lastSrxl2Type = cp.lastSrxl2Type;
    this.#fport.set(cp.fport);
    this.#fportLength = cp.fportLength;
    this.#fportEscape = cp.fportEscape;
    this.#scanned = true;
  }

  /**
   * `count` bytes of the stream went by unscanned: the stream index moves on and what comes next
   * is scanned as if the stream began there (no candidate pending, nothing remembered). Packets
   * ending within `SCAN_MEMORY` bytes after may be missed or be chance ones; after that, when the
   * bytes fed since hold no `startsCandidate` byte in their first `SCAN_MEMORY`, the scanner is in
   * the very state it would be in had it scanned everything.
   */
  pass(count: number): void {
    this.#n += count;
    if (!this.#scanned) return; // cleared already: a run of passes clears once
    this.#pending = 0;
    this.#fportLength = -1;
    this.#fportEscape = false;
    this.#ring.fill(0);
    this.#scanned = false;
  }

  /** The stream's next bytes: those of `bytes` from `start` to `end` (default all). */
  push(bytes: Uint8Array, start = 0, end = bytes.length): void {
    // The state in locals for the loop (written back at the end): this runs on every byte, so
    // the usual byte (no packet ends here, none is pending, it starts none) costs a store, two
    // compares and one table lookup.
    const ring = this.#ring;
    const mask = HISTORY - 1;
    const pendingAt = this.#pendingAt;
    const pendingKind = this.#pendingKind;
    const starts = (startKinds ??= buildStartKinds());
    let pending = this.#pending;
    let k = this.#n;
    for (let i = start; i < end; i++, k++) {
      const b = bytes[i] as number;
      ring[k & mask] = b;
      // IBUS ends here? (0x20 0x40 31 bytes back.)
      if (ring[(k - (IBUS_LENGTH - 1)) & mask] === 0x20 && k >= IBUS_LENGTH - 1) this.#ibus(k);
      // SBUS: a 0x0F 25 bytes back, a footer just before this byte, and this byte the next 0x0F.
      if (b === 0x0f && k >= SBUS_LENGTH) {
        const footer = ring[(k - 1) & mask] as number;
        if (ring[(k - SBUS_LENGTH) & mask] === 0x0f && (footer === 0x00 || (footer & 0xcf) === 0x04)) this.onPacket('sbus', k - 1);
      }
      // Packets announced by a length byte: check the ones that end here.
      if (pending > 0) pending = this.#checkPending(k, pending);
      const start = starts[b] as number;
      if (start === START_FPORT) this.#fportFlag(k);
      else if (this.#fportLength >= 0) this.#fportByte(b);
      if (start >= 0 && start !== START_FPORT) {
        if (pending === MAX_PENDING) {
          pendingAt.copyWithin(0, 1);
          pendingKind.copyWithin(0, 1);
          pending--;
        }
        pendingAt[pending] = k;
        pendingKind[pending] = start;
        pending++;
      }
    }
    this.#pending = pending;
    this.#n = k;
    if (end > start) this.#scanned = true;
  }

  /** An FPort flag at stream index `k`: it ends the frame open (checked and reported) and opens the next. */
  #fportFlag(k: number): void {
    const n = this.#fportLength;
    const f = this.#fport;
    if (n >= 4 && !this.#fportEscape && n === (f[0] ?? 0) + 2) {
      let sum = 0;
      for (let i = 0; i < n; i++) sum += f[i] ?? 0;
      while (sum > 0xff) sum = (sum & 0xff) + (sum >> 8);
      if (sum === 0xff) this.onPacket('fport', k);
    }
    this.#fportLength = 0;
    this.#fportEscape = false;
  }

  /** A byte inside an open FPort frame, unescaped; a frame longer than any FPort frame is dropped. */
  #fportByte(b: number): void {
    if (b === FPORT_ESCAPE && !this.#fportEscape) {
      this.#fportEscape = true;
      return;
    }
    const n = this.#fportLength;
    if (n >= FPORT_MAX_LENGTH) {
      this.#fportLength = -1;
      return;
    }
    this.#fport[n] = this.#fportEscape ? b ^ 0x20 : b;
    this.#fportEscape = false;
    this.#fportLength = n + 1;
  }

  /** An IBUS packet that may end at stream index `k` (its first byte is 0x20): checked and reported. */
  #ibus(k: number): void {
    const ring = this.#ring;
    const mask = HISTORY - 1;
    const s = k - (IBUS_LENGTH - 1);
    if (ring[(s + 1) & mask] !== 0x40) return;
    let sum = 0;
    for (let j = 0; j < IBUS_LENGTH - 2; j++) sum += ring[(s + j) & mask] ?? 0;
    const check = (ring[(k - 1) & mask] ?? 0) | ((ring[k & mask] ?? 0) << 8);
    if (((0xffff - sum) & 0xffff) === check) this.onPacket('ibus', k);
  }

  /**
   * The pending candidates at stream index `k` (its byte already in the ring): those that end
   * here are checked and reported, those that can no longer be a packet dropped. Returns how
   * many remain (kept in order at the start of the lists).
   */
  #checkPending(k: number, pending: number): number {
    const ring = this.#ring;
    const mask = HISTORY - 1;
    const pendingAt = this.#pendingAt;
    const pendingKind = this.#pendingKind;
    let w = 0;
    for (let p = 0; p < pending; p++) {
      const at = pendingAt[p] ?? 0;
      const kind = pendingKind[p] ?? 0;
      // CRSF and GHST: the length right after the first byte, CRC-8 over type and payload.
      const crc8 = kind === 2 || kind === START_GHST;
      const lengthAt = at + (crc8 ? 1 : 2);
      let keep = true;
      if (kind === 0) {
        // SRXL v1 has no length byte: a fixed 18 bytes.
        if (k === at + SRXL_V1_LENGTH - 1) {
          keep = false;
          const crc = ((ring[(k - 1) & mask] ?? 0) << 8) | (ring[k & mask] ?? 0);
          if (crc16Xmodem(ring, at, SRXL_V1_LENGTH - 2) === crc) this.onPacket('srxl-v1', k);
        }
      } else if (k === lengthAt) {
        const length = ring[k & mask] ?? 0;
        keep = crc8
          ? length >= 2 && length <= (kind === 2 ? CRSF_MAX_LENGTH : GHST_MAX_LENGTH)
          : length >= SRXL_MIN_LENGTH && length <= SRXL_MAX_LENGTH;
      } else if (k > lengthAt) {
        const length = ring[lengthAt & mask] ?? 0;
        const total = crc8 ? length + 2 : length;
        if (k === at + total - 1) {
          keep = false;
          if (crc8) {
            if (crc8DvbS2(ring, at + 2, total - 3) === ring[k & mask]) this.onPacket(kind === 2 ? 'crsf' : 'ghst', k);
          } else {
            const crc = ((ring[(k - 1) & mask] ?? 0) << 8) | (ring[k & mask] ?? 0);
            if (crc16Xmodem(ring, at, total - 2) === crc) {
              this.lastSrxl2Type = ring[(at + 1) & mask] ?? 0;
              this.onPacket('srxl2', k);
            }
          }
        }
      }
      if (keep && k - at < HISTORY - 1) {
        pendingAt[w] = at;
        pendingKind[w] = kind;
        w++;
      }
    }
    return w;
  }
}

// ---------------------------------------------------------------------------------------------
// Naming a line from its read errors
// ---------------------------------------------------------------------------------------------

/** What arrived over a window, for `classifyLine`. */
export interface LineCounts {
  /** Seconds the window covers (with data or errors). */
  seconds: number;
  bytes: number;
  /** Bytes inside decoded Spektrum frames. */
  frameBytes: number;
  /** Characters with a framing or parity error (some platforms report a framing error as ParityError). */
  characterErrors: number;
  breaks: number;
  /** Packets recognised, by kind. */
  packets: Readonly<Record<PacketKind, number>>;
  /**
   * With per-byte times only: the period of the bursts of activity, µs, when they repeat
   * regularly; NaN when they do not or when times are per chunk.
   */
  burstPeriodUs: number;
}

export type LineVerdict =
  | { kind: 'satellite' }
  | { kind: 'too-little' }
  | { kind: 'packets'; protocol: PacketKind; count: number }
  | { kind: 'inverted-satellite'; periodUs: number; breaksPerSecond: number; bytesPerBreak: number; confident: boolean }
  | { kind: 'sbus'; periodUs: number; breaksPerSecond: number; bytesPerBreak: number; confident: boolean }
  | { kind: 'idle-low'; breaksPerSecond: number; bytesPerBreak: number }
  | { kind: 'crsf'; periodUs: number }
  | { kind: 'other-speed'; errorRatio: number }
  | { kind: 'noise'; breaksPerSecond: number; errorRatio: number }
  | { kind: 'unknown-115200'; bytes: number };

/** Bytes a window needs before the line is judged: about a dozen frames' worth. */
export const LINE_MIN_BYTES = 64;
/** Known packets before a protocol is named (each passed its checksum). */
export const LINE_MIN_PACKETS = 3;
/**
 * CRSF, SBUS, FPort and GHST packets are found in bytes only where those bytes were read at
 * their own line setting (a logic analyser's export, a raw dump), never at 115200, and their
 * checks are weak (an 8-bit CRC; SBUS's fixed header and footer): named only when they come at
 * least once every this many bytes. A stream of them sends one every 25-40 bytes; random bytes
 * pass a CRC-8 check about once in 100 000.
 */
export const PACKET_SPACING_MAX = 256;
/** Share of the bytes that decoded as Spektrum frames above which the line is a satellite. */
export const SATELLITE_SHARE = 0.5;
/** Share of characters with errors above which the line is not 115200 8N1. */
export const ERROR_RATIO = 0.15;

const near = (x: number, target: number, tolerance = 0.15): boolean => Math.abs(x - target) <= tolerance * target;
/** CRSF packet rates: 50, 150, 250, 500 Hz (ExpressLRS and Crossfire modes). */
const CRSF_PERIODS_US = [20_000, 6_667, 4_000, 2_000];

/**
 * Names what is on a line from one window of counts. The rules, first match wins:
 *
 * 1. Most bytes decoded as Spektrum frames: a satellite.
 * 2. IBUS, SRXL2 or SRXL v1 packets with valid checksums: that protocol at 115200; CRSF, SBUS,
 *    FPort or GHST packets, densely: that protocol's bytes, read at its own setting.
 * 3. Break conditions repeating: the line idles low (inverted). A satellite's 16 bytes, seen
 *    through an inverter at its own speed, come out as about 10 bytes and one break per frame;
 *    SBUS's 25 bytes at 100000 8E2 as about 16 and one break per frame. Fewer than 3 bytes a
 *    break is noise. The break rate is the packet rate (11 or 22 ms; SBUS 7 or 14 ms).
 * 4. Character errors without breaks: a normal-polarity signal at another speed: CRSF when
 *    bursts repeat at a CRSF packet rate (needs per-byte times), else "another speed".
 * 5. Clean bytes that are nothing known.
 */
export function classifyLine(c: LineCounts): LineVerdict {
  const chars = c.bytes + c.characterErrors;
  if (c.frameBytes >= LINE_MIN_BYTES / 2 && c.frameBytes >= SATELLITE_SHARE * c.bytes) return { kind: 'satellite' };
  for (const protocol of ['srxl2', 'ibus', 'srxl-v1'] as const) {
    const count = c.packets[protocol];
    if (count >= LINE_MIN_PACKETS) return { kind: 'packets', protocol, count };
  }
  for (const protocol of ['crsf', 'sbus', 'fport', 'ghst'] as const) {
    const count = c.packets[protocol];
    if (count >= LINE_MIN_PACKETS && count * PACKET_SPACING_MAX >= c.bytes) return { kind: 'packets', protocol, count };
  }
  if (chars + c.breaks < LINE_MIN_BYTES || !(c.seconds > 0)) return { kind: 'too-little' };
  const errorRatio = c.characterErrors / Math.max(1, chars);
  if (c.breaks >= 3) {
    const breaksPerSecond = c.breaks / c.seconds;
    const bytesPerBreak = c.bytes / c.breaks;
    const periodUs = 1e6 / breaksPerSecond;
    if (bytesPerBreak < 3) return { kind: 'noise', breaksPerSecond, errorRatio };
    if (bytesPerBreak >= 13) {
      return {
        kind: 'sbus',
        periodUs,
        breaksPerSecond,
        bytesPerBreak,
        confident: near(periodUs, 14_000) || near(periodUs, 7_000) || near(periodUs, 9_000, 0.08) || near(periodUs, 10_000, 0.08),
      };
    }
    if (bytesPerBreak >= 6) {
      return {
        kind: 'inverted-satellite',
        periodUs,
        breaksPerSecond,
        bytesPerBreak,
        confident: near(periodUs, 11_000) || near(periodUs, 22_000),
      };
    }
    return { kind: 'idle-low', breaksPerSecond, bytesPerBreak };
  }
  if (errorRatio >= ERROR_RATIO) {
    if (Number.isFinite(c.burstPeriodUs) && CRSF_PERIODS_US.some((p) => near(c.burstPeriodUs, p, 0.05)))
      return { kind: 'crsf', periodUs: c.burstPeriodUs };
    return { kind: 'other-speed', errorRatio };
  }
  return { kind: 'unknown-115200', bytes: c.bytes };
}
