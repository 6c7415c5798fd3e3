/**
 * The whole worker in Node: the dispatcher built with a fake host (post, clock) and stand-in
 * ports, commands through its queue in order, sources closed while their data is on the way.
 */
import { describe, expect, it } from 'vitest';
import { encodeCapture } from '../src/capture/writer.js';
import { parseCapture } from '../src/capture/reader.js';
import { preset } from '../src/simulator/presets.js';
import { simulate } from '../src/simulator/simulator.js';
import { Dispatcher } from '../src/worker/dispatcher.js';
import { framesFile } from '../src/worker/frames-export.js';
import type { ToWorker } from '../src/worker/protocol.js';
import type { ReportRequest } from '../src/worker/report-worker.js';
import { usbChunks } from './feeds.js';
import { fakeHost } from './worker-fakes.js';

/** A two-port .sscap: an internal remote on port 0, an external one on port 1, 3 s. */
function twoPortCapture(): ArrayBuffer {
  const a = simulate({ ...preset('dsmx-11ms-2048-internal'), seed: 1 }, 3_000_000);
  const b = simulate({ ...preset('dsmx-11ms-2048-external'), seed: 2 }, 3_000_000);
  const records = [
    ...usbChunks(a.bytes, a.timesUs).map((c) => ({ type: 'data' as const, bytes: c.bytes, timeUs: c.timeUs, port: 0 })),
    ...usbChunks(b.bytes, b.timesUs).map((c) => ({ type: 'data' as const, bytes: c.bytes, timeUs: c.timeUs + 3, port: 1 })),
  ].sort((x, y) => x.timeUs - y.timeUs);
  const file = encodeCapture({ baudRate: 115200 }, records);
  return file.buffer.slice(file.byteOffset, file.byteOffset + file.byteLength) as ArrayBuffer;
}

/** A SerialPort stand-in: an idle line, until `unplug()`. */
class FakePort {
  opens = 0;
  closes = 0;
  #readable: ReadableStream<Uint8Array> | null = null;
  #line: ReadableStreamDefaultController<Uint8Array> | undefined;
  async open(): Promise<void> {
    this.opens++;
    this.#readable = new ReadableStream<Uint8Array>({
      start: (controller) => {
        this.#line = controller;
      },
    });
  }
  /** Bytes arrive on the line. */
  receive(bytes: Uint8Array): void {
    this.#line?.enqueue(bytes);
  }
  /** The device goes away: reading fails as WebSerial's does. */
  unplug(): void {
    const gone = new Error('The device has been lost.');
    gone.name = 'NetworkError';
    this.#line?.error(gone);
  }
  get readable(): ReadableStream<Uint8Array> | null {
    return this.#readable;
  }
  async close(): Promise<void> {
    this.closes++;
    this.#readable = null;
  }
  async setSignals(): Promise<void> {}
  getInfo(): SerialPortInfo {
    return { usbVendorId: 0x0403, usbProductId: 0x6001 };
  }
}

function setup(findPort?: () => Promise<SerialPort | undefined>) {
  const fake = fakeHost();
  const reports: ReportRequest[] = [];
  const worker = new Dispatcher(fake.host, {
    findPort,
    makeReport: async (request) => {
      reports.push(request);
      // Frames are made as the helper makes them; a report is a stand-in.
      const { of } = request;
      if (request.frames !== undefined && !('bytes' in of)) {
        const capture = 'capture' in of ? of.capture : parseCapture(new Uint8Array(await of.file.arrayBuffer()));
        const file = framesFile(capture, { ...request.frames, resolution: request.resolution });
        return { data: file.data, frames: file.frames };
      }
      return { data: new TextEncoder().encode('report').buffer as ArrayBuffer };
    },
  });
  const send = async (...messages: ToWorker[]): Promise<void> => {
    for (const m of messages) worker.receive(m);
    await worker.queue.idle();
  };
  return { ...fake, worker, send, reports };
}

