/**
 * The worker's doctor (src/worker/diagnosis.ts) without a browser: findings reach the page only
 * when they change and at most 4× a second, a removed port leaves nothing behind, and the
 * "listen at the other speed" probe reopens the port at the finding's setting, confirms what it
 * hears there, and returns to 115200. The port is a stand-in with WebSerial's shape.
 */
import { describe, expect, it } from 'vitest';
import type { DoctorFinding } from '../src/report/doctor-types.js';
import { importRaw } from '../src/capture/raw.js';
import { crsfStream } from '../src/simulator/protocols.js';
import { receiveAs } from '../src/simulator/line.js';
import { Diagnosis, type ProbeHooks } from '../src/worker/diagnosis.js';
import { Engine } from '../src/worker/engine.js';
import type { FromWorker } from '../src/worker/protocol.js';
import { SerialSource } from '../src/worker/sources/serial.js';

const nowUs = (): number => performance.now() * 1000;

/** A SerialPort stand-in: `play(options)` gives what the line delivers at that setting. */
class FakePort {
  readonly opened: SerialOptions[] = [];
  #readable: ReadableStream<Uint8Array> | null = null;
  constructor(readonly play: (options: SerialOptions) => Uint8Array[]) {}
  async open(options: SerialOptions): Promise<void> {
    this.opened.push(options);
    const chunks = this.play(options);
    this.#readable = new ReadableStream<Uint8Array>({
      start(controller) {
        for (const c of chunks) controller.enqueue(c);
        // Then nothing more until the reader is cancelled, as an idle line.
      },
    });
  }
  get readable(): ReadableStream<Uint8Array> | null {
    return this.#readable;
  }
  async close(): Promise<void> {
    this.#readable = null;
  }
  async setSignals(): Promise<void> {}
  getInfo(): SerialPortInfo {
    return {};
  }
}

function setup() {
  const posts: FromWorker[] = [];
  const diagnosis = new Diagnosis(
    (m) => posts.push(m),
    nowUs,
    () => [0],
  );
  diagnosis.reset();
  const engine = new Engine({ resolution: 'auto', jitterUs: 20_000 });
  diagnosis.attach(0, engine, 'A');
  const findings = (): DoctorFinding[] => {
    diagnosis.tick(true);
    const last = posts.filter((p) => p.type === 'diagnosis').at(-1);
    return last?.type === 'diagnosis' ? last.diagnosis.findings : [];
  };
  return { posts, diagnosis, engine, findings };
}

