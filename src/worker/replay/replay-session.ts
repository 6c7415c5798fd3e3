/**
 * A capture opened for replay: read once, played through the live path by a ReplaySource
 * (sources/replay.ts) feeding one source per port, with play, pause, speed and seek, and its
 * status sent to the page a few times a second. A capture with recorded chunk times is decoded
 * once more, a slice at a time while it plays (replay-pass.ts): its overview is sent as it
 * grows, and a seek starts from that decode's nearest checkpoint. Others get their overview at
 * once (overview.ts) and seek with fresh decodes.
 */
import { plural } from '../../report/report-text.js';
import { CaptureFormatError, type Capture } from '../../capture/model.js';
import { capturePorts } from '../../capture/facts.js';
import { readCapture } from '../../capture/sniff.js';
import { FRAME_PERIOD_11MS_US } from '../../decoder/spec.js';
import { captureSpan } from '../../report/capture-span.js';
import { timingJitterUs } from '../../report/capture-pass.js';
import type { Batcher } from '../batcher.js';
import type { Diagnosis } from '../diagnosis.js';
import { type Host, notice } from '../host.js';
import { overviewOf } from './overview.js';
import type { Overview, ReplayStatus } from '../protocol.js';
import type { Driver, SourceRegistry } from '../registry.js';
import { type Checkpoint, type OverviewPass, ReplayPass } from './replay-pass.js';
import { type PreviewSizes, previewOf, previewed } from './replay-preview.js';
import type { PassHelperMaker } from './replay-helper.js';
import { type SplitPass, keptCapture, readInPieces, startSplit } from './replay-split.js';
import { OverviewSender } from './overview-sender.js';
import { ReplaySource } from '../sources/replay.js';

/** The position moves every tick; the page needs it a few times a second. */
const STATUS_MS = 200;
/** A seek from a checkpoint feeds at least this much before the target: the graphs' history (their default window). */
const SEEK_HISTORY_US = 60e6;
/** The capture is decoded for this long at a time, then messages and playback go through. */
const PASS_SLICE_MS = 40;

export interface ReplayParts {
  host: Host;
  registry: SourceRegistry;
  diagnosis: Diagnosis;
  batcher: Batcher;
  /** How much of a long capture is read first (default: replay-preview.ts's). */
  previewSizes?: PreviewSizes | undefined;
  /** Starts the helper that decodes half the ports of a long capture (replay-split.ts); none: one worker decodes all. */
  passHelper?: PassHelperMaker | undefined;
}

export class ReplaySession implements Driver {
  readonly kind = 'replay';
  readonly source: ReplaySource;
  readonly #p: ReplayParts;
  #lastStatusMs = Number.NEGATIVE_INFINITY;
  /** The capture's decode for the overview and the checkpoints (null: the overview came at once, seeks decode afresh). */
  readonly #pass: OverviewPass | null;
  #passTimer: unknown;
  readonly #sender: OverviewSender;
  #stopped = false;