describe('the dispatcher', () => {
  it('runs commands one after another in the order they came, each to its end', async () => {
    const { send, posts, of } = setup();
    const data = twoPortCapture();
    await send(
      { type: 'replay-open', name: 'two.sscap', file: new Blob([data]) },
      { type: 'replay-pause' },
      { type: 'replay-seek', timeUs: 2_000_000 },
      { type: 'set-label', source: 1, label: 'Tail' },
    );
    const types = posts.map((p) => p.type);
    expect(types.indexOf('overview')).toBeGreaterThan(-1);
    // The capture was open (playing) before the pause and the seek were handled.
    const statuses = of('replay').map((r) => r.replay);
    expect(statuses[0]).toMatchObject({ name: 'two.sscap', playing: true });
    expect(statuses.at(-1)).toMatchObject({ playing: false, positionUs: 2_000_000 });
    const sources = of('sources').at(-1)?.sources ?? [];
    expect(sources.map((s) => [s.id, s.label, s.state, s.kind])).toEqual([
      [0, 'A', 'paused', 'replay'],
      [1, 'Tail', 'paused', 'replay'],
    ]);
  });

  it("exports a replayed remote's decoded frames through the helper, named after the capture and the remote", async () => {
    const { send, of, reports } = setup();
    const data = twoPortCapture();
    await send({ type: 'replay-open', name: 'two.sscap', file: new Blob([data]) }, { type: 'replay-pause' });
    await send({ type: 'export-frames', source: 1, format: 'jsonl', fromUs: null, toUs: null });
    expect(reports.at(-1)?.frames).toEqual({ port: 1, format: 'jsonl', fromUs: null, toUs: null });
    const file = of('export-ready').at(-1);
    expect(file?.name).toBe('two-B.frames.jsonl');
    const want = framesFile(parseCapture(new Uint8Array(data)), { port: 1, format: 'jsonl', fromUs: null, toUs: null, resolution: 'auto' });
    expect(new TextDecoder().decode(file?.data)).toBe(new TextDecoder().decode(want.data));
    expect(want.frames).toBeGreaterThan(250);
    // A span with no frame: said, and nothing saved.
    const before = of('export-ready').length;
    await send({ type: 'export-frames', source: 1, format: 'csv', fromUs: 0, toUs: 1 });
    expect(of('export-ready').length).toBe(before);
    expect(of('notice').at(-1)?.title).toBe('No frames to export');
  });

  it('tells the user of a command that failed, and goes on with the next', async () => {
    const { send, of, worker } = setup(async () => {
      throw new Error('getPorts broke');
    });
    await send({ type: 'serial-open', port: { index: 0 } }, { type: 'demo-start' });
    expect(of('notice').map((n) => n.title)).toContain('Something went wrong in the worker');
    expect(worker.registry.list().map((s) => s.kind)).toEqual(['demo', 'demo']);
    await send({ type: 'close-all' });
  });

  it('opens a port and closes it in that order, however long opening takes', async () => {
    const port = new FakePort();
    const { send, worker, of, clock } = setup(async () => {
      // getPorts() takes a while: the close must still wait for the open.
      await new Promise((r) => setTimeout(r, 20));
      return port as unknown as SerialPort;
    });
    worker.receive({ type: 'serial-open', port: { index: 0, usbVendorId: 0x0403, usbProductId: 0x6001 } });
    worker.receive({ type: 'serial-close', source: 0 });
    await worker.queue.idle();
    expect(port.opens).toBe(1);
    expect(port.closes).toBe(1);
    expect(worker.registry.size).toBe(0);
    const states = of('sources').map((m) => m.sources.map((s) => s.state).join());
    expect(states).toContain('reading');
    expect(states.at(-1)).toBe('');
    // Nothing is left ticking.
    clock.advance(1000);
    expect(clock.pending).toBe(0);
    await send({ type: 'close-all' });
  });

  it('keeps an unplugged adapter as a lost remote, tries it every second, and takes it back as the same remote', async () => {
    const port = new FakePort();
    let plugged = true;
    const { send, worker, clock, of } = setup(async () => (plugged ? (port as unknown as SerialPort) : undefined));
    await send({ type: 'serial-open', port: { index: 0, usbVendorId: 0x0403, usbProductId: 0x6001 } });
    const a = worker.registry.get(0);
    expect(a?.state).toBe('reading');
    plugged = false;
    port.unplug();
    await new Promise((r) => setTimeout(r, 0));
    expect(a?.state).toBe('lost');
    // Tries while it is away change nothing.
    clock.advance(3000);
    await worker.queue.idle();
    expect(a?.state).toBe('lost');
    plugged = true;
    clock.advance(1000);
    await worker.queue.idle();
    expect(worker.registry.get(0)).toBe(a);
    expect(a?.state).toBe('reading');
    expect(port.opens).toBe(2);
    expect(of('notice').map((n) => n.title)).toEqual(['Remote A: the adapter was unplugged', 'Remote A reconnected']);
    // Back: no more tries.
    clock.advance(5000);
    await worker.queue.idle();
    expect(port.opens).toBe(2);
    await send({ type: 'close-all' });
  });

  it('counts no hold, failsafe or missed frame for the time an unplugged adapter is away', async () => {
    const port = new FakePort();
    let plugged = true;
    const { send, worker, clock, batches } = setup(async () => (plugged ? (port as unknown as SerialPort) : undefined));
    await send({ type: 'serial-open', port: { index: 0, usbVendorId: 0x0403, usbProductId: 0x6001 } });
    // A second of frames at their pace, then the adapter goes.
    const sim = simulate({ ...preset('dsmx-11ms-2048-internal'), seed: 5 }, 1_000_000);
    for (let i = 0; i < sim.bytes.length; i += 16) {
      port.receive(sim.bytes.slice(i, i + 16));
      await new Promise((r) => setTimeout(r, 0));
      clock.advance(11);
    }
    plugged = false;
    port.unplug();
    await new Promise((r) => setTimeout(r, 0));
    clock.advance(3000);
    await worker.queue.idle();
    worker.batcher.flush();
    const last = batches()
      .filter((b) => b.source === 0)
      .at(-1)?.batch;
    expect(last?.counters.frames).toBeGreaterThan(80);
    expect(last?.link).toMatchObject({ holds: 0, failsafes: 0, missedFrames: 0, state: 'waiting' });
    // Back, and frames again: still nothing counted for the time away.
    plugged = true;
    clock.advance(1000);
    await worker.queue.idle();
    expect(worker.registry.get(0)?.state).toBe('reading');
    for (let i = 0; i < 160; i += 16) {
      port.receive(sim.bytes.slice(i, i + 16));
      await new Promise((r) => setTimeout(r, 0));
      clock.advance(11);
    }
    worker.batcher.flush();
    const back = batches()
      .filter((b) => b.source === 0)
      .at(-1)?.batch;
    expect(back?.link).toMatchObject({ holds: 0, failsafes: 0, missedFrames: 0, state: 'live' });
    await send({ type: 'close-all' });
  });

  it('gives a source removed while its data is on the way none of it; the others go on', async () => {
    const { send, worker, clock, posts, batches } = setup();
    await send({ type: 'demo-start' });
    clock.advance(200);
    const batchesOf = (from: number, id: number) => batches(from).filter((b) => b.source === id).length;
    expect(batchesOf(0, 0)).toBeGreaterThan(5);
    expect(batchesOf(0, 1)).toBeGreaterThan(5);
    // Remote B's next chunk is already generated when its close is handled.
    worker.receive({ type: 'serial-close', source: 1 });
    worker.sink(1, new Uint8Array(64), clock.now() * 1000);
    await worker.queue.idle();
    const from = posts.length;
    worker.sink(1, new Uint8Array(64), clock.now() * 1000);
    clock.advance(200);
    expect(batchesOf(from, 1)).toBe(0);
    expect(batchesOf(from, 0)).toBeGreaterThan(5);
    expect(worker.registry.get(1)).toBeUndefined();
    await send({ type: 'close-all' });
    // Nothing is left ticking (the doctor's last throttled post aside, once).
    clock.advance(1000);
    expect(clock.pending).toBe(0);
  });

  it('plays a capture to its end at full speed on the fake clock, then freezes every source there', async () => {
    const { send, clock, of, worker, reports } = setup();
    const file = new Blob([twoPortCapture()]);
    await send({ type: 'replay-open', name: 'two.sscap', file }, { type: 'replay-speed', speed: 0 });
    for (let i = 0; i < 100 && of('replay').at(-1)?.replay?.ended !== true; i++) clock.advance(10);
    const last = of('replay').at(-1)?.replay;
    expect(last).toMatchObject({ ended: true, playing: false });
    expect(last?.positionUs).toBe(last?.endUs);
    expect(worker.registry.list().map((s) => s.state)).toEqual(['ended', 'ended']);
    expect(last?.frames).toBe(worker.registry.list().reduce((n, s) => n + s.engine.decoder.stats.frames, 0));
    // The replay's timer is gone (the doctor's last throttled post aside, once).
    clock.advance(1000);
    expect(clock.pending).toBe(0);
    // A report is made of the capture being replayed, from its file (the worker keeps no copy of it).
    await send({ type: 'report', format: 'json' });
    await new Promise((r) => setTimeout(r, 0));
    expect(of('export-ready').at(-1)?.name).toBe('two.report.json');
    const of0 = reports[0]?.of;
    expect(of0 !== undefined && 'file' in of0 && of0.file).toBe(file);
    expect(reports[0]).toMatchObject({ name: 'two.sscap', format: 'json', resolution: 'auto' });
    // Closing ends the replay for the page.
    await send({ type: 'close-all' });
    expect(of('replay').at(-1)?.replay).toBeNull();
  });
});
