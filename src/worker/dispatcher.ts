/**
 * The worker's parts, made once and wired together, and every command from the page dispatched
 * to them in the order it came (one queue: a command runs to its end before the next starts).
 * Built with a `Host` (post and clock), so the whole worker runs in Node with fakes; worker.ts
 * gives it the browser's.
 */
import { USB_CHUNK_JITTER_US } from '../decoder/spec.js';
import { Batcher } from './batcher.js';
import { bind } from './binding.js';
import { DriveSession } from './drive.js';
import { FcReader } from './fc.js';
import { Diagnosis } from './diagnosis.js';
import { type Host, notice, nowUs } from './host.js';
import { type LiveSink, liveSink } from './live.js';
import type { PortIdentity, ToWorker } from './protocol.js';
import { TaskQueue } from './queue.js';
import { Recorder } from './recorder.js';
import { SourceRegistry } from './registry.js';
import { ReplaySession } from './replay/replay-session.js';
import { tooLargeToReadWhole } from './replay/capture-file.js';
import { READ_HERE, type SliceReaderMaker } from './replay/slice-reader.js';
import { type ReportMaker, WORKER_REPORT_MAKER, report } from './report.js';
import type { ReportRequest } from './report-worker.js';
import { setResolution, shareResolution, tellMismatch } from './resolution.js';
import { DemoSource } from './sources/demo.js';
import { SerialPorts } from './sources/serial-ports.js';

/** What the browser provides that tests replace. */
export interface DispatcherOptions {
  findPort?: (identity: PortIdentity) => Promise<SerialPort | undefined>;
  makeReport?: ReportMaker;
  /** How a replay's walk reads its file: on this thread unless told (worker.ts: a reader worker). */
  readSlices?: SliceReaderMaker;
}

export class Dispatcher {
  readonly queue: TaskQueue;
  readonly recorder: Recorder;
  readonly diagnosis: Diagnosis;
  readonly registry: SourceRegistry;
  readonly batcher: Batcher;
  readonly serial: SerialPorts;
  readonly sink: LiveSink;
  readonly drive: DriveSession;
  readonly fc: FcReader;
  readonly #makeReport: ReportMaker;
  readonly #readSlices: SliceReaderMaker;

  constructor(
    readonly host: Host,
    options: DispatcherOptions = {},
  ) {
    this.queue = new TaskQueue((error) => notice(host, 'error', 'Something went wrong in the worker', String(error)));
    this.recorder = new Recorder((recording) => host.post({ type: 'recording', recording }));
    this.diagnosis = new Diagnosis(
      (message) => host.post(message),
      () => this.registry.clockUs(),
      () =>
        this.registry
          .list()
          .filter((s) => s.kind === 'serial' && s.state === 'reading')
          .map((s) => s.id),
      host.clock,
    );
    this.registry = new SourceRegistry(host, this.diagnosis, {
      closing: () => this.recorder.stop(),
      empty: () => this.batcher.stop(),
    });
    this.batcher = new Batcher(host, this.registry, () => {
      for (const s of this.registry.list()) tellMismatch(s, this.registry.resolution, host);
      shareResolution(this.registry, host);
      this.registry.send();
      this.diagnosis.tick();
    });
    this.sink = liveSink(host, this.registry, this.recorder, this.batcher);
    this.serial = new SerialPorts({
      host,
      registry: this.registry,
      recorder: this.recorder,
      diagnosis: this.diagnosis,
      batcher: this.batcher,
      sink: this.sink,
      enqueue: (task) => this.queue.enqueue(task),
      findPort: options.findPort,
    });
    this.fc = new FcReader(host, (identity) => this.serial.find(identity));
    this.drive = new DriveSession(
      host,
      this.registry,
      this.serial,
      (sinceMs) => this.fc.readingsSince(sinceMs),
      () => this.fc.expectedOrder,
    );
    this.#makeReport = options.makeReport ?? WORKER_REPORT_MAKER;
    this.#readSlices = options.readSlices ?? READ_HERE;
  }

  /** A message from the page: queued behind those before it. */
  receive(message: ToWorker): void {
    // Stopping a drive and its sticks cannot wait for a command under way.
    if (message.type === 'drive-stop') this.drive.cancel();
    else if (message.type === 'drive-channel') this.drive.setChannel(message.id, message.percent);
    else if (message.type === 'drive-start') {
      const ticket = this.drive.request();
      this.queue.enqueue(() => this.drive.start(message, ticket));
    } else this.queue.enqueue(() => this.handle(message));
  }

