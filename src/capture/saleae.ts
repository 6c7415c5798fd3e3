/**
 * Saleae Logic "Async Serial" CSV exports (Logic 1 and 2): one byte per line with its time.
 */
import { utf8Decode, utf8Encode } from './text.js';
import { CaptureFormatError } from './model.js';
import { stepOverBadTimes } from './time-rule.js';
import type { Capture, CaptureIssue, CaptureMeta } from './model.js';

//
// The parser works on the file's bytes, not on a decoded string: Saleae exports are ASCII, and
// reading numbers straight from the bytes avoids a string (and an array of strings) per row.
// Strings are only made for the header, for analyser names when they change, and for messages.

const COMMA = 0x2c;
const QUOTE = 0x22;
export const LF = 0x0a;
export const CR = 0x0d;
const SPACE = 0x20;
const TAB = 0x09;
const DOT = 0x2e;
const MINUS = 0x2d;
const PLUS = 0x2b;
const ZERO = 0x30;

/** Where the columns we use are in a Saleae header, found by name so column order does not matter. */
interface CsvColumns {
  /** Number of columns in the header. */
  count: number;
  time: number;
  value: number;
  /** Logic 2 `name`: the analyser that produced the row; each distinct name becomes a port. */
  name: number;
  /** Logic 2 `type`: only `data` rows are bytes. */
  type: number;
  /** Columns whose title mentions "error" (Logic 1 `Parity Error`, `Framing Error`; Logic 2 `error`), with their titles. */
  errors: { index: number; title: string }[];
}

