/**
 * Drive: the worker writes a satellite's stream to a port's TX (the adapter wired to a flight
 * controller's satellite pad), on the worker's own timers, so a hidden tab does not slow it.
 * The port is opened as an ordinary source too, so that with its TX wired to its own RX (the
 * loopback self-test) the page decodes what it sends with SatScope's decoder.
 *
 * The frames come from the drive library (src/drive): the scenario's player and the write
 * schedule (a frame only after 8 ms of silence, the newest frame when late). Stopping (the
 * user, the scenario's end, a write that fails) stops the stream at once: the flight controller
 * sees the link lost, as it would in the air.
 */
import { builtinScenarios, type DriveReceiver, manualScenario } from '../drive/builtins.js';
import { type DriveCheck, gradeDrive } from '../drive/grade.js';
import { DrivePlayer, type DriveWrite } from '../drive/player.js';
import { type DriveScenario, parseDriveScenario } from '../drive/scenario.js';
import { type DriveTimingStats, WriteSchedule } from '../drive/schedule.js';
import { CHANNEL_COUNT, channelResolution, servoToMicros } from '../decoder/spec.js';
import type { FcTimedReading } from './fc.js';
import { type Host, notice } from './host.js';
import type { PortIdentity } from './protocol.js';
import type { SerialPorts } from './sources/serial-ports.js';
import type { SourceRegistry } from './registry.js';

/** How often the page is told where the drive is, ms. */
const STATUS_MS = 250;
/** A timer that wakes within this of a write's time (the ms clock's rounding) finds it due, µs. */
const WAKE_TOLERANCE_US = 1;
/**
 * What it wrote in the last this long a drive keeps, to grade the flight controller's reading
 * against: a whole built-in scenario, the last of a long one (the sticks alone run an hour), µs.
 */
const MAX_GRADED_US = 2 * 60e6;
/** Writes a drive lets be on their way to the port at once (see `#tick`). */
const MAX_WRITING = 2;

/** What the page asks the worker to drive. */
export interface DriveRequest {
  port: PortIdentity;
  receiver: DriveReceiver;
  /** A built-in scenario's name ('manual' for the page's sticks alone), or a scenario as JSON. */
  scenario: string;
  /** The most travel channel 0 (throttle) may reach, % (−100 … 100). */
  throttleCeilingPercent: number;
  /** Channels the page holds from the first frame on (slider values, % by channel id). */
  held?: Record<number, number>;
}

/** What the page is told of the drive. */
export interface DriveStatus {
  state: 'driving' | 'ended' | 'stopped' | 'failed';
  name: string;
  title: string;
  steps: { note: string; startUs: number; endUs: number }[];
  /** Where the scenario is, µs from its start, and its length. */
  positionUs: number;
  durationUs: number;
  step: number;
  /** The newest frame written: its header, and each channel's newest value written under it (µs by channel id, NaN: none). */
  sent: { system: number | null; remote: 'internal' | 'external'; resolution: 1024 | 2048; us: number[] } | null;
  timing: DriveTimingStats;
  /** Why it stopped, in words (null while driving). */
  reason: string | null;
  /** The source reading the same port (the loopback self-test), or null. */
  source: number | null;
  /** The receiver the drive was made for. */
  receiver: DriveReceiver;
  /** Once it stopped: the flight controller's reading graded (null: not graded, `gradeNote` says why). */
  checks: DriveCheck[] | null;
  gradeNote: string | null;
}

/** The scenario a request names: a built-in for its receiver, or the user's own JSON. @throws TypeError saying what is wrong */
export function requestedScenario(r: DriveRequest): DriveScenario {
  const text = r.scenario.trim();
  if (text.startsWith('{')) return parseDriveScenario(text);
  if (text === 'manual') return manualScenario(r.receiver);
  const found = builtinScenarios(r.receiver).find((s) => s.name === text);
  if (found === undefined) throw new TypeError(`no built-in scenario is called "${text}"`);
  return found;
}

/** One drive at a time: started, its writes timed, stopped. */
export class DriveSession {
  #player: DrivePlayer | null = null;
  #schedule: WriteSchedule | null = null;
  #writer: WritableStreamDefaultWriter<Uint8Array> | null = null;
  #startMs = 0;
  #timer: unknown;
  #statusTimer: unknown;
  #sent: DriveStatus['sent'] = null;
  #state: DriveStatus['state'] = 'stopped';
  #reason: string | null = null;
  #source: number | null = null;
  /** Writes on their way to the port, counted per drive (a stopped drive's writes settle later). */
  #writing = { count: 0 };
  /** Starts asked for (each gets the next number when it arrives), and the last a stop cancelled. */
  #requested = 0;
  #cancelled = 0;
  /** What was written, while the scenario is short enough to grade (null: not kept). */
  #written: DriveWrite[] = [];
  /** The first of `#written` still in the last `MAX_GRADED_US` (the rest is dropped now and then, not each write). */
  #writtenFrom = 0;
  #receiver: DriveReceiver | null = null;
  #checks: DriveCheck[] | null = null;
  #gradeNote: string | null = null;