  /** The replay being played, if the session is one. */
  get replay(): ReplaySession | undefined {
    const d = this.registry.driver;
    return d instanceof ReplaySession ? d : undefined;
  }

  async handle(message: ToWorker): Promise<void> {
    const { host, registry, recorder } = this;
    // A drive holds its port's writer: a command that closes the port stops the drive first.
    const closes =
      message.type === 'close-all' ||
      message.type === 'demo-stop' ||
      message.type === 'demo-start' ||
      message.type === 'replay-open' ||
      message.type === 'bind' ||
      (message.type === 'serial-close' && message.source === this.drive.source);
    if (closes && this.drive.source !== null) this.drive.stop('its port was closed');
    switch (message.type) {
      case 'serial-open':
        await this.serial.open(message.port);
        break;
      case 'serial-close':
        await registry.remove(message.source);
        break;
      case 'close-all':
      case 'demo-stop':
        await registry.closeAll();
        break;
      case 'demo-start':
        await this.#startDemo();
        break;
      case 'bind':
        await bind(message, host, registry, this.serial);
        break;
      case 'set-label':
        registry.setLabel(message.source, message.label);
        break;
      case 'record-start':
        await this.#startRecording();
        break;
      case 'record-stop':
        await recorder.stop();
        break;
      case 'export': {
        const result = await recorder.export(message.recording, message.what);
        if (typeof result === 'string') notice(host, 'warning', 'Nothing to export', result);
        else for (const { name, data } of result) host.post({ type: 'export-ready', name, mime: 'application/octet-stream', data }, [data]);
        break;
      }
      case 'inspect': {
        const entries = registry.get(message.source)?.engine.inspector.snapshot(message.limit) ?? [];
        // All entries of a snapshot share one buffer: transfer it once.
        const buffer = entries.find((e) => e.bytes !== null)?.bytes?.buffer;
        host.post({ type: 'inspection', source: message.source, entries }, buffer instanceof ArrayBuffer ? [buffer] : []);
        break;
      }
      case 'report': {
        const replay = this.replay;
        let of: ReportRequest['of'] | null = null;
        if (replay !== undefined) of = replay.of();
        else {
          const bytes = await recorder.current();
          if (bytes !== null) of = { bytes };
        }
        const name = replay !== undefined ? replay.name : 'live session';
        // Not awaited: the next commands (and the ports) go on while the helper works.
        report(host, this.#makeReport, of, name, message.format, registry.resolution).catch((error: unknown) =>
          notice(host, 'error', 'The report could not be made', String(error)),
        );
        break;
      }
      case 'export-frames':
        await this.#exportFrames(message);
        break;
      case 'diagnosis-confirm':
        await this.#confirm(message);
        break;
      case 'discard-recovered':
        await recorder.discardRecovered();
        break;
      case 'replay-open':
        await ReplaySession.open(message.name, message.file, {
          host,
          registry,
          diagnosis: this.diagnosis,
          batcher: this.batcher,
          readSlices: this.#readSlices,
        });
        break;
      case 'replay-play':
        await this.replay?.play();
        break;
      case 'replay-pause':
        this.replay?.pause();
        break;
      case 'replay-speed':
        this.replay?.setSpeed(message.speed);
        break;
      case 'replay-seek':
        await this.replay?.seek(message.timeUs);
        break;
      case 'drive-start':
        await this.drive.start(message);
        break;
      case 'drive-stop':
        this.drive.cancel();
        break;
      case 'drive-channel':
        this.drive.setChannel(message.id, message.percent);
        break;
      case 'fc-open':
        await this.fc.open(message.port);
        break;
      case 'fc-close':
        await this.fc.close();
        break;
      case 'set-resolution':
        setResolution(registry, message.resolution);
        this.batcher.schedule();
        break;
      default: {
        const never: never = message;
        throw new Error(`unknown message ${JSON.stringify(never)}`);
      }
    }
  }

