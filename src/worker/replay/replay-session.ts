/**
 * A capture opened for replay: played through the live path by a ReplaySource
 * (sources/replay.ts) feeding one source per port, with play, pause, speed and seek, and its
 * status sent to the page a few times a second.
 *
 * One pipeline. An intact .sscap with recorded times is never read whole: its start, end and
 * index are read (capture-file.ts), its records are walked once from the File, a slice at a
 * time, by the decode that draws the overview and keeps checkpoints (replay-pass.ts), and it
 * plays a window of records at a time; a seek reads the window at its checkpoint. Memory is the
 * overview, the checkpoints and a few windows, however long the capture. A file whose ports its
 * index does not give plays once the walk has found them (the overview grows meanwhile). Any
 * other file (raw bytes, a Saleae export, a .sscap that is damaged or whose times need stepping
 * over) is read whole and salvaged, and plays from memory; seeks start from the same decode's
 * checkpoints where it has recorded times.
 */
import { formatClock, plural } from '../../report/report-text.js';
import { CaptureFormatError, type Capture, type CaptureIssue, type CaptureMeta } from '../../capture/model.js';
import { capturePorts } from '../../capture/facts.js';
import { readCapture } from '../../capture/sniff.js';
import { truncatedRecord } from '../../capture/reader.js';
import { FRAME_PERIOD_11MS_US } from '../../decoder/spec.js';
import { captureSpan } from '../../report/capture-span.js';
import { timingJitterUs } from '../../report/capture-pass.js';
import type { Batcher } from '../batcher.js';
import type { Diagnosis } from '../diagnosis.js';
import { type Host, notice } from '../host.js';
import { overviewOf } from './overview.js';
import type { ReplayStatus } from '../protocol.js';
import type { Driver, SourceRegistry } from '../registry.js';
import { type Checkpoint, PASS_SLICE_MS, ReplayPass } from './replay-pass.js';
import { CaptureFile, tooLargeToReadWhole } from './capture-file.js';
import { walkFile } from './file-walk.js';
import type { SliceReaderMaker } from './slice-reader.js';
import { OverviewSender } from './overview-sender.js';
import { type ReplayData, type ReplayPosition, ReplaySource } from '../sources/replay.js';

/** The position moves every tick; the page needs it a few times a second. */
const STATUS_MS = 200;
/** A seek from a checkpoint feeds at least this much before the target: the graphs' history (their default window). */
const SEEK_HISTORY_US = 60e6;
/**
 * A seek further than this past the decode's latest checkpoint starts fresh decodes a little
 * before the target instead (the link figures then count from there until the decode gets there).
 */
const FRESH_SEEK_US = 15 * 60e6;

export interface ReplayParts {
  host: Host;
  registry: SourceRegistry;
  diagnosis: Diagnosis;
  batcher: Batcher;
  /** How the walk reads the file (slice-reader.ts). */
  readSlices: SliceReaderMaker;
}

export class ReplaySession implements Driver {
  readonly kind = 'replay';
  readonly source: ReplaySource;
  readonly #p: ReplayParts;
  readonly #blob: Blob;
  /** What was opened: the capture read whole, or the file itself. */
  readonly #opened: ReplayData;
  #lastStatusMs = Number.NEGATIVE_INFINITY;
  /** The capture's decode for the overview and the checkpoints (null: the overview came at once, seeks decode afresh). */
  #pass: ReplayPass | null = null;
  #passTimer: unknown;
  readonly #sender: OverviewSender;
  #stopped = false;
  /** What was skipped reading the file (a recording cut off inside its last record). */
  #issues: readonly CaptureIssue[];