  /**
   * Reads `file` and starts playing it, every source before it closed; null (the user told why)
   * when it is not a capture. A long capture's start and end are read first: its span is shown
   * at once; with a helper, its ports are decoded in two halves as the file is read (the
   * overview first, replay-split.ts), else its first records are.
   */
  static async open(name: string, file: Blob, parts: ReplayParts): Promise<ReplaySession | null> {
    const { host, registry, diagnosis } = parts;
    // A long capture: its start decoded and shown on its whole span before all of it is read.
    if (previewed(file.size, parts.previewSizes)) parts.passHelper?.prepare?.();
    const preview = await previewOf(file, parts.previewSizes);
    const sender = new OverviewSender(host);
    let early: ReplayPass | null = null;
    let split: SplitPass | null = null;
    let capture: Capture | null = null;
    let session: ReplaySession | null = null;
    const cannotOpen = (why: string): null => {
      notice(host, 'error', `Cannot open ${name}`, why);
      split?.stop();
      if (preview !== null) host.post({ type: 'replay', replay: null });
      return null;
    };
    if (preview !== null) {
      await registry.closeAll();
      const { ports, startUs, endUs } = preview;
      host.post({ type: 'replay', replay: readingStatus(name, startUs, endUs) });
      const { resolution } = registry;
      const span = { originUs: startUs, endUs, resolution };
      const halves = startSplit(file, ports, span, preview.expected, parts.passHelper, host.clock, parts.previewSizes?.sliceBytes, () => {
        // Until the capture is read the overview is drawn from here, after from the replay's slices.
        // Complete once both halves are (every record checked): the parse is not waited for.
        if (session !== null) session.#readOn();
        else if (split !== null && (split.overviewComplete || sender.due())) sender.offer(split.overview());
      });
      split = halves?.pass ?? null;
      if (halves === null) {
        early = new ReplayPass(preview.head, ports, registry.resolution, startUs, endUs, true);
        early.step(PASS_SLICE_MS, () => host.clock.now());
        sender.offer(early.overview());
      } else {
        try {
          // Read once, piece by piece, each piece to both halves as it comes: the overview first.
          await readInPieces(file, halves.mine, halves.theirs, parts.previewSizes?.sliceBytes);
          await Promise.all([halves.mine.ended, halves.theirs.ended]);
        } catch (error) {
          return cannotOpen(`The file could not be read (${String(error)}).`);
        }
        // An intact file is the capture the helper's half kept as it walked; anything else is read again and parsed.
        capture = keptCapture(halves.mine, halves.theirs);
      }
    }
    if (capture === null) {
      let bytes: Uint8Array;
      try {
        bytes = new Uint8Array(await file.arrayBuffer());
      } catch (error) {
        return cannotOpen(`The file could not be read (${String(error)}).`);
      }
      try {
        // The file itself is not kept: the capture holds what replay and a report need.
        capture = readCapture(bytes, name);
      } catch (error) {
        return cannotOpen(error instanceof CaptureFormatError ? error.message : String(error));
      }
    }
    if (preview === null) await registry.closeAll();
    if (capture.issues.length > 0) {
      notice(
        host,
        'warning',
        `${name}: ${plural(capture.issues.length, 'damaged part')} skipped`,
        `${capture.issues[0]?.message ?? ''} Every intact record is kept.`,
      );
    }
    const ports = capturePorts(capture);
    let pass: OverviewPass | null = null;
    let overview: Overview | null = null;
    let periodUs = FRAME_PERIOD_11MS_US;
    const span = capture.timing === 'per-chunk' ? captureSpan(capture) : undefined;
    if (split !== null && span !== undefined) {
      // The halves count if the capture read whole agrees with them (replay-split.ts).
      split.adopt(capture, ports, span);
      pass = split;
    } else if (span !== undefined && Number.isFinite(span.startUs)) {
      split?.stop();
      // The preview's decode goes on where the whole capture starts as its first records did.
      pass =
        early?.continueWith(capture, ports, span.startUs, span.endUs) === true
          ? early
          : new ReplayPass(capture, ports, registry.resolution, span.startUs, span.endUs);
    } else {
      split?.stop();
      ({ overview, periodUs } = overviewOf(capture, ports, registry.resolution));
    }
    session = new ReplaySession(name, capture, periodUs, parts, pass, sender);
    const r = session.source;
    await registry.use(session);
    diagnosis.replay(capture, r.startUs);
    if (overview !== null) sender.offer(overview);
    else session.#readOn(true);
    if (!r.recordedTiming) {
      notice(
        host,
        'info',
        `${name}: no recorded timing`,
        `Replayed at the receiver's pace (a frame every ${periodUs / 1000} ms). Holds, failsafes, lost frames and the frame period cannot be measured without the recorded times.`,
      );
    }
    session.#resetSources();
    r.play();
    registry.setAllStates('playing');
    session.status();
    return session;
  }