describe("the worker's doctor", () => {
  it('posts the findings when they change, at most every 250 ms, and the last change after that', async () => {
    const { posts, diagnosis } = setup();
    const count = () => posts.filter((p) => p.type === 'diagnosis').length;
    const before = count();
    diagnosis.open(0, nowUs() - 1_500_000);
    diagnosis.tick();
    diagnosis.tick();
    diagnosis.tick();
    // Throttled: one more post at most right now, and the change goes out within 250 ms.
    await new Promise((r) => setTimeout(r, 300));
    const last = posts.filter((p) => p.type === 'diagnosis').at(-1);
    expect(last?.type === 'diagnosis' && last.diagnosis.findings.map((f) => f.code)).toEqual(['nothing-arrives']);
    expect(count() - before).toBeLessThanOrEqual(2);
  });

  it('forgets a removed port: a remote given its number later starts clean', () => {
    const { diagnosis, findings } = setup();
    diagnosis.open(0, nowUs() - 2_000_000);
    expect(findings().map((f) => f.code)).toEqual(['nothing-arrives']);
    diagnosis.remove(0);
    expect(findings()).toEqual([]);
  });

  it('listens at 420000 when asked, hears CRSF there, returns to 115200, and the finding becomes certain', async () => {
    const { diagnosis, engine, findings } = setup();
    // CRSF seen by a 115200 UART: bytes and framing errors.
    const at115200 = receiveAs(crsfStream({ durationUs: 1_000_000 }));
    const crsf = receiveAs(crsfStream({ durationUs: 600_000 }), { baudRate: 420_000 });
    expect(crsf.errors).toEqual([]);
    const feed = () => {
      const t = nowUs();
      engine.push(at115200.bytes, t, 0);
      for (const _ of at115200.errors) diagnosis.lineError(0, 'FramingError', t);
    };
    const port = new FakePort((o) => (o.baudRate === 420_000 ? [crsf.bytes.subarray(0, 300), crsf.bytes.subarray(300)] : []));
    const serial = new SerialSource(nowUs, { data: (b, t) => engine.push(b, t, 0), lineError: () => undefined, lost: () => undefined });
    await serial.open(port as unknown as SerialPort);
    diagnosis.open(0, nowUs());
    feed();
    const before = findings().find((f) => f.code === 'wrong-speed');
    expect(before?.confirm).toMatchObject({ baudRate: 420_000, parity: 'none', stopBits: 1 });

    const events: string[] = [];
    const states: string[] = [];
    const hooks: ProbeHooks = { nowUs, event: (text) => events.push(text), data: () => undefined, state: (s) => states.push(s) };
    const problem = await diagnosis.confirm(0, serial, undefined, before!.confirm!, hooks);
    expect(problem).toBeNull();
    expect(port.opened.map((o) => [o.baudRate, o.parity, o.stopBits])).toEqual([
      [115_200, 'none', 1],
      [420_000, 'none', 1],
      [115_200, 'none', 1],
    ]);
    expect(events).toEqual(['port opened at 420000 baud', 'port opened at 115200 baud']);
    expect(states).toEqual(['probing', 'reading']);
    expect(serial.port).toBe(port);

    feed();
    const after = findings();
    const f = after.find((x) => x.code === 'crsf');
    expect(f?.confidence).toBe('certain');
    expect(f?.evidence.some((e) => /Confirmed: \d+ valid CRSF .* packets when listening at 420000 baud/.test(e.text))).toBe(true);
    expect(after.map((x) => x.code)).not.toContain('wrong-speed');
    await serial.close();
  });

  it('refuses a line setting the doctor did not ask for, without touching the port', async () => {
    const { diagnosis } = setup();
    const port = new FakePort(() => []);
    const serial = new SerialSource(nowUs, { data: () => undefined, lineError: () => undefined, lost: () => undefined });
    await serial.open(port as unknown as SerialPort);
    const hooks: ProbeHooks = { nowUs, event: () => undefined, data: () => undefined, state: () => undefined };
    await expect(
      diagnosis.confirm(0, serial, undefined, { baudRate: 9600, parity: 'none', stopBits: 1, listenUs: 500_000, note: '' }, hooks),
    ).resolves.toMatch(/Not a line setting/);
    expect(port.opened).toHaveLength(1);
    await serial.close();
  });
});

describe('the worker doctor on a replayed file without a Spektrum stream', () => {
  it('says so plainly as it plays (on the replay pace), and at the end of a file too short for that', () => {
    for (const length of [20_000, 300]) {
      let clock = 0;
      const posts: FromWorker[] = [];
      const diagnosis = new Diagnosis(
        (m) => posts.push(m),
        () => clock,
        () => [],
      );
      const bytes = Uint8Array.from({ length }, (_, i) => (i * 37 + (i >> 3)) & 0xff);
      bytes.set([0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a]);
      const raw = importRaw(bytes);
      diagnosis.replay(raw.timing, raw.events, 0);
      const engine = new Engine({ resolution: 'auto', jitterUs: 0 });
      diagnosis.attach(0, engine, 'Port 0');
      // As the replay feeds an untimed file: 16 bytes every 11 ms, without a time.
      for (let at = 0; at < bytes.length; at += 16) {
        clock += 11_000;
        engine.push(bytes.subarray(at, at + 16), undefined, 0);
      }
      const codes = (): string[] => {
        diagnosis.tick(true);
        const last = posts.filter((p) => p.type === 'diagnosis').at(-1);
        return last?.type === 'diagnosis' ? last.diagnosis.findings.map((f) => f.code) : [];
      };
      if (length > 10_000) expect(codes()).toContain('no-satellite');
      else {
        expect(codes()).not.toContain('no-satellite');
        diagnosis.ended();
        expect(codes()).toContain('no-satellite');
      }
    }
  });
});