  /**
   * Opens `file` and starts playing it, every source before it closed; null (the user told why)
   * when it is not a capture. `whole`: read it whole (a file found damaged as it was walked).
   */
  static async open(name: string, file: Blob, parts: ReplayParts, whole = false): Promise<ReplaySession | null> {
    const { host } = parts;
    const cannotOpen = (why: string): null => {
      notice(host, 'error', `Cannot open ${name}`, why);
      return null;
    };
    let opened: CaptureFile | null = null;
    try {
      if (!whole) opened = await CaptureFile.open(file);
    } catch (error) {
      return cannotOpen(`The file could not be read (${String(error)}).`);
    }
    if (opened !== null) return ReplaySession.#openFile(name, file, opened, parts);
    const tooLarge = tooLargeToReadWhole(
      file.size,
      whole ? 'a damaged capture' : 'a file that is not an intact .sscap with recorded times',
    );
    if (tooLarge !== null) return cannotOpen(tooLarge);
    let capture: Capture;
    try {
      capture = readCapture(new Uint8Array(await file.arrayBuffer()), name);
    } catch (error) {
      if (error instanceof CaptureFormatError) return cannotOpen(error.message);
      return cannotOpen(`The file could not be read (${String(error)}).`);
    }
    await parts.registry.closeAll();
    ReplaySession.#opens++;
    const ports = capturePorts(capture);
    const span = captureSpan(capture);
    const timed = capture.timing === 'per-chunk' && Number.isFinite(span.startUs);
    // Without chunk times the overview is made at once (it also finds the period to pace at).
    const once = timed ? null : overviewOf(capture, ports, parts.registry.resolution);
    const session = new ReplaySession(name, file, { capture }, parts, capture.issues, once?.periodUs ?? FRAME_PERIOD_11MS_US);
    if (timed) session.#pass = new ReplayPass(capture, ports, parts.registry.resolution, span.startUs, span.endUs);
    await session.#start();
    if (once !== null) session.#sender.offer(once.overview);
    else session.#stepPass(true);
    return session;
  }