  private constructor(
    readonly name: string,
    capture: Capture,
    periodUs: number,
    parts: ReplayParts,
    pass: OverviewPass | null,
    sender: OverviewSender,
  ) {
    this.#p = parts;
    this.#pass = pass;
    this.#sender = sender;
    const { host, registry } = parts;
    this.source = new ReplaySource(
      capture,
      (port, bytes, time, _atUs, fedAtMs) => registry.get(port)?.engine.push(bytes, time, host.timeOriginMs + fedAtMs),
      () => {
        parts.batcher.flush();
        if (host.clock.now() - this.#lastStatusMs >= STATUS_MS) this.status();
      },
      () => {
        // The end: every link is judged at the capture's last recorded time, and stays so.
        const r = this.source;
        for (const s of registry.list()) {
          s.engine.end(r.recordedTiming ? r.endUs : Number.NaN);
          s.state = 'ended';
        }
        parts.batcher.flush();
        this.status();
      },
      {
        untimedPeriodUs: periodUs,
        clock: host.clock,
        onStop: (port, atUs) => registry.get(port)?.engine.interrupt(atUs),
      },
    );
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
   * Decodes the next slice of the capture for the overview and the checkpoints (the first one
   * now, the others after the messages and ticks waiting), and sends the overview as it grows.
   */
  #readOn(now = false): void {
    const pass = this.#pass;
    if (pass === null || this.#stopped || this.#passTimer !== undefined) return;
    const { host } = this.#p;
    const sender = this.#sender;
    const slice = (): void => {
      this.#passTimer = undefined;
      if (this.#stopped || sender.complete) return;
      const done = pass.step(PASS_SLICE_MS, () => host.clock.now());
      if (done || sender.due()) sender.offer(pass.overview());
      // Waiting for a half decoded elsewhere: its next report wakes this (replay-split.ts).
      if (!done && !pass.waiting) this.#passTimer = host.clock.after(0, slice);
    };
    if (now) slice();
    else this.#passTimer = host.clock.after(0, slice);
  }

  async stop(): Promise<void> {
    this.#stopped = true;
    this.#pass?.stop();
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
    const capture = r.capture;
    const ports = r.ports;
    registry.clear();
    diagnosis.replayReset(r.startUs);
    for (const port of ports) {
      const s = registry.add('replay', port, `${this.name}${ports.length > 1 ? ` port ${port}` : ''}`, timingJitterUs(capture.timing));
      // The label the remote had when it was recorded.
      const saved = capture.meta.ports?.[port]?.name;
      if (typeof saved === 'string' && saved !== '') s.label = saved;
      s.state = r.playing ? 'playing' : 'paused';
    }
  }

  play(): void {
    const r = this.source;
    // At the end, play starts over.
    if (r.ended) {
      this.#resetSources();
      r.seek(r.startUs);
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
   * without one (no such decode, or another resolution chosen since), fresh decodes fed the
   * history before it (ReplaySource.seek).
   */
  seek(timeUs: number): void {
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
    this.source.seek(timeUs, from === undefined ? undefined : (from?.chunk ?? 0));
    this.#p.registry.setAllStates(state);
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
    return pass.checkpointFor(target, SEEK_HISTORY_US) ?? null;
  }

  /** Tells the page where the replay is. */
  status(): void {
    const { host, registry } = this.#p;
    const r = this.source;
    const c = r.capture;
    this.#lastStatusMs = host.clock.now();
    let frames = 0;
    for (const s of registry.list()) frames += s.engine.decoder.stats.frames;
    host.post({
      type: 'replay',
      replay: {
        name: this.name,
        kind: c.kind,
        timing: c.timing,
        startUs: r.startUs,
        endUs: r.endUs,
        positionUs: r.positionUs,
        playing: r.playing,
        speed: r.speed,
        frames,
        issues: c.issues.map((i) => i.message),
        recordedTiming: r.recordedTiming,
        ended: r.ended,
        reading: false,
      },
    });
  }
}

/** The replay's status while a long capture's file is still being read: its span, nothing played. */
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
