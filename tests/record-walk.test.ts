/**
 * Walking an intact .sscap's data records from a Blob a slice at a time (record-walk.ts): the
 * same chunks parseCapture reads, whatever the slice size; a file that is not intact is refused.
 */
import { describe, expect, it } from 'vitest';
import { encodeCapture } from '../src/capture/writer.js';
import { parseCapture } from '../src/capture/reader.js';
import { recordTimeUs, walkDataRecords } from '../src/capture/record-walk.js';
import { CaptureFormatError } from '../src/capture/model.js';

/** Data records of 1–40 bytes (one of 3000) on three ports, an event every 50, one record far bigger than a slice. */
function file(): Uint8Array {
  const records: Parameters<typeof encodeCapture>[1][number][] = [];
  let seed = 7;
  const next = () => (seed = (seed * 1103515245 + 12345) >>> 0);
  for (let k = 0; k < 600; k++) {
    if (k % 50 === 0) records.push({ type: 'event', text: `event ${k}`, timeUs: k * 1000, port: k % 3 });
    const length = k === 300 ? 3000 : 1 + (next() % 40);
    records.push({ type: 'data', bytes: Uint8Array.from({ length }, () => next() & 0xff), timeUs: k * 1000 + 0.5, port: k % 3 });
  }
  return encodeCapture({ baudRate: 115200 }, records);
}

/**
 * `readAhead` slices asked for at once, each answered after a delay of its own (as reads on
 * another thread may be), so that a later slice often arrives before an earlier one.
 */
function unevenReads(bytes: Uint8Array) {
  let n = 0;
  const blob = new Blob([bytes.slice()]);
  return {
    size: blob.size,
    slice: (start: number, end: number) => blob.slice(start, end),
    view: (start: number, end: number) =>
      new Promise<Uint8Array>((resolve) => setTimeout(() => resolve(bytes.slice(start, end)), (n++ * 7) % 5)),
  };
}

async function walk(bytes: Uint8Array, sliceBytes?: number, checked = true, readAhead?: number) {
  const got: { bytes: number[]; timeUs: number; port: number }[] = [];
  const walked = await walkDataRecords(
    readAhead === undefined ? new Blob([bytes.slice()]) : unevenReads(bytes),
    (b, view, start, end, port) => got.push({ bytes: Array.from(b.subarray(start, end)), timeUs: recordTimeUs(view, start), port }),
    { ...(sliceBytes === undefined ? {} : { sliceBytes }), checked: () => checked, ...(readAhead === undefined ? {} : { readAhead }) },
  );
  return { walked, got };
}