  /**
   * An intact-looking .sscap: played from the File. Its records are walked once for the overview
   * and checkpoints; with its ports known from its index it plays at once, else once walked.
   */
  static async #openFile(name: string, blob: Blob, file: CaptureFile, parts: ReplayParts): Promise<ReplaySession | null> {
    const { host, registry } = parts;
    await registry.closeAll();
    const token = ++ReplaySession.#opens;
    const pass = new ReplayPass(null, file.ports, registry.resolution, file.startUs, file.endUs);
    let session: ReplaySession | null = null;
    if (file.ports === null) host.post({ type: 'replay', replay: readingStatus(name, file.startUs, file.endUs) });
    else {
      session = new ReplaySession(name, blob, { file, ports: file.ports }, parts, [], FRAME_PERIOD_11MS_US);
      session.#pass = pass;
      await session.#start();
    }
    // Not awaited: the walk goes on between the messages and the playback.
    ReplaySession.#walk(name, blob, file, pass, session, parts, token).catch((error: unknown) => {
      if (token === ReplaySession.#opens) notice(host, 'error', `${name} could not be read to its end`, String(error));
    });
    return session;
  }

  /** Counts opens: a walk whose replay was replaced by another source or file stops. */
  static #opens = 0;

  /**
   * Walks the file's records once into `pass` (checked, each CRC), sending the overview as it
   * grows; then plays the file if it was waiting for its ports. Anything the walk finds that the
   * windows cannot play as recorded (damage, times that need stepping over, a span other than its
   * first and last records showed) opens it again, read whole: the reader salvages it.
   */
  static async #walk(
    name: string,
    blob: Blob,
    file: CaptureFile,
    pass: ReplayPass,
    playing: ReplaySession | null,
    parts: ReplayParts,
    token: number,
  ): Promise<void> {
    const { host, registry } = parts;
    const sender = playing === null ? new OverviewSender(host) : playing.#sender;
    const replaced = (): boolean => token !== ReplaySession.#opens || (playing === null ? registry.driver !== undefined : playing.#stopped);
    const { walked, check } = await walkFile(blob, parts.readSlices, pass, sender, host.clock, replaced);
    if (replaced()) return;
    const span = check.span;
    if (walked === null || !check.inLine || span.startUs !== file.startUs || span.endUs !== file.endUs) {
      await ReplaySession.open(name, blob, parts, true);
      return;
    }
    pass.finish();
    sender.offer(pass.overview());
    const issues = walked.cutAt === undefined ? [] : [truncatedRecord(walked.cutAt, blob.size - walked.cutAt)];
    if (playing !== null) {
      playing.#issues = issues;
      playing.#tellIssues();
      playing.status();
      return;
    }
    const session = new ReplaySession(name, blob, { file, ports: pass.ports }, parts, issues, FRAME_PERIOD_11MS_US, sender);
    session.#pass = pass;
    await session.#start();
  }

  private constructor(
    readonly name: string,
    blob: Blob,
    opened: ReplayData,
    parts: ReplayParts,
    issues: readonly CaptureIssue[],
    /** Without recorded timing, the receiver's frame period its bytes are paced at. */
    readonly periodUs: number,
    sender = new OverviewSender(parts.host),
  ) {
    this.#p = parts;
    this.#blob = blob;
    this.#opened = opened;
    this.#issues = issues;
    this.#sender = sender;
    const { host, registry } = parts;
    this.source = new ReplaySource(
      opened,
      (port, bytes, time, _atUs, fedAtMs) => registry.get(port)?.engine.push(bytes, time, host.timeOriginMs + fedAtMs),
      () => {
        parts.batcher.flush();
        if (host.clock.now() - this.#lastStatusMs >= STATUS_MS) this.status();
      },
      () => {
        // The end: every link is judged at the capture's last recorded time (or the last read), and stays so.
        const r = this.source;
        for (const s of registry.list()) {
          s.engine.end(r.recordedTiming ? r.playsToUs : Number.NaN);
          s.state = 'ended';
        }
        parts.batcher.flush();
        this.status();
      },
      {
        untimedPeriodUs: this.periodUs,
        clock: host.clock,
        onStop: (port, atUs) => registry.get(port)?.engine.interrupt(atUs),
        onWindow: (w) => parts.diagnosis.replayEvents(w.capture.events),
        onReadFailed: () => {
          notice(
            host,
            'error',
            `${name}: the file could not be read on`,
            `${this.#readFailure() ?? ''} Nothing after it is shown or judged. A seek reads the file again.`,
          );
          this.status();
        },
      },
    );
  }

  /** The session takes over the registry and plays from the start. */
  async #start(): Promise<void> {
    const { registry, diagnosis, host } = this.#p;
    const r = this.source;
    await registry.use(this);
    diagnosis.replay(this.#timing, 'capture' in this.#opened ? this.#opened.capture.events : [], r.startUs);
    this.#tellIssues();
    if (!r.recordedTiming) {
      notice(
        host,
        'info',
        `${this.name}: no recorded timing`,
        `Replayed at the receiver's pace (a frame every ${this.periodUs / 1000} ms). Holds, failsafes, lost frames and the frame period cannot be measured without the recorded times.`,
      );
    }
    r.play();
    this.#resetSources();
    registry.setAllStates('playing');
    await r.seek(r.startUs, this.#first);
    this.status();
  }

  /** Where the capture's first chunk is. */
  get #first(): ReplayPosition {
    return { chunk: 0, offset: 'file' in this.#opened ? this.#opened.file.recordsFrom : 0 };
  }

  /** The file could not be read on while it played, in words (null: it reads). */
  #readFailure(): string | null {
    const r = this.source;
    const failed = r.readFailure;
    if (failed === null) return null;
    // The browser's own words for a file changed or moved since it was opened say little: its name for the error is enough.
    const why = failed.error instanceof Error ? failed.error.name : String(failed.error);
    return `The file could not be read past ${formatClock(failed.lastUs - r.startUs)}: it was changed, moved or removed since it was opened (${why}). The replay ends there.`;
  }

  /** What reading the file skipped, told once known. */
  #tellIssues(): void {
    const issues = this.#issues;
    if (issues.length === 0) return;
    notice(
      this.#p.host,
      'warning',
      `${this.name}: ${plural(issues.length, 'damaged part')} skipped`,
      `${issues[0]?.message ?? ''} Every intact record is kept.`,
    );
  }

  get #timing(): Capture['timing'] {
    return 'capture' in this.#opened ? this.#opened.capture.timing : 'per-chunk';
  }

  get #meta(): CaptureMeta {
    return 'capture' in this.#opened ? this.#opened.capture.meta : this.#opened.file.head.meta;
  }

  /** What a report or an export of this replay reads: the capture read whole, or the file again. */
  of(): { capture: Capture } | { file: Blob } {
    return 'capture' in this.#opened ? { capture: this.#opened.capture } : { file: this.#blob };
  }

  clockUs(): number {
    return this.source.positionUs;
  }

  clockRate(): number {
    return this.source.playing ? this.source.speed || 1 : 0;
  }

  linkNowUs(id: number): number {
    return this.source.linkNowUs(id);
  }

  /**
   * Decodes the next slice of a capture read whole for the overview and the checkpoints (the
   * first one now, the others after the messages and ticks waiting), and sends the overview as
   * it grows.
   */
  #stepPass(now = false): void {
    const pass = this.#pass;
    if (pass === null || this.#stopped || this.#passTimer !== undefined || !('capture' in this.#opened)) return;
    const { host } = this.#p;
    const sender = this.#sender;
    const slice = (): void => {
      this.#passTimer = undefined;
      if (this.#stopped || sender.complete) return;
      const done = pass.step(PASS_SLICE_MS, () => host.clock.now());
      if (done || sender.due()) sender.offer(pass.overview());
      if (!done) this.#passTimer = host.clock.after(0, slice);
    };
    if (now) slice();
    else this.#passTimer = host.clock.after(0, slice);
  }

  async stop(): Promise<void> {
    this.#stopped = true;
    this.#p.host.clock.cancel(this.#passTimer);
    this.#passTimer = undefined;
    this.source.stop();
    this.#p.host.post({ type: 'replay', replay: null });
  }

  /** A port's source closed: its bytes go nowhere from now on (the registry no longer has it). */
  async release(): Promise<void> {}

  /** Fresh decodes for every port (at the start, and a seek). */
  #resetSources(): void {
    const { registry, diagnosis } = this.#p;
    const r = this.source;
    const ports = r.ports;
    registry.clear();
    diagnosis.replayReset(r.startUs);
    for (const port of ports) {
      const s = registry.add('replay', port, `${this.name}${ports.length > 1 ? ` port ${port}` : ''}`, timingJitterUs(this.#timing));
      // The label the remote had when it was recorded.
      const saved = this.#meta.ports?.[port]?.name;
      if (typeof saved === 'string' && saved !== '') s.label = saved;
      s.state = r.playing ? 'playing' : 'paused';
    }
  }

  async play(): Promise<void> {
    const r = this.source;
    // At the end, play starts over.
    if (r.ended) {
      this.#resetSources();
      await r.seek(r.startUs, this.#first);
    }
    r.play();
    this.#p.registry.setAllStates('playing');
    this.status();
  }

  pause(): void {
    this.source.pause();
    this.#p.registry.setAllStates('paused');
    this.status();
  }

  setSpeed(speed: number): void {
    this.source.setSpeed(speed);
    this.#p.registry.send();
    this.status();
  }

  /**
   * Starts over at `timeUs`: from the capture's decode's nearest checkpoint at least a graph
   * history before it, with the whole capture's counters, episodes and link state up to there;
   * without one (no such decode, another resolution chosen since, or the decode not there yet),
   * fresh decodes fed the history before it (ReplaySource.seek).
   */
  async seek(timeUs: number): Promise<void> {
    const state = this.source.playing ? 'playing' : 'paused';
    this.#resetSources();
    const from = this.#checkpointFor(timeUs);
    if (from !== undefined && from !== null) {
      for (const [port, cp] of from.ports) {
        const engine = this.#p.registry.get(port)?.engine;
        if (engine === undefined) continue;
        engine.restore(cp.decoder, cp.link);
        this.#p.diagnosis.restored(port);
      }
    }
    const start: ReplayPosition | undefined =
      from === undefined ? undefined : { ...(from ?? this.#first), readTo: this.#pass?.checkpointAfter(timeUs)?.offset };
    this.#p.registry.setAllStates(state);
    await this.source.seek(timeUs, start);
    this.status();
  }

  /**
   * The checkpoint a seek to `timeUs` starts from; null to start from the capture's first chunk
   * (the target is that near the start); undefined when the decodes must start afresh.
   */
  #checkpointFor(timeUs: number): Checkpoint | null | undefined {
    const pass = this.#pass;
    if (pass === null || this.#p.registry.resolution !== pass.resolution) return undefined;
    const r = this.source;
    const target = Math.min(Math.max(timeUs, r.startUs), r.endUs);
    const cp = pass.checkpointFor(target, SEEK_HISTORY_US);
    const fromUs = cp?.fedUntilUs ?? r.startUs;
    if (!pass.done && target - fromUs > FRESH_SEEK_US) return undefined;
    return cp ?? null;
  }

  /** Tells the page where the replay is (nothing once another source or file has taken over). */
  status(): void {
    if (this.#stopped) return;
    const { host, registry } = this.#p;
    const r = this.source;
    this.#lastStatusMs = host.clock.now();
    let frames = 0;
    for (const s of registry.list()) frames += s.engine.decoder.stats.frames;
    host.post({
      type: 'replay',
      replay: {
        name: this.name,
        kind: 'capture' in this.#opened ? this.#opened.capture.kind : 'sscap',
        timing: this.#timing,
        startUs: r.startUs,
        endUs: r.endUs,
        positionUs: r.positionUs,
        playing: r.playing,
        speed: r.speed,
        frames,
        issues: [...this.#issues.map((i) => i.message), this.#readFailure()].filter((i) => i !== null),
        recordedTiming: r.recordedTiming,
        ended: r.ended,
        reading: false,
      },
    });
  }
}

/** The replay's status while a capture's records are walked before it can play: its span, nothing played. */
function readingStatus(name: string, startUs: number, endUs: number): ReplayStatus {
  return {
    name,
    kind: 'sscap',
    timing: 'per-chunk',
    startUs,
    endUs,
    positionUs: startUs,
    playing: false,
    speed: 1,
    frames: 0,
    issues: [],
    recordedTiming: true,
    ended: false,
    reading: true,
  };
}
