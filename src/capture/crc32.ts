/**
 * CRC-32 (IEEE 802.3, as zlib) for the .sscap records, with the combining arithmetic that keeps
 * recovery from a damaged file linear.
 */

/** CRC-32/ISO-HDLC (zlib, PNG, Ethernet): reflected polynomial 0xEDB88320, init and xor-out 0xFFFFFFFF. */
const CRC32_POLY = 0xedb88320;
let crcTable: Uint32Array | undefined;

function buildCrcTable(): Uint32Array {
  const table = new Uint32Array(256);
  for (let n = 0; n < 256; n++) {
    let c = n;
    for (let k = 0; k < 8; k++) c = c & 1 ? CRC32_POLY ^ (c >>> 1) : c >>> 1;
    table[n] = c >>> 0;
  }
  return table;
}

/** CRC-32 (as zlib computes it) of `bytes[start, end)`, as an unsigned 32-bit number. */
export function crc32(bytes: Uint8Array, start = 0, end = bytes.length): number {
  return (crcRun(0xffffffff, bytes, start, end) ^ 0xffffffff) >>> 0;
}

/** Runs the CRC register `c` (before the final XOR) over `bytes[start, end)`. */
export function crcRun(c: number, bytes: Uint8Array, start: number, end: number): number {
  // Built on first use rather than at import, so importing the module does no work.
  const table = (crcTable ??= buildCrcTable());
  for (let i = start; i < end; i++) c = (table[(c ^ (bytes[i] as number)) & 0xff] as number) ^ (c >>> 8);
  return c;
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
  for (let k = 3; n > 0; k++, n = Math.floor(n / 2)) if (n % 2 === 1) p = mulModPoly(powers[k & 31] as number, p);
  return p;
}
