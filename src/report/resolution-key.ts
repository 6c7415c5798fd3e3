/**
 * §8: "the internal remote provides the key for … all remotes". The resolution an external
 * remote takes from the internal one, and the order a whole capture's ports are decoded in so
 * that each is decoded once: the internal remote's port first, then the others with its key.
 */
import { type AnyCapture, captureWindows } from '../capture/capture-windows.js';
import { capturePorts } from '../capture/facts.js';
import { decodeCapture } from './capture-pass.js';
import { SpektrumDecoder } from '../decoder/decoder.js';
import { systemInfo, type Resolution } from '../decoder/spec.js';
import type { DecoderStats, FormatInfo } from '../decoder/types.js';

/**
 * The resolution an external remote takes: that of an internal remote whose system byte is one
 * of the four valid ones, or undefined when there is none among `formats`.
 */
export function resolutionKey(formats: Iterable<FormatInfo>): Resolution | undefined {
  let key: Resolution | undefined;
  for (const f of formats) {
    if (f.remote === 'internal' && f.system !== null && f.systemValid && systemInfo(f.system) !== undefined && f.resolution !== null)
      key = f.resolution;
  }
  return key;
}

/** Bytes of a port a look-ahead decodes at most to see which remote it carries. */
const LOOK_AHEAD_BYTES = 1 << 16;

/**
 * What a port's stream starts as: its first bytes (up to 64 kB, until the decoder locks) through
 * a decoder of their own. Only an order to decode in and a guess of the key: the key itself
 * comes from the whole decode.
 */
function lookAhead(capture: AnyCapture, port: number): FormatInfo {
  const decoder = new SpektrumDecoder();
  let fed = 0;
  for (const { bytes, chunkEnds, chunkPorts } of captureWindows(capture, port)) {
    let from = 0;
    for (let i = 0; i < chunkEnds.length; i++) {
      if (fed >= LOOK_AHEAD_BYTES) return decoder.format;
      const to = chunkEnds[i] ?? from;
      if (chunkPorts[i] === port) {
        const end = Math.min(to, from + LOOK_AHEAD_BYTES - fed);
        decoder.push(bytes.subarray(from, end));
        fed += end - from;
        while (decoder.next() !== undefined) {}
        if (decoder.format.locked && decoder.format.remote !== null) return decoder.format;
      }
      from = to;
    }
  }
  return decoder.format;
}

/** Whether a port's stream starts as an internal remote (`lookAhead`). */
export function looksInternal(capture: AnyCapture, port: number): boolean {
  return lookAhead(capture, port).remote === 'internal';
}

/** A reading `readPorts` asks its decode for. */
export interface PortReadingAsked {
  port: number;
  resolution: 'auto' | Resolution;
  from: 'user' | 'internal-remote';
}

/**
 * The final readings `readPorts` (with `looksInternal` as its `leads`) will most likely ask for,
 * in the order it asks, but for the first: what another thread can make while this one makes
 * the first. A guess from each port's first bytes (`lookAhead`): the key the internal remote's
 * start shows is the one its whole decode gives unless the remote changed its resolution.
 */
export function likelyReadings(capture: AnyCapture, ports: readonly number[], resolution: 'auto' | Resolution): PortReadingAsked[] {
  if (resolution !== 'auto' || ports.length < 2) return ports.slice(1).map((port) => ({ port, resolution, from: 'user' }));
  const starts = new Map(ports.map((p) => [p, lookAhead(capture, p)]));
  const lead = ports.filter((p) => starts.get(p)?.remote === 'internal');
  const key = resolutionKey(lead.flatMap((p) => starts.get(p) ?? []));
  const order = [...lead, ...ports.filter((p) => !lead.includes(p))];
  return order
    .slice(1)
    .map(
      (port): PortReadingAsked =>
        key === undefined || lead.includes(port)
          ? { port, resolution: 'auto', from: 'user' }
          : { port, resolution: key, from: 'internal-remote' },
    );
}

/** What a port's decode must show for the choice between readings. */
export interface PortReading {
  format: FormatInfo;
  stats: Readonly<DecoderStats>;
}

/**
 * Decodes `port` with `resolution` (from the user, or the internal remote's key); `final`: this
 * decode is the port's reading (its frames go to the report), else it is only compared.
 */
export type PortDecode<T extends PortReading> = (
  port: number,
  resolution: 'auto' | Resolution,
  from: 'user' | 'internal-remote',
  final: boolean,
) => T;

