/**
 * A File read forward a piece at a time (piece-reader.ts): the pieces are the file's bytes,
 * read into the buffer handed back when there is one, by its byte stream or a slice at a time
 * (also from a read of the stream that never answers on), and a file that ends before its size
 * says so.
 */
import { describe, expect, it } from 'vitest';
import { PieceReader, type ReadableFile } from '../src/worker/replay/piece-reader.js';

const bytes = Uint8Array.from({ length: 100_000 }, (_, i) => (i * 31 + (i >> 8)) & 0xff);

async function readAll(reader: PieceReader, spares: ArrayBuffer[] = []): Promise<Uint8Array[]> {
  const pieces: Uint8Array[] = [];
  for (let piece = await reader.next(spares.shift()); piece !== null; piece = await reader.next(spares.shift())) pieces.push(piece.slice());
  return pieces;
}

function joined(pieces: Uint8Array[]): number[] {
  return pieces.flatMap((p) => Array.from(p));
}

describe('reading a file a piece at a time', () => {
  it('gives the file in pieces of the size asked, the last one shorter, by its byte stream into the buffers handed back', async () => {
    const reader = new PieceReader(new Blob([bytes]), 30_000);
    const spares = [new ArrayBuffer(30_000), new ArrayBuffer(30_000), new ArrayBuffer(100)];
    const handed = [...spares];
    const pieces = await readAll(reader, spares);
    expect(pieces.map((p) => p.length)).toEqual([30_000, 30_000, 30_000, 10_000]);
    expect(joined(pieces)).toEqual(Array.from(bytes));
    // The two of the piece size were read into (the stream took them over); the one of another size was not.
    expect(handed.map((b) => b.byteLength)).toEqual([0, 0, 100]);
    expect(reader.at).toBe(bytes.length);
  });

  it('reads a slice at a time where the file has no byte stream', async () => {
    const blob = new Blob([bytes]);
    const file: ReadableFile = {
      size: blob.size,
      slice: (start, end) => blob.slice(start, end),
      stream: () => {
        throw new TypeError('no byte stream here');
      },
    };
    expect(joined(await readAll(new PieceReader(file, 40_000)))).toEqual(Array.from(bytes));
  });

  it('reads a slice at a time from a read of the byte stream that never answers, the stream cancelled', async () => {
    const blob = new Blob([bytes]);
    const stream = blob.stream();
    let reads = 0;
    let cancelled = 0;
    // The file's own stream, whose third read never answers (as Chromium's sometimes does).
    const stalling = {
      getReader: () => {
        const inner = stream.getReader({ mode: 'byob' });
        return {
          read: (view: Uint8Array<ArrayBuffer>) => (++reads === 3 ? new Promise(() => {}) : inner.read(view)),
          cancel: async () => {
            cancelled++;
          },
        };
      },
    } as unknown as ReadableStream<Uint8Array<ArrayBuffer>>;
    const file: ReadableFile = { size: blob.size, slice: (start, end) => blob.slice(start, end), stream: () => stalling };
    const reader = new PieceReader(file, 30_000, 20);
    const pieces = await readAll(reader);
    expect(joined(pieces)).toEqual(Array.from(bytes));
    expect(pieces.map((p) => p.length)).toEqual([30_000, 30_000, 30_000, 10_000]);
    // Given up once, after its wait; not asked again.
    expect(reads).toBe(3);
    expect(cancelled).toBe(1);
  });

  it('says so when the file ends before its size', async () => {
    const blob = new Blob([bytes.subarray(0, 50_000)]);
    const file: ReadableFile = { size: bytes.length, slice: (start, end) => blob.slice(start, end), stream: () => blob.stream() };
    const reader = new PieceReader(file, 30_000);
    expect((await reader.next())?.length).toBe(30_000);
    await expect(reader.next()).rejects.toThrow('the file ended after 50000 of 100000 bytes');
  });
});
