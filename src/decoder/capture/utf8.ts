/**
 * A small UTF-8 encoder and decoder. The decoder library is compiled against ES2022 alone (no
 * DOM, no Node), so `TextEncoder`, `TextDecoder` and `Buffer` are not available to it. Both
 * functions behave like the WHATWG ones for well-formed input; malformed input becomes U+FFFD
 * (one per offending byte, which is simpler than WHATWG's "maximal subpart" rule and only ever
 * matters for text that is already broken).
 */

const REPLACEMENT = 0xfffd;
/** How many UTF-16 code units to hand to `String.fromCharCode` at once (stays far below engine argument limits). */
const FLUSH_UNITS = 8192;

/** Encodes a string as UTF-8. Lone surrogates become U+FFFD (EF BF BD), as `TextEncoder` does. */
export function utf8Encode(text: string): Uint8Array {
  // Worst case is 3 bytes per UTF-16 code unit (a surrogate pair is 2 units → 4 bytes).
  const out = new Uint8Array(text.length * 3);
  let o = 0;
  for (let i = 0; i < text.length; i++) {
    let c = text.charCodeAt(i);
    if (c < 0x80) {
      out[o++] = c;
      continue;
    }
    if (c >= 0xd800 && c <= 0xdfff) {
      const next = i + 1 < text.length ? text.charCodeAt(i + 1) : 0;
      if (c <= 0xdbff && next >= 0xdc00 && next <= 0xdfff) {
        c = 0x10000 + ((c - 0xd800) << 10) + (next - 0xdc00);
        i++;
      } else {
        c = REPLACEMENT;
      }
    }
    if (c < 0x800) {
      out[o++] = 0xc0 | (c >> 6);
      out[o++] = 0x80 | (c & 0x3f);
    } else if (c < 0x10000) {
      out[o++] = 0xe0 | (c >> 12);
      out[o++] = 0x80 | ((c >> 6) & 0x3f);
      out[o++] = 0x80 | (c & 0x3f);
    } else {
      out[o++] = 0xf0 | (c >> 18);
      out[o++] = 0x80 | ((c >> 12) & 0x3f);
      out[o++] = 0x80 | ((c >> 6) & 0x3f);
      out[o++] = 0x80 | (c & 0x3f);
    }
  }
  return out.slice(0, o);
}

/**
 * Length of the well-formed UTF-8 sequence that starts at `i`, or 0 when the bytes there are not
 * one (bad lead byte, bad continuation, overlong form, surrogate, above U+10FFFF, or cut short
 * by `end`).
 */
function sequenceLength(bytes: Uint8Array, i: number, end: number): number {
  const b0 = bytes[i] ?? 0;
  if (b0 < 0x80) return 1;
  let need: number;
  let min: number;
  if (b0 >= 0xc2 && b0 <= 0xdf) {
    need = 1;
    min = 0x80;
  } else if (b0 >= 0xe0 && b0 <= 0xef) {
    need = 2;
    min = 0x800;
  } else if (b0 >= 0xf0 && b0 <= 0xf4) {
    need = 3;
    min = 0x10000;
  } else {
    return 0;
  }
  if (i + need >= end) return 0;
  let c = b0 & (0x3f >> need);
  for (let k = 1; k <= need; k++) {
    const b = bytes[i + k] ?? 0;
    if ((b & 0xc0) !== 0x80) return 0;
    c = (c << 6) | (b & 0x3f);
  }
  if (c < min || c > 0x10ffff || (c >= 0xd800 && c <= 0xdfff)) return 0;
  return need + 1;
}

/**
 * Decodes UTF-8 bytes `[start, end)` to a string. Malformed bytes become U+FFFD; a byte-order
 * mark is kept (callers that want it gone strip it).
 */
export function utf8Decode(bytes: Uint8Array, start = 0, end = bytes.length): string {
  const units = new Uint16Array(Math.min(FLUSH_UNITS, Math.max(0, end - start)) + 2);
  const parts: string[] = [];
  let u = 0;
  let i = start;
  while (i < end) {
    // Flush before the buffer could overflow (one sequence adds at most 2 code units).
    if (u >= units.length - 2) {
      parts.push(String.fromCharCode.apply(null, units.subarray(0, u) as unknown as number[]));
      u = 0;
    }
    const b0 = bytes[i] ?? 0;
    if (b0 < 0x80) {
      units[u++] = b0;
      i++;
      continue;
    }
    const len = sequenceLength(bytes, i, end);
    if (len === 0) {
      units[u++] = REPLACEMENT;
      i++;
      continue;
    }
    let c = b0 & (0x3f >> (len - 1));
    for (let k = 1; k < len; k++) c = (c << 6) | ((bytes[i + k] ?? 0) & 0x3f);
    if (c >= 0x10000) {
      c -= 0x10000;
      units[u++] = 0xd800 + (c >> 10);
      units[u++] = 0xdc00 + (c & 0x3ff);
    } else {
      units[u++] = c;
    }
    i += len;
  }
  parts.push(String.fromCharCode.apply(null, units.subarray(0, u) as unknown as number[]));
  return parts.length === 1 ? (parts[0] ?? '') : parts.join('');
}

/**
 * True when bytes `[start, end)` are well-formed UTF-8. With `allowCutTail`, an incomplete
 * sequence in the last three bytes is accepted (useful when `end` cuts a sample out of a longer
 * file and may land inside a character).
 */
export function isUtf8(bytes: Uint8Array, start = 0, end = bytes.length, allowCutTail = false): boolean {
  let i = start;
  while (i < end) {
    if ((bytes[i] ?? 0) < 0x80) {
      i++;
      continue;
    }
    const len = sequenceLength(bytes, i, end);
    if (len === 0) return allowCutTail && end - i < 4 && isPrefixOfSequence(bytes, i, end);
    i += len;
  }
  return true;
}

/** True when `[i, end)` is a valid start of a multi-byte sequence that `end` cut short. */
function isPrefixOfSequence(bytes: Uint8Array, i: number, end: number): boolean {
  const b0 = bytes[i] ?? 0;
  const need = b0 >= 0xc2 && b0 <= 0xdf ? 1 : b0 >= 0xe0 && b0 <= 0xef ? 2 : b0 >= 0xf0 && b0 <= 0xf4 ? 3 : 0;
  if (need === 0 || end - i > need) return false;
  for (let k = i + 1; k < end; k++) if (((bytes[k] ?? 0) & 0xc0) !== 0x80) return false;
  return true;
}