/**
 * Every port's reading under §8's rule: each port is read on its own ('auto'), then every port
 * that is not an internal remote is read again with the internal remote's resolution, and
 * keeps that reading when it reads at least as many frames (a port of another system, or a
 * capture put together from unrelated receivers, keeps its own).
 *
 * Decided with one decode per port where the streams allow: ports that start as an internal
 * remote are decoded first, the others straight with the key. A keyed reading that put every
 * byte in a frame cannot be beaten; otherwise the port's own reading is decoded to compare.
 * When the look-ahead was wrong (a port read with the key is an internal remote), the rule is
 * applied as written, decoding every port both ways.
 */
export function readPorts<T extends PortReading>(
  ports: readonly number[],
  resolution: 'auto' | Resolution,
  leads: (port: number) => boolean,
  decode: PortDecode<T>,
): Map<number, T> {
  const out = new Map<number, T>();
  if (resolution !== 'auto' || ports.length < 2) {
    for (const p of ports) out.set(p, decode(p, resolution, 'user', true));
    return out;
  }
  const lead = ports.filter(leads);
  const order = [...lead, ...ports.filter((p) => !lead.includes(p))];
  const own = new Map<number, T>();
  const keyed = new Map<number, T>();
  const keyOf = (): Resolution | undefined => resolutionKey(ports.flatMap((p) => own.get(p)?.format ?? []));
  let key: Resolution | undefined;
  for (const p of order) {
    if (key === undefined || lead.includes(p)) {
      own.set(p, decode(p, 'auto', 'user', true));
      key = keyOf();
    } else {
      keyed.set(p, decode(p, key, 'internal-remote', true));
    }
  }
  // Once there is a key, no port is decoded on its own any more, so the key stays the one used.
  for (const reading of keyed.values()) if (reading.format.remote === 'internal') return asWritten(ports, decode);
  for (const p of ports) {
    const mine = own.get(p);
    if (mine !== undefined) {
      if (key === undefined || mine.format.remote === 'internal') out.set(p, mine);
      else {
        const k = decode(p, key, 'internal-remote', false);
        out.set(p, k.stats.frames >= mine.stats.frames ? decode(p, key, 'internal-remote', true) : mine);
      }
      continue;
    }
    const k = keyed.get(p);
    if (k === undefined) continue;
    if (k.stats.frameBytes === k.stats.bytes) {
      out.set(p, k);
      continue;
    }
    const alone = decode(p, 'auto', 'user', false);
    if (alone.format.remote === 'internal') return asWritten(ports, decode);
    out.set(p, k.stats.frames >= alone.stats.frames ? k : decode(p, 'auto', 'user', true));
  }
  return out;
}

/** §8's rule as written: every port on its own, the key, every other port with the key; then the chosen readings decoded as final. */
function asWritten<T extends PortReading>(ports: readonly number[], decode: PortDecode<T>): Map<number, T> {
  const own = ports.map((p) => decode(p, 'auto', 'user', false));
  const key = resolutionKey(own.map((r) => r.format));
  const out = new Map<number, T>();
  ports.forEach((p, i) => {
    const mine = own[i];
    if (mine === undefined) return;
    if (key === undefined || mine.format.remote === 'internal') {
      out.set(p, decode(p, 'auto', 'user', true));
      return;
    }
    const k = decode(p, key, 'internal-remote', false);
    out.set(p, k.stats.frames >= mine.stats.frames ? decode(p, key, 'internal-remote', true) : decode(p, 'auto', 'user', true));
  });
  return out;
}

/**
 * Each port's resolution setting as the health report reads the port (`readPorts`: the internal
 * remote's key for the others, unless their own reading is better), for a surface that decodes
 * the ports side by side and so cannot decode one before the other (`doctorCapture`). Decodes
 * the ports as the report does, without what listens to the frames; a setting given by the user
 * (or a single port) needs no decode.
 */
export function portResolutions(capture: AnyCapture, resolution: 'auto' | Resolution): Map<number, PortReadingAsked> {
  const ports = capturePorts(capture);
  if (resolution !== 'auto' || ports.length < 2) return new Map(ports.map((port) => [port, { port, resolution, from: 'user' }]));
  const read = readPorts(
    ports,
    resolution,
    (port) => looksInternal(capture, port),
    (port, r, from) => {
      const { decoder } = decodeCapture(capture, { port, resolution: r, resolutionFrom: from }, () => {});
      return { format: decoder.format, stats: decoder.stats, asked: { port, resolution: r, from } };
    },
  );
  return new Map([...read].map(([port, reading]) => [port, reading.asked]));
}