/** Time column: Logic 1 `Time [s]`, Logic 2 `start_time`. */
const TIME_HEADER = /^(time( ?\[s\])?|start_time)$/;
/** Value column: Logic 1 `Value`, Logic 2 `data`. */
const VALUE_HEADER = /^(value|data)$/;
/** A number of seconds in a form the fast path does not take (an exponent, as in `1.5e-3`). */
const DECIMAL_NUMBER = /^[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?$/;
/** Flag values that mean "no error" in an error column. */
const NO_ERROR = new Set(['', '0', 'false', 'no', 'none']);
const UTF8_BOM = [0xef, 0xbb, 0xbf] as const;

export function bomLength(bytes: Uint8Array): number {
  return bytes[0] === UTF8_BOM[0] && bytes[1] === UTF8_BOM[1] && bytes[2] === UTF8_BOM[2] ? 3 : 0;
}

/**
 * Field boundaries of one CSV line, reused from line to line. Quotes are removed and spaces
 * around fields trimmed; `escaped[i]` says field `i` holds a doubled quote (`""`) that
 * `text(i)` turns back into one.
 */
class CsvFields {
  readonly starts: Int32Array;
  readonly ends: Int32Array;
  readonly escaped: Uint8Array;
  /** Fields on the line (may exceed the capacity; only the first `capacity` are recorded). */
  count = 0;

  constructor(
    /** The bytes the line is in: a reader that reads a file a piece at a time sets each piece here. */
    public bytes: Uint8Array,
    capacity: number,
  ) {
    this.starts = new Int32Array(capacity);
    this.ends = new Int32Array(capacity);
    this.escaped = new Uint8Array(capacity);
  }

  /** Splits `[ls, le)`. Returns false on an unterminated quote. */
  split(ls: number, le: number): boolean {
    const b = this.bytes;
    const cap = this.starts.length;
    let n = 0;
    let i = ls;
    for (;;) {
      let s = i;
      while (s < le && (b[s] === SPACE || b[s] === TAB)) s++;
      let fs: number;
      let fe: number;
      let esc = 0;
      if (s < le && b[s] === QUOTE) {
        let j = s + 1;
        for (;;) {
          while (j < le && b[j] !== QUOTE) j++;
          if (j >= le) return false;
          if (b[j + 1] !== QUOTE || j + 1 >= le) break;
          esc = 1;
          j += 2;
        }
        fs = s + 1;
        fe = j;
        // Whatever sits between the closing quote and the next comma is ignored.
        i = j + 1;
        while (i < le && b[i] !== COMMA) i++;
      } else {
        i = s;
        while (i < le && b[i] !== COMMA) i++;
        fs = s;
        fe = i;
        while (fe > fs && (b[fe - 1] === SPACE || b[fe - 1] === TAB)) fe--;
      }
      if (n < cap) {
        this.starts[n] = fs;
        this.ends[n] = fe;
        this.escaped[n] = esc;
      }
      n++;
      if (i >= le) break;
      i++; // past the comma
    }
    this.count = n;
    return true;
  }

  /** Field `i` as a string (a fresh one: use for names and messages, not per row). */
  text(i: number): string {
    const t = utf8Decode(this.bytes, this.starts[i] ?? 0, this.ends[i] ?? 0);
    return this.escaped[i] ? t.replaceAll('""', '"') : t;
  }

  isEmpty(i: number): boolean {
    return (this.ends[i] ?? 0) <= (this.starts[i] ?? 0);
  }

  /** True when field `i` equals `lower` ignoring ASCII case (`lower` is lower-case ASCII). */
  equalsIgnoreCase(i: number, lower: string): boolean {
    const s = this.starts[i] ?? 0;
    if ((this.ends[i] ?? 0) - s !== lower.length) return false;
    for (let k = 0; k < lower.length; k++) {
      const c = this.bytes[s + k] ?? 0;
      if ((c >= 0x41 && c <= 0x5a ? c | 0x20 : c) !== lower.charCodeAt(k)) return false;
    }
    return true;
  }

  /** True when field `i` holds the same bytes as `[s, e)`. */
  sameBytes(i: number, s: number, e: number): boolean {
    const fs = this.starts[i] ?? 0;
    if ((this.ends[i] ?? 0) - fs !== e - s) return false;
    for (let k = 0; k < e - s; k++) if (this.bytes[fs + k] !== this.bytes[s + k]) return false;
    return true;
  }
}

/** The columns of a Saleae async-serial header at `[ls, le)`, or undefined when it is not one. */
export function csvColumns(bytes: Uint8Array, ls: number, le: number): CsvColumns | undefined {
  // Count fields first so that every title is recorded.
  let commas = 0;
  for (let i = ls; i < le; i++) if (bytes[i] === COMMA) commas++;
  const fields = new CsvFields(bytes, commas + 1);
  if (!fields.split(ls, le)) return undefined;
  const cols: CsvColumns = { count: fields.count, time: -1, value: -1, name: -1, type: -1, errors: [] };
  for (let i = 0; i < fields.count; i++) {
    const title = fields.text(i).trim();
    const t = title.toLowerCase();
    if (cols.time < 0 && TIME_HEADER.test(t)) cols.time = i;
    else if (cols.value < 0 && VALUE_HEADER.test(t)) cols.value = i;
    else if (t === 'name') cols.name = i;
    else if (t === 'type') cols.type = i;
    else if (t.includes('error')) cols.errors.push({ index: i, title });
  }
  return cols.time >= 0 && cols.value >= 0 ? cols : undefined;
}

/**
 * A plain decimal number of seconds at `[s, e)` (`9.260826000000000`, `-0.5`, `12`) as whole
 * nanoseconds, rounded half away from zero at the tenth decimal; NaN when the field has another
 * form (an exponent, say), which then takes the slow path. Exact for times under 104 days.
 */
function secondsToNs(bytes: Uint8Array, s: number, e: number): number {
  let i = s;
  const sign = bytes[i];
  if (sign === MINUS || sign === PLUS) i++;
  let whole = 0;
  let digits = 0;
  for (; i < e; i++, digits++) {
    const d = (bytes[i] ?? 0) - ZERO;
    if (d < 0 || d > 9) break;
    whole = whole * 10 + d;
  }
  let frac = 0;
  let fracDigits = 0;
  let roundUp = 0;
  if (i < e && bytes[i] === DOT) {
    for (i++; i < e; i++, digits++, fracDigits++) {
      const d = (bytes[i] ?? 0) - ZERO;
      if (d < 0 || d > 9) break;
      if (fracDigits < 9) frac = frac * 10 + d;
      else if (fracDigits === 9) roundUp = d >= 5 ? 1 : 0;
    }
  }
  if (i !== e || digits === 0) return NaN;
  for (let k = fracDigits; k < 9; k++) frac *= 10;
  const ns = whole * 1e9 + frac + roundUp;
  return sign === MINUS ? -ns : ns;
}

function hexDigit(c: number): number {
  if (c >= 0x30 && c <= 0x39) return c - 0x30;
  const l = c | 0x20;
  return l >= 0x61 && l <= 0x66 ? l - 0x61 + 10 : -1;
}

/**
 * A byte value at `[s, e)` in hex (`0x3E`), decimal (`62`) or binary (`0b00111110`, a radix
 * Saleae can also export), or -1.
 */
function byteValue(bytes: Uint8Array, s: number, e: number): number {
  if (e <= s) return -1;
  let radix = 10;
  if (e - s > 2 && bytes[s] === ZERO) {
    const p = (bytes[s + 1] ?? 0) | 0x20;
    if (p === 0x78)
      radix = 16; // x
    else if (p === 0x62) radix = 2; // b
    if (radix !== 10) s += 2;
  }
  let v = 0;
  for (let i = s; i < e; i++) {
    const d = hexDigit(bytes[i] ?? 0);
    if (d < 0 || d >= radix) return -1;
    v = v * radix + d;
    if (v > 0xff) return -1;
  }
  return v;
}

/** Shortens text for quoting in a message. */
export function quote(text: string, max = 60): string {
  return JSON.stringify(text.length > max ? `${text.slice(0, max)}…` : text);
}

/** A growable column of numbers; doubles its capacity when full. */
class Column<T extends Float64Array | Uint8Array> {
  length = 0;
  constructor(
    public array: T,
    private readonly make: (size: number) => T,
  ) {}
  push(v: number): void {
    if (this.length === this.array.length) {
      const bigger = this.make(this.array.length * 2);
      bigger.set(this.array);
      this.array = bigger;
    }
    this.array[this.length++] = v;
  }
}

/** True when `[ls, le)` holds only spaces, tabs and CR. */
export function isBlank(bytes: Uint8Array, ls: number, le: number): boolean {
  for (let i = ls; i < le; i++) {
    const c = bytes[i];
    if (c !== SPACE && c !== TAB && c !== CR) return false;
  }
  return true;
}

/**
 * The rows of a Saleae async-serial export, a line at a time: the header's columns from the first
 * line that is not blank, then each row's byte, time (µs) and port, or the issue that leaves it
 * out. What `importSaleaeCsv` reads a file with, and the streaming reader (csv-stream.ts) a
 * piece of a file at a time: the same rules, the same issues, the same ports.
 */
export class SaleaeRows {
  cols: CsvColumns | undefined;
  readonly issues: CaptureIssue[] = [];
  /** Each analyser name's port, first seen = port 0. */
  readonly portNames = new Map<string, number>();
  /** The last row's byte, time (µs) and port, when `line` said it gave one. */
  value = 0;
  timeUs = 0;
  port = 0;
  #fields: CsvFields | undefined;
  #need = 0;
  #bytes: Uint8Array = new Uint8Array(0);
  /** File offset of the piece's byte 0. */
  #base = 0;
  // The previous row's analyser name, so that a string is only made when it changes.
  #prevNameStart = 0;
  #prevNameEnd = -1;
  #prevPort = 0;

  /** The piece of the file the next lines are in, and its file offset. */
  piece(bytes: Uint8Array, base: number): void {
    this.#bytes = bytes;
    this.#base = base;
    if (this.#fields !== undefined) this.#fields.bytes = bytes;
    // The previous name is in the last piece: looked up again by its text.
    this.#prevNameEnd = -1;
  }

  /**
   * Line `lineNo` of the piece, `[ls, le)` without its LF: true when it gave a byte.
   * @throws {CaptureFormatError} when the first line that is not blank is no async-serial header
   */
  line(ls: number, end: number, lineNo: number): boolean {
    const bytes = this.#bytes;
    let le = end;
    if (le > ls && bytes[le - 1] === CR) le--;
    if (isBlank(bytes, ls, le)) return false;
    const lineText = (): string => quote(utf8Decode(bytes, ls, le));
    const issue = (kind: CaptureIssue['kind'], why: string): false => {
      this.issues.push({ kind, offset: this.#base + ls, length: le - ls, line: lineNo, message: `line ${lineNo}: ${why}` });
      return false;
    };
    const cols = this.cols;
    const fields = this.#fields;
    if (!cols || !fields) {
      this.cols = csvColumns(bytes, ls, le);
      if (!this.cols) {
        throw new CaptureFormatError(
          `not a Saleae async-serial CSV: line ${lineNo} should be a header with a time column ("Time [s]" or "start_time") ` +
            `and a value column ("Value" or "data"), but it is ${lineText()}`,
        );
      }
      this.#fields = new CsvFields(bytes, this.cols.count);
      this.#need = Math.max(this.cols.time, this.cols.value, this.cols.name, this.cols.type) + 1;
      return false;
    }
    const need = this.#need;
    if (!fields.split(ls, le)) return issue('malformed-row', `unterminated quote in ${lineText()}`);
    if (fields.count < need) return issue('malformed-row', `expected at least ${need} columns, found ${fields.count} in ${lineText()}`);
    if (cols.type >= 0 && !fields.equalsIgnoreCase(cols.type, 'data'))
      return issue('skipped-row', `row of type ${quote(fields.text(cols.type))} is not serial data; skipped`);
    const ts = fields.starts[cols.time] ?? 0;
    const te = fields.ends[cols.time] ?? 0;
    let ns = secondsToNs(bytes, ts, te);
    if (Number.isNaN(ns)) {
      // A time that is no number of seconds (-Infinity, NaN, text) still dates a good byte:
      // kept, NaN, for the time rule to step over and report (`bad-time`) as any jump.
      const text = fields.text(cols.time);
      const seconds = DECIMAL_NUMBER.test(text) || /^[+-]?Infinity$/.test(text) ? Number(text) : NaN;
      ns = Number.isFinite(seconds) ? Math.round(seconds * 1e9) : seconds;
    }
    const value = byteValue(bytes, fields.starts[cols.value] ?? 0, fields.ends[cols.value] ?? 0);
    if (value < 0) return issue('malformed-row', `value ${quote(fields.text(cols.value))} is not a byte in hex (0x3E) or decimal (62)`);
    let flagged: string | undefined;
    for (const e of cols.errors) {
      if (e.index >= fields.count || fields.isEmpty(e.index)) continue;
      const flag = fields.text(e.index);
      if (!NO_ERROR.has(flag.toLowerCase())) {
        flagged = e.title + (flag.toLowerCase() === e.title.toLowerCase() ? '' : ` = ${flag}`);
        break;
      }
    }
    if (flagged !== undefined)
      return issue(
        'flagged-byte',
        `byte ${fields.text(cols.value)} flagged by the analyser (${flagged}); left out because its bits are unreliable`,
      );
    let port = 0;
    if (cols.name >= 0) {
      if (fields.sameBytes(cols.name, this.#prevNameStart, this.#prevNameEnd)) {
        port = this.#prevPort;
      } else {
        const name = fields.text(cols.name);
        let known = this.portNames.get(name);
        if (known === undefined) {
          if (this.portNames.size === 256) return issue('malformed-row', `analyser ${quote(name)} would be a 257th port; skipped`);
          known = this.portNames.size;
          this.portNames.set(name, known);
        }
        port = known;
        this.#prevNameStart = fields.starts[cols.name] ?? 0;
        this.#prevNameEnd = fields.ends[cols.name] ?? 0;
        this.#prevPort = port;
      }
    }
    this.value = value;
    // Whole ns to µs: one correctly rounded division, so 9260826000 ns is exactly 9260826 µs.
    this.timeUs = ns / 1e3;
    this.port = port;
    return true;
  }
}

/**
 * A Saleae Logic "Async Serial" CSV export, Logic 1 (`Time [s],Value,Parity Error,Framing
 * Error`) or Logic 2 (`name,type,start_time,duration,"data"`); columns are found by name. Each
 * row is one byte with its time, so the result has `timing: 'per-byte'`; times are in µs,
 * rounded to the nanosecond (Saleae prints 15 decimals of float noise, e.g. 9.260999999999999).
 *
 * - Values may be hex (`0x3E`), decimal (`62`) or binary (`0b00111110`); anything else (an
 *   ASCII rendering such as `'>'`) is reported as a `malformed-row` issue with its line number.
 * - A row whose parity or framing error flag is set is left out and reported (`flagged-byte`):
 *   Spektrum frames carry no checksum, so a byte with unreliable bits would pass as a wrong
 *   servo value, while a missing byte makes the decoder drop the frame, which is the truth.
 * - Logic 2 exports can hold several analysers; each distinct `name` becomes a port (first
 *   seen = port 0), listed in `meta.ports`. Rows whose `type` is not `data` are skipped.
 * - CRLF, a byte-order mark and blank lines (e.g. at the end) are accepted.
 *
 * Issue offsets are byte offsets in the file (for a string, in its UTF-8 encoding).
 *
 * @throws {CaptureFormatError} when the first non-blank line is not an async-serial header or
 *   no row gives a byte.
 * @throws {TypeError} when `input` is neither a string nor a Uint8Array.
 */
export function importSaleaeCsv(input: string | Uint8Array): Capture {
  let bytes: Uint8Array;
  if (typeof input === 'string') bytes = utf8Encode(input);
  else if (input instanceof Uint8Array) bytes = input;
  else throw new TypeError('importSaleaeCsv expects a string or a Uint8Array');
  const n = bytes.length;

  // Rows arrive in time order across every analyser; they are grouped by port at the end.
  // A Logic 1 row is about 25 bytes, so this rarely grows.
  const estimate = Math.max(16, Math.ceil(n / 24));
  const values = new Column(new Uint8Array(estimate), (s) => new Uint8Array(s));
  const times = new Column(new Float64Array(estimate), (s) => new Float64Array(s));
  const ports = new Column(new Uint8Array(estimate), (s) => new Uint8Array(s));
  const rows = new SaleaeRows();
  rows.piece(bytes, 0);
  let lineNo = 0;
  let pos = bomLength(bytes);
  while (pos < n) {
    const nl = bytes.indexOf(LF, pos);
    const ls = pos;
    const le = nl < 0 ? n : nl;
    pos = le + 1;
    lineNo++;
    if (rows.line(ls, le, lineNo)) {
      values.push(rows.value);
      times.push(rows.timeUs);
      ports.push(rows.port);
    }
  }
  const { cols, issues, portNames } = rows;
  if (!cols) throw new CaptureFormatError('not a Saleae async-serial CSV: the file has no header line (it is empty or blank)');
  const count = values.length;
  if (count === 0) {
    const first = issues[0];
    throw new CaptureFormatError(
      first
        ? `Saleae CSV has no usable bytes: all ${issues.length} row(s) were rejected (first: ${first.message})`
        : 'Saleae CSV has no usable bytes: there are no rows after the header',
    );
  }

  const meta: CaptureMeta = { source: 'saleae-csv' };
  if (portNames.size > 0) meta.ports = [...portNames.keys()].map((name) => ({ name }));
  const portCount = Math.max(1, portNames.size);

  let data: Uint8Array;
  let byteTimes: Float64Array;
  const chunkEnds = new Uint32Array(portCount);
  const chunkTimes = new Float64Array(portCount);
  const chunkPorts = new Uint8Array(portCount);
  if (portCount === 1) {
    data = values.array.slice(0, count);
    byteTimes = times.array.slice(0, count);
    chunkEnds[0] = count;
  } else {
    // Group rows by port, keeping their order within a port (a counting sort).
    const starts = new Uint32Array(portCount + 1);
    for (let i = 0; i < count; i++) starts[(ports.array[i] ?? 0) + 1]!++;
    for (let p = 0; p < portCount; p++) starts[p + 1]! += starts[p] ?? 0;
    data = new Uint8Array(count);
    byteTimes = new Float64Array(count);
    const cursor = starts.slice(0, portCount);
    for (let i = 0; i < count; i++) {
      const at = cursor[ports.array[i] ?? 0]!++;
      data[at] = values.array[i] ?? 0;
      byteTimes[at] = times.array[i] ?? NaN;
    }
    for (let p = 0; p < portCount; p++) {
      chunkEnds[p] = starts[p + 1] ?? 0;
      chunkPorts[p] = p;
    }
  }
  // Every port has at least one byte (a port exists because a row gave it one).
  for (let p = 0; p < portCount; p++) chunkTimes[p] = byteTimes[(chunkEnds[p] ?? 0) - 1] ?? NaN;

  return stepOverBadTimes({
    kind: 'saleae-csv',
    meta,
    timing: 'per-byte',
    bytes: data,
    chunkEnds,
    chunkTimesUs: chunkTimes,
    chunkPorts,
    byteTimesUs: byteTimes,
    events: [],
    issues,
  });
}
