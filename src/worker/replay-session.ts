/**
 * A capture opened for replay: read once, its overview made (overview.ts), then played through
 * the live path by a ReplaySource (sources/replay.ts) feeding one source per port, with play,
 * pause, speed and seek, and its status sent to the page a few times a second.
 */
import { CaptureFormatError, capturePorts, readCapture, type Capture } from '../capture/index.js';
import { timingJitterUs } from '../analysis/index.js';
import type { Batcher } from './batcher.js';
import type { Diagnosis } from './diagnosis.js';
import { type Host, notice } from './host.js';
import { overviewOf } from './overview.js';
import type { Driver, SourceRegistry } from './registry.js';
import { ReplaySource } from './sources/replay.js';

/** The position moves every tick; the page needs it a few times a second. */
const STATUS_MS = 200;

export interface ReplayParts {
  host: Host;
  registry: SourceRegistry;
  diagnosis: Diagnosis;
  batcher: Batcher;
}

export class ReplaySession implements Driver {
  readonly kind = 'replay';
  readonly source: ReplaySource;
  readonly #p: ReplayParts;
  #lastStatusMs = Number.NEGATIVE_INFINITY;

  /**
   * Reads `data` and starts playing it, every source before it closed; null (the user told why)
   * when it is not a capture.
   */
  static async open(name: string, data: ArrayBuffer, parts: ReplayParts): Promise<ReplaySession | null> {
    const { host, registry, diagnosis } = parts;
    let capture: Capture;
    try {
      // The file itself is not kept: the capture holds what replay and a report need.
      capture = readCapture(new Uint8Array(data), name);
    } catch (error) {
      const why = error instanceof CaptureFormatError ? error.message : String(error);
      notice(host, 'error', `Cannot open ${name}`, why);
      return null;
    }
    await registry.closeAll();
    if (capture.issues.length > 0) {
      notice(
        host,
        'warning',
        `${name}: ${capture.issues.length} damaged part(s) skipped`,
        `${capture.issues[0]?.message ?? ''} Every intact record is kept.`,
      );
    }
    const { overview, periodUs } = overviewOf(capture, capturePorts(capture), registry.resolution);
    const session = new ReplaySession(name, capture, periodUs, parts);
    const r = session.source;
    await registry.use(session);
    diagnosis.replay(capture, r.startUs);
    host.post({ type: 'overview', overview }, [overview.t.buffer, overview.fadeRate.buffer, overview.lost.buffer]);
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
  ) {
    this.#p = parts;
    const { host, registry } = parts;
    this.source = new ReplaySource(
      capture,
      (port, bytes, time) => registry.get(port)?.engine.push(bytes, time, host.timeOriginMs + host.clock.now()),
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
      { untimedPeriodUs: periodUs, clock: host.clock },
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

  async stop(): Promise<void> {
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

  /** Starts over at `timeUs`: fresh decodes, fed the history before it (ReplaySource.seek). */
  seek(timeUs: number): void {
    const state = this.source.playing ? 'playing' : 'paused';
    this.#resetSources();
    this.source.seek(timeUs);
    this.#p.registry.setAllStates(state);
    this.status();
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
      },
    });
  }
}