describe('walking the data records of an intact capture', () => {
  const bytes = file();
  const capture = parseCapture(bytes);
  const want = Array.from(capture.chunkEnds, (end, i) => ({
    bytes: Array.from(capture.bytes.subarray(i === 0 ? 0 : capture.chunkEnds[i - 1], end)),
    timeUs: capture.chunkTimesUs[i],
    port: capture.chunkPorts[i],
  }));

  it('hands over the chunks parseCapture reads, in order, with their counts, for any slice size and reads ahead', async () => {
    expect(capture.issues).toEqual([]);
    expect(want.length).toBe(600);
    for (const [slice, ahead] of [[1], [17], [100], [4096], [undefined], [17, 3], [100, 2], [4096, 4]]) {
      const { walked, got } = await walk(bytes, slice, true, ahead);
      expect({ slice, ahead, walked }).toEqual({
        slice,
        ahead,
        walked: {
          chunks: 600,
          dataBytes: capture.bytes.length,
          header: { meta: capture.meta, version: capture.version, headerLength: capture.headerLength },
        },
      });
      expect(got).toEqual(want);
    }
  });

  it('refuses a read that gives fewer bytes than asked: the slices after it would leave a hole', async () => {
    let reads = 0;
    const short = {
      size: bytes.length,
      slice: (start: number, end: number) => new Blob([bytes.slice(start, end)]),
      view: async (start: number, end: number) => bytes.slice(start, ++reads === 3 ? end - 1 : end),
    };
    const walking = walkDataRecords(short, () => {}, { sliceBytes: 1000, readAhead: 2 });
    await expect(walking).rejects.toThrow('a read of the file gave 999 bytes of 1000');
    await expect(walking).rejects.not.toBeInstanceOf(CaptureFormatError);
  });

  it('stops when asked between slices', async () => {
    let slices = 0;
    const walked = await walkDataRecords(new Blob([bytes.slice()]), () => {}, { goOn: () => ++slices < 3, sliceBytes: 1000 });
    expect([walked, slices]).toEqual([null, 3]);
  });

  it('checks the CRC of the records asked for', async () => {
    // A payload byte of the 101st data record (port 100 % 3 = 1) flipped.
    let p = capture.headerLength;
    const view = new DataView(bytes.buffer, bytes.byteOffset);
    for (let data = 0; ; ) {
      if (bytes[p + 2] === 1 && data++ === 100) break;
      p += 20 + view.getUint32(p + 4, true);
    }
    const damaged = bytes.slice();
    damaged[p + 16] = (damaged[p + 16] ?? 0) ^ 4;
    const blob = () => new Blob([damaged]);
    await expect(walkDataRecords(blob(), () => {}, { checked: (port) => port === 1 })).rejects.toThrow(`damaged record at offset ${p}`);
    await expect(walkDataRecords(blob(), () => {}, { checked: (port) => port !== 1 })).resolves.toMatchObject({ chunks: 600 });
  });

  it('hands over the runs of whole records walked, events among them, and checks the events when asked', async () => {
    const runs = async (file: Uint8Array, sliceBytes: number, eventsChecked: boolean) => {
      const got: number[] = [];
      await walkDataRecords(new Blob([file.slice()]), () => {}, {
        sliceBytes,
        eventsChecked,
        runs: (b, view, from, to) => {
          expect(view.buffer).toBe(b.buffer);
          got.push(...b.subarray(from, to));
        },
      });
      return Uint8Array.from(got);
    };
    // The runs, one after the other, are every record of the file (one cut across slices joined whole).
    for (const slice of [100, 4096]) expect(await runs(bytes, slice, true)).toEqual(bytes.subarray(capture.headerLength));
    // The text of the fifth event changed: its CRC fails when events are checked, whether or not data records are.
    const damaged = bytes.slice();
    const at = Buffer.from(damaged).indexOf('event 200');
    damaged[at + 6] = '7'.charCodeAt(0);
    await expect(runs(damaged, 100, true)).rejects.toThrow(/damaged record at offset/);
    await expect(runs(damaged, 100, false)).resolves.toHaveLength(bytes.length - capture.headerLength);
    await expect(walk(damaged, 100)).resolves.toMatchObject({ walked: { chunks: 600 } });
  });

  it('says where a file cut off inside a record ends, having walked every record before it', async () => {
    // The last data record (the final index follows it: its payload length is 12 bytes from
    // the end) cut in its CRC, in its header, and after its first byte.
    const indexAt = bytes.length - 20 - new DataView(bytes.buffer, bytes.byteOffset).getUint32(bytes.length - 12, true);
    const last = capture.chunkEnds.length - 1;
    const lastStart = indexAt - (20 + (capture.chunkEnds[last] ?? 0) - (capture.chunkEnds[last - 1] ?? 0));
    for (const end of [indexAt - 3, lastStart + 9, lastStart + 1]) {
      const cut = bytes.subarray(0, end);
      const parsed = parseCapture(cut);
      expect(parsed.issues.map((i) => [i.kind, i.offset])).toEqual([['truncated-record', lastStart]]);
      const { walked, got } = await walk(cut, 1000);
      expect({ cutAt: walked?.cutAt, chunks: walked?.chunks, got: got.length }).toEqual({ cutAt: lastStart, chunks: last, got: last });
    }
    const { walked } = await walk(bytes, 1000);
    expect(walked?.cutAt).toBeUndefined();
  });

  it('refuses a file whose records do not lead to its end, or whose header is damaged', async () => {
    const stray = new Uint8Array(bytes.length + 1);
    stray.set(bytes.subarray(0, 5000));
    stray.set(bytes.subarray(5000), 5001);
    await expect(walk(stray, 1000, false)).rejects.toThrow(/no intact record header/);
    const header = bytes.slice();
    header[20] = (header[20] ?? 0) ^ 1;
    await expect(walk(header, 1000)).rejects.toThrow(/header is damaged/);
  });
});
