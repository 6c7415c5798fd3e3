/**
 * CRC-32 (IEEE 802.3, as zlib) for the .sscap records, with the combining arithmetic that keeps
 * recovery from a damaged file linear.
 */

/** CRC-32/ISO-HDLC (zlib, PNG, Ethernet): reflected polynomial 0xEDB88320, init and xor-out 0xFFFFFFFF. */
const CRC32_POLY = 0xedb88320;
/**
 * Eight tables for slicing-by-8: `table[k·256 + b]` is the register after byte `b` and `k` zero
 * bytes, so eight bytes take eight lookups and no loop-carried shift per byte (about three times
 * the speed of one table on records of a few dozen bytes).
 */
function buildCrcTable(): Uint32Array {
  const table = new Uint32Array(8 * 256);
  for (let n = 0; n < 256; n++) {
    let c = n;
    for (let k = 0; k < 8; k++) c = c & 1 ? CRC32_POLY ^ (c >>> 1) : c >>> 1;
    table[n] = c >>> 0;
  }
  for (let n = 0; n < 256; n++) {
    let c = table[n] ?? 0;
    for (let k = 1; k < 8; k++) {
      c = (table[c & 0xff] ?? 0) ^ (c >>> 8);
      table[k * 256 + n] = c >>> 0;
    }
  }
  return table;
}

/**
 * Built as the module loads (2048 entries, some microseconds), not on first use: a table read
 * through a `let` that may still be unset is loaded and tested at every call, and that made a
 * record's check 41-42 ns instead of 32 in Node. Pure, for bundlers that drop an unused module.
 */
const crcTable = /* @__PURE__ */ buildCrcTable();

/**
 * CRC-32 (as zlib computes it) of `bytes[start, end)`, as an unsigned 32-bit number. `view`: a
 * DataView over exactly `bytes`, for callers that check many short records (see crcRun).
 */
export function crc32(bytes: Uint8Array, start = 0, end = bytes.length, view?: DataView): number {
  run(-1, bytes, start, end, view);
  return ((register[0] ?? 0) ^ -1) >>> 0;
}

/**
 * Whether the CRC-32 stored after `bytes[start, end)` (little-endian, at `end`: a record's or a
 * header's own) is that of the range. `view` as for crc32. What a reader checking every record
 * calls: a boolean crosses the call, where the CRC itself, most often above what a browser keeps
 * as a small integer (2^30), would be a new heap number a record when the call is not inlined.
 */
export function crcFollows(bytes: Uint8Array, start: number, end: number, view: DataView): boolean {
  run(-1, bytes, start, end, view);
  return ((register[0] ?? 0) ^ -1) === view.getInt32(end, true);
}

/** Runs the CRC register `c` (before the final XOR) over `bytes[start, end)` (see `run`). */
export function crcRun(c: number, bytes: Uint8Array, start: number, end: number, view?: DataView): number {
  run(c, bytes, start, end, view);
  return register[0] ?? 0;
}

/** Where `run` leaves the register: a 32-bit result returned from a call that is not inlined is boxed. */
const register = new Int32Array(1);

/**
 * Runs the CRC register `from` over `bytes[start, end)`, into `register`. Eight bytes, then four,
 * are read as little-endian words through `view` (a DataView over exactly `bytes`), fewer reads
 * than a byte at a time. Without one, a range under 64 bytes is read a byte at a time (making a
 * view costs more).
 */
function run(from: number, bytes: Uint8Array, start: number, end: number, view?: DataView): void {
  const t = crcTable;
  // A 32-bit integer from the start: a register that began as the argument (a tagged value) is
  // boxed on every turn of the loop once it leaves the small integers (±2^30).
  let c = from | 0;
  let i = start;
  // Without a view, one is made only for a range long enough to repay making it.
  const v = view ?? (end - start >= 64 ? new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength) : undefined);
  if (v !== undefined) {
    for (; i + 8 <= end; i += 8) {
      const lo = (c ^ v.getInt32(i, true)) >>> 0;
      const hi = v.getUint32(i + 4, true);
      c =
        (t[1792 + (lo & 0xff)] ?? 0) ^
        (t[1536 + ((lo >>> 8) & 0xff)] ?? 0) ^
        (t[1280 + ((lo >>> 16) & 0xff)] ?? 0) ^
        (t[1024 + (lo >>> 24)] ?? 0) ^
        (t[768 + (hi & 0xff)] ?? 0) ^
        (t[512 + ((hi >>> 8) & 0xff)] ?? 0) ^
        (t[256 + ((hi >>> 16) & 0xff)] ?? 0) ^
        (t[hi >>> 24] ?? 0);
    }
    if (i + 4 <= end) {
      const lo = (c ^ v.getInt32(i, true)) >>> 0;
      c = (t[768 + (lo & 0xff)] ?? 0) ^ (t[512 + ((lo >>> 8) & 0xff)] ?? 0) ^ (t[256 + ((lo >>> 16) & 0xff)] ?? 0) ^ (t[lo >>> 24] ?? 0);
      i += 4;
    }
  }
  for (; i < end; i++) c = (t[(c ^ (bytes[i] ?? 0)) & 0xff] ?? 0) ^ (c >>> 8);
  register[0] = c;
}

// CRC-32 is linear over GF(2), so the CRC of `a || b` follows from the CRCs of `a` and `b` and
// the length of `b` (zlib's crc32_combine): crc(a || b) = crc(a) · x^(8·|b|) mod P  ⊕  crc(b).
// The reader uses it to check a long record from two prefix CRCs instead of reading it again.

/** a · b modulo the CRC polynomial, in the reflected bit order the table uses. */
export function mulModPoly(a: number, b: number): number {
  if (a === 0) return 0;
  let m = 0x80000000;
  let p = 0;
  for (;;) {
    if (a & m) {
      p ^= b;
      if ((a & (m - 1)) === 0) break;
    }
    m >>>= 1;
    b = b & 1 ? (b >>> 1) ^ CRC32_POLY : b >>> 1;
  }
  return p >>> 0;
}

/** x^(2^k) mod P for k = 0…31, built on first use. */
let crcPowers: Uint32Array | undefined;

/** x^(8·n) mod P: the factor that moves a CRC past n zero bytes. */
export function crcShift(n: number): number {
  const powers = (crcPowers ??= (() => {
    const t = new Uint32Array(32);
    let p = 0x40000000; // x^1
    t[0] = p;
    for (let k = 1; k < 32; k++) t[k] = p = mulModPoly(p, p);
    return t;
  })());
  let p = 0x80000000; // x^0
  for (let k = 3; n > 0; k++, n = Math.floor(n / 2)) if (n % 2 === 1) p = mulModPoly(powers[k & 31] ?? 0, p);
  return p;
}