  constructor(
    readonly host: Host,
    readonly registry: SourceRegistry,
    readonly serial: SerialPorts,
    /** The flight controller's readings since a time on the worker's clock (ms), if its port is read. */
    readonly fcReadings: (sinceMs: number) => FcTimedReading[] = () => [],
    /** The order its channels should follow the receiver's in, by the stack it speaks (undefined: Betaflight's). */
    readonly fcOrder: () => readonly number[] | undefined = () => undefined,
  ) {}

  /** The source whose port the drive writes (null: none). */
  get source(): number | null {
    return this.#player === null ? null : this.#source;
  }

  /** A start has arrived (before it waits its turn): its number, for `start`. */
  request(): number {
    return ++this.#requested;
  }

  /**
   * Opens the port (as a source, for the loopback) and starts writing the scenario: unless a
   * stop came after start number `ticket` arrived, even while it waited its turn or the port.
   */
  async start(r: DriveRequest, ticket = this.request()): Promise<void> {
    if (ticket <= this.#cancelled) return;
    this.stop('a new drive started');
    let scenario: DriveScenario;
    try {
      scenario = requestedScenario(r);
    } catch (error) {
      notice(this.host, 'error', 'The scenario cannot be driven', (error as Error).message);
      return;
    }
    if (!(await this.serial.open(r.port)) || ticket <= this.#cancelled) return;
    const port = await this.serial.find(r.port);
    if (ticket <= this.#cancelled) return;
    const source = this.registry.list().find((s) => port !== undefined && s.serial?.port === port);
    if (source === undefined || port === undefined || port.writable === null) {
      notice(this.host, 'error', 'The port cannot be written', 'The adapter was opened, but the browser gives no way to write to it.');
      return;
    }
    const writer = port.writable.getWriter();
    this.#writer = writer;
    this.#source = source.id;
    this.#player = new DrivePlayer(scenario, { throttleCeilingPercent: r.throttleCeilingPercent });
    for (const [id, percent] of Object.entries(r.held ?? {})) this.setChannel(Number(id), percent);
    this.#writing = { count: 0 };
    this.#schedule = new WriteSchedule(this.#player);
    this.#sent = null;
    this.#receiver = r.receiver;
    this.#written = [];
    this.#writtenFrom = 0;
    this.#checks = null;
    this.#gradeNote = null;
    this.#state = 'driving';
    this.#reason = null;
    this.#startMs = this.host.clock.now();
    this.#tick();
    this.#statusTimer = this.host.clock.every(STATUS_MS, () => this.#post());
    this.#post();
  }

  /** A channel held by the page (slider, key, gamepad) from the next frame on; null gives it back to the scenario. */
  setChannel(id: number, percent: number | null): void {
    if (!Number.isInteger(id) || id < 0 || id >= CHANNEL_COUNT) return;
    this.#player?.setChannel(id, percent === null ? null : Math.max(-150, Math.min(150, percent)));
  }

  /** The user's stop: writing stops now, and no start asked for before it begins. */
  cancel(): void {
    this.#cancelled = this.#requested;
    this.stop('stopped by the user');
  }

  /** Stops writing now (the flight controller sees the link lost). */
  stop(reason: string, state: 'stopped' | 'ended' | 'failed' = 'stopped'): void {
    if (this.#player === null) return;
    this.host.clock.cancel(this.#timer);
    this.host.clock.cancel(this.#statusTimer);
    this.#timer = undefined;
    this.#statusTimer = undefined;
    const writer = this.#writer;
    this.#writer = null;
    // Bytes already handed to the port go out; none after this.
    writer?.releaseLock();
    this.#state = state;
    this.#reason = reason;
    this.#grade();
    this.#post();
    this.#player = null;
    this.#schedule = null;
  }

  /** Keeps a write for grading; what fell out of the last `MAX_GRADED_US` goes once it is as many writes as those kept. */
  #keep(w: DriveWrite): void {
    const written = this.#written;
    written.push(w);
    while (this.#writtenFrom < written.length && (written[this.#writtenFrom] as DriveWrite).atUs < w.atUs - MAX_GRADED_US)
      this.#writtenFrom++;
    if (this.#writtenFrom > written.length / 2) {
      written.splice(0, this.#writtenFrom);
      this.#writtenFrom = 0;
    }
  }

  #nowUs(): number {
    return (this.host.clock.now() - this.#startMs) * 1000;
  }

  /**
   * Writes what is due, then sleeps until the next write is. At most `MAX_WRITING` writes are on
   * their way at a time (a browser takes some ms to say a write is done, and the schedule must
   * not wait for that): a port that stalls (unplugged, or a driver that holds writes) never has
   * a queue of frames to send back to back, which a flight controller reads as one broken frame.
   */
  #tick(): void {
    const schedule = this.#schedule;
    const writer = this.#writer;
    const writing = this.#writing;
    if (schedule === null || writer === null || writing.count >= MAX_WRITING) return;
    const now = this.#nowUs();
    const w = schedule.take(now + WAKE_TOLERANCE_US);
    if (w !== null) {
      writing.count++;
      this.#keep(w);
      writer.write(w.bytes).then(
        () => {
          // A tick that found the port's hands full left no timer: this write's end wakes it.
          if (writing.count-- === MAX_WRITING && this.#writer === writer) this.#tick();
        },
        (error: unknown) => {
          writing.count--;
          if (this.#writer === writer) this.stop(`the adapter could not be written (${String(error)}): unplugged?`, 'failed');
        },
      );
      const f = w.frame;
      if (f !== null) {
        // Each channel's newest value: frames in pairs carry half the channels each.
        const before = this.#sent;
        const same = before !== null && before.system === f.system && before.remote === f.remote && before.resolution === f.resolution;
        const us = same ? before.us : new Array<number>(CHANNEL_COUNT).fill(Number.NaN);
        for (const c of f.channels) if (c.id < CHANNEL_COUNT) us[c.id] = servoToMicros(c.pos, channelResolution(c.id, f.resolution));
        this.#sent = { system: f.system, remote: f.remote, resolution: f.resolution, us };
      }
    }
    const next = schedule.nextDueUs();
    if (Number.isNaN(next)) {
      this.stop('the scenario ended', 'ended');
      return;
    }
    this.host.clock.cancel(this.#timer);
    this.#timer = this.host.clock.after(Math.max(0, (next - now) / 1000), () => this.#tick());
  }

  /**
   * The flight controller's reading of what was written, graded (drive/grade.ts), once the drive
   * stopped. Its readings are put on the player's clock as they were answered: the latency found
   * includes the time an answer takes, half a reading interval at the most.
   */
  #grade(): void {
    const written = this.#written.slice(this.#writtenFrom);
    this.#written = [];
    this.#writtenFrom = 0;
    const fromUs = written[0]?.atUs ?? 0;
    const readings = this.fcReadings(this.#startMs)
      .map((r) => ({ atUs: (r.atMs - this.#startMs) * 1000, channels: r.channels, rxLoss: r.rxLoss }))
      .filter((r) => r.atUs >= fromUs);
    if (readings.length === 0) {
      this.#gradeNote = "Not graded: the flight controller's USB port was not read during the drive.";
      return;
    }
    this.#checks = gradeDrive(written, readings, this.fcOrder(), this.#player?.steps ?? []).checks;
    const last =
      fromUs > 0 ? `, over the drive's last ${Math.round(MAX_GRADED_US / 60e6)} minutes (from ${(fromUs / 1e6).toFixed(0)} s)` : '';
    this.#gradeNote = `Graded on ${readings.length} readings of the flight controller's channels${last}.`;
  }

  #post(): void {
    const player = this.#player;
    const schedule = this.#schedule;
    if (player === null || schedule === null) return;
    const position = Math.min(this.#nowUs(), player.durationUs);
    const status: DriveStatus = {
      state: this.#state,
      name: player.scenario.name,
      title: player.scenario.title,
      steps: player.steps.map((s) => ({ note: s.note, startUs: s.startUs, endUs: s.endUs })),
      positionUs: position,
      durationUs: player.durationUs,
      step: player.stepAt(position).index,
      sent: this.#sent,
      timing: schedule.stats,
      reason: this.#reason,
      source: this.#source,
      receiver: this.#receiver ?? { system: 0, remote: 'internal', channels: 0 },
      checks: this.#checks,
      gradeNote: this.#gradeNote,
    };
    this.host.post({ type: 'drive', drive: status });
  }
}
