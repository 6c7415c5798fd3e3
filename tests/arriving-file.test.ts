/**
 * A file arriving piece by piece (arriving-file.ts), read forward as it comes: what walkDataRecords
 * reads from it is the file's bytes, whatever the pieces; a read waits for its bytes, a failure
 * reaches every read, and bytes already read past are let go.
 */
import { describe, expect, it } from 'vitest';
import { ArrivingFile } from '../src/worker/replay/arriving-file.js';

const bytes = Uint8Array.from({ length: 1000 }, (_, i) => (i * 7) & 0xff);

async function read(file: ArrivingFile, start: number, end: number): Promise<number[]> {
  return Array.from(new Uint8Array(await file.slice(start, end).arrayBuffer()));
}

describe('a file arriving in pieces', () => {
  it('serves any forward range once its bytes have arrived, across pieces', async () => {
    const file = new ArrivingFile(bytes.length);
    const waiting = read(file, 0, 300);
    let served = false;
    void waiting.then(() => {
      served = true;
    });
    file.push(bytes.subarray(0, 100));
    file.push(bytes.subarray(100, 250));
    await new Promise((resolve) => setTimeout(resolve, 0));
    expect(served).toBe(false);
    file.push(bytes.subarray(250, 700));
    expect(await waiting).toEqual(Array.from(bytes.subarray(0, 300)));
    expect(await read(file, 290, 690)).toEqual(Array.from(bytes.subarray(290, 690)));
    file.push(bytes.subarray(700));
    expect(await read(file, 650, 2000)).toEqual(Array.from(bytes.subarray(650)));
    await expect(read(file, 10, 20)).rejects.toThrow(/let go/);
  });

  it('hands over a piece that owns its buffer as it is', async () => {
    const file = new ArrivingFile(200);
    const piece = bytes.slice(0, 200);
    file.push(piece);
    expect(await file.slice(0, 200).arrayBuffer()).toBe(piece.buffer);
  });

  it('reads within one piece as a view of it, across pieces as a copy, and keeps its offsets when a piece read past is transferred away', async () => {
    const file = new ArrivingFile(bytes.length);
    const pieces = [bytes.slice(0, 400), bytes.slice(400, 800), bytes.slice(800)];
    for (const piece of pieces) file.push(piece);
    const inside = await file.view(100, 300);
    expect(inside.buffer).toBe(pieces[0]?.buffer);
    expect(Array.from(inside)).toEqual(Array.from(bytes.subarray(100, 300)));
    const across = await file.view(350, 450);
    expect(across.buffer).not.toBe(pieces[0]?.buffer);
    expect(Array.from(across)).toEqual(Array.from(bytes.subarray(350, 450)));
    // The first piece goes to another thread while still held here (a read past it may wait for
    // bytes still to come): its length reads 0 from then on.
    structuredClone(pieces[0], { transfer: [pieces[0]?.buffer as ArrayBuffer] });
    expect(pieces[0]?.length).toBe(0);
    expect(Array.from(await file.view(790, 900))).toEqual(Array.from(bytes.subarray(790, 900)));
    expect(Array.from(await file.view(850, 1000))).toEqual(Array.from(bytes.subarray(850, 1000)));
  });

  it('fails every read, waiting or to come, and lets go of what it holds, when the file cannot be read', async () => {
    const file = new ArrivingFile(bytes.length);
    file.push(bytes.subarray(0, 100));
    const waiting = read(file, 50, 500);
    file.fail(new Error('NotReadableError'));
    await expect(waiting).rejects.toThrow('NotReadableError');
    await expect(read(file, 100, 600)).rejects.toThrow('NotReadableError');
    // What had arrived is let go too: nothing more is read.
    await expect(read(file, 60, 90)).rejects.toThrow('NotReadableError');
  });
});