  /**
   * A remote's decoded frames, from the capture replayed or the live session's recording, made
   * by the report helper (a long capture's take seconds; the ports are read meanwhile).
   */
  async #exportFrames(m: Extract<ToWorker, { type: 'export-frames' }>): Promise<void> {
    const replay = this.replay;
    let of: ReportRequest['of'] | null = null;
    let transfer: Transferable[] = [];
    if (replay !== undefined) of = replay.of();
    else {
      const bytes = await this.recorder.current();
      if (bytes !== null) {
        const copy = bytes.slice();
        of = { bytes: copy };
        transfer = [copy.buffer];
      }
    }
    if (of === null) {
      notice(this.host, 'warning', 'No frames to export', 'Record the live session (● Record) or open a capture first.');
      return;
    }
    const tooLarge = 'file' in of ? tooLargeToReadWhole(of.file.size, 'a capture whose frames are exported') : null;
    if (tooLarge !== null) {
      notice(this.host, 'error', 'The frames could not be exported', tooLarge);
      return;
    }
    const name = replay?.name ?? 'satscope-live';
    const frames = { port: m.source, format: m.format, fromUs: m.fromUs, toUs: m.toUs };
    const reply = await this.#makeReport({ of, name, format: 'json', resolution: this.registry.resolution, frames }, transfer);
    if (reply.error !== undefined) {
      notice(this.host, 'error', 'The frames could not be exported', reply.error);
      return;
    }
    if (reply.frames === 0) {
      notice(this.host, 'warning', 'No frames to export', 'No frame of this remote was decoded in that span.');
      return;
    }
    const label = this.registry.get(m.source)?.label ?? `port${m.source}`;
    const base = `${name.replace(/\.[^.]+$/, '') || 'satscope'}-${label}`.replace(/[^\w.-]+/g, '-');
    const mime = m.format === 'csv' ? 'text/csv' : 'application/x-ndjson';
    this.host.post({ type: 'export-ready', name: `${base}.frames.${m.format}`, mime, data: reply.data }, [reply.data]);
  }

  async #startDemo(): Promise<void> {
    const { registry } = this;
    await registry.closeAll();
    const demo = new DemoSource(this.host.clock, this.sink, (atUs) => {
      for (const s of registry.list()) if (s.kind === 'demo') s.engine.interrupt(atUs);
    });
    await registry.use(demo);
    for (let i = 0; i < demo.remotes; i++) {
      const s = registry.add('demo', i, i === 0 ? 'Demo remote (internal, DSMX 11 ms)' : 'Demo remote (external)', USB_CHUNK_JITTER_US);
      s.state = 'reading';
    }
    demo.start();
    this.batcher.startTicks();
    registry.send();
  }

  async #startRecording(): Promise<void> {
    const live = this.registry.list().filter((s) => s.kind === 'serial' || s.kind === 'demo');
    const first = live[0];
    if (first === undefined) {
      notice(this.host, 'warning', 'Nothing to record', 'Connect a receiver (or start the demo) first.');
      return;
    }
    // One entry per port number (= source id): the remote's label and its adapter.
    const ports = Array.from({ length: Math.max(...live.map((s) => s.id)) + 1 }, (_, id) => {
      const s = this.registry.get(id);
      return s === undefined
        ? {}
        : { name: s.label, baudRate: 115200, usbVendorId: s.identity?.usbVendorId, usbProductId: s.identity?.usbProductId };
    });
    await this.recorder.start(
      {
        baudRate: 115200,
        source: first.kind === 'demo' ? 'demo' : 'webserial',
        usbVendorId: first.identity?.usbVendorId,
        usbProductId: first.identity?.usbProductId,
        ports,
      },
      new Date(this.host.timeOriginMs + this.host.clock.now()).toISOString(),
    );
  }

  async #confirm(message: Extract<ToWorker, { type: 'diagnosis-confirm' }>): Promise<void> {
    const { host, registry, recorder } = this;
    const s = registry.get(message.source);
    if (s?.serial === undefined || s.state !== 'reading') {
      notice(host, 'warning', 'Cannot listen at another speed', 'Only a connected serial port can (not the demo or a replay).');
      return;
    }
    const problem = await this.diagnosis.confirm(s.id, s.serial, s.signals, message.probe, {
      nowUs: () => nowUs(host),
      event: (text, t) => recorder.event(text, t, s.id),
      data: (bytes, t) => recorder.data(bytes, t, s.id),
      state: (state, name) =>
        registry.setState(
          s,
          state,
          name === undefined ? s.name.replace(/ at .*$/, ' at 115200 baud') : s.name.replace(/ at .*$/, ` ${name}`),
        ),
    });
    if (problem !== null) notice(host, 'warning', `Remote ${s.label}: could not listen at ${message.probe.baudRate} baud`, problem);
  }
}
