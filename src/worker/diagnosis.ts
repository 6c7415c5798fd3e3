/**
 * The doctor in the worker (src/report): one `Doctor` per session, fed through the same path
 * as the decoders: each engine's bytes and frames (its `tap`), each port's opening, read errors
 * and loss. Its findings go to the page when they change, at most 4× a second.
 *
 * A replay gets a fresh doctor on the capture's clock (its timing, its first time as origin,
 * memory over the whole file, as `satscope doctor` reads it), with the capture's recorded
 * events fed in time order before the bytes they precede; a seek starts it over, as it does the
 * decoders. Live ports can be asked to listen briefly at another line setting to confirm a
 * finding (`confirm`), and return to 115200.
 */
import { Doctor } from '../report/doctor.js';
import { doctorEvent } from '../report/doctor-events.js';
import type { ConfirmProbe, DoctorFinding } from '../report/doctor-types.js';
import type { CaptureEvent, CaptureTiming } from '../capture/model.js';
import type { Engine } from './engine.js';
import { BROWSER_CLOCK, type Clock } from './host.js';
import type { DiagnosisStatus, FromWorker } from './protocol.js';
import { SerialSource } from './sources/serial.js';

/** The page hears from the doctor at most this often. */
const MIN_POST_MS = 250;
/** Line settings a probe may use: anything else from the page is refused. */
const PROBE_BAUDS = new Set([100_000, 420_000]);
const MAX_LISTEN_US = 2_000_000;

/** What the worker lends the probe. */
export interface ProbeHooks {
  nowUs(): number;
  /** Recorded like any port event, so `satscope doctor` on the recording sees the probe too. */
  event(text: string, timeUs: number): void;
  data(bytes: Uint8Array, timeUs: number): void;
  state(state: string, name?: string): void;
}

export class Diagnosis {
  #doctor = new Doctor();
  #mode: 'live' | 'replay' = 'live';
  #timing: CaptureTiming = 'per-chunk';
  /** A capture read whole: all its recorded events, in time order. */
  #captureEvents: CaptureEvent[] = [];
  /** The recorded events the doctor hears as the replay reaches them: the capture's, or those of the file's windows read since the last start. */
  #events: CaptureEvent[] = [];
  #nextEvent = 0;
  #labels = new Map<number, string>();
  #probing: DiagnosisStatus['probing'] = null;
  #lastKey = '';
  #lastPostMs = -Infinity;
  #timer: unknown;

  /**
   * @param post sends a message to the page
   * @param clockUs the session's clock (live: now; replay: the replay position)
   * @param probeable the live serial sources that could listen at another speed
   * @param clock wall time and timers (the throttle, the probe's listen)
   */
  constructor(
    readonly post: (message: FromWorker) => void,
    readonly clockUs: () => number,
    readonly probeable: () => number[],
    readonly clock: Clock = BROWSER_CLOCK,
  ) {}

  /** A new live session (every port closed): a fresh doctor, its sentences timed from now. */
  reset(): void {
    this.#mode = 'live';
    this.#captureEvents = [];
    this.#events = [];
    this.#labels.clear();
    this.#doctor = new Doctor({ originUs: this.clockUs() });
    this.#probing = null;
    this.tick(true);
  }

  /**
   * A capture opens for replay: with its timing and, read whole, its recorded events (a file
   * played a window at a time tells each window's, `replayEvents`).
   */
  replay(timing: CaptureTiming, events: readonly CaptureEvent[], startUs: number): void {
    this.#mode = 'replay';
    this.#timing = timing;
    this.#captureEvents = [...events].sort((a, b) => a.timeUs - b.timeUs);
    this.#labels.clear();
    this.#restartReplay(startUs);
  }

  /** A window of the file's records starts to play: its recorded events, heard as the replay reaches them. */
  replayEvents(events: readonly CaptureEvent[]): void {
    if (this.#mode !== 'replay' || events.length === 0) return;
    const waiting = [...this.#events.slice(this.#nextEvent), ...events].sort((a, b) => a.timeUs - b.timeUs);
    this.#events = waiting;
    this.#nextEvent = 0;
  }

  /** The replay starts over (a seek): the decoders are new, and so is the doctor. */
  replayReset(startUs: number): void {
    if (this.#mode === 'replay') this.#restartReplay(startUs);
  }

  #restartReplay(startUs: number): void {
    this.#doctor = new Doctor({ timing: this.#timing, memoryUs: Infinity, originUs: Number.isFinite(startUs) ? startUs : 0 });
    this.#events = this.#captureEvents;
    this.#nextEvent = 0;
  }

  /** Recorded events up to `timeUs`, in order. */
  #eventsUntil(timeUs: number): void {
    for (let e = this.#events[this.#nextEvent]; e !== undefined && !(e.timeUs > timeUs); e = this.#events[++this.#nextEvent])
      doctorEvent(this.#doctor, e.port, e.text, e.timeUs);
  }

  /** A source's engine: its bytes and frames reach the doctor from now on. */
  attach(id: number, engine: Engine, label: string): void {
    if (this.#labels.has(id) && this.#mode === 'live') this.#doctor.detach(id);
    this.#labels.set(id, label);
    const doctor = (): Doctor => this.#doctor;
    doctor().attach(id, { decoder: engine.decoder, link: engine.link, label });
    engine.tap = {
      bytes: (bytes, time) => {
        if (this.#mode === 'replay') {
          const t = time instanceof Float64Array ? time[0] : time;
          if (t !== undefined) this.#eventsUntil(t);
        }
        // A replay without recorded timing feeds its bytes untimed: the doctor's line windows
        // run on the replay's pace instead (its 'none' timing states no time from it).
        doctor().bytes(id, bytes, time ?? (this.#mode === 'replay' ? this.clockUs() : undefined));
      },
      frame: (f) => doctor().frame(id, f),
    };
  }

  /**
   * The replay reached the end of its capture: every port is judged on all it held, however
   * short (bytes without a frame: no satellite), as `satscope doctor` judges the file.
   */
  ended(): void {
    for (const id of this.#labels.keys()) this.#doctor.ended(id);
    this.tick(true);
  }

  /** A source's decoder and link monitor were restored from a checkpoint: the doctor counts from there. */
  restored(id: number): void {
    this.#doctor.restored(id);
  }

  /** A source's label changed: the findings name it. */
  relabel(id: number, engine: Engine, label: string): void {
    this.#labels.set(id, label);
    this.#doctor.attach(id, { decoder: engine.decoder, link: engine.link, label });
  }

  open(id: number, timeUs: number): void {
    this.#doctor.open(id, timeUs);
  }

  lineError(id: number, name: string, timeUs: number): void {
    this.#doctor.lineError(id, name, timeUs);
  }

  /** A source's port was lost at `timeUs` (its adapter went away). */
  close(id: number, timeUs: number): void {
    this.#doctor.close(id, timeUs);
  }

  /** A source was removed: its port number may be given to another remote. */
  remove(id: number): void {
    this.#doctor.detach(id);
    this.#labels.delete(id);
  }

  /**
   * Sends the findings when they changed, at most every MIN_POST_MS (a change inside that
   * time goes out when it is over). `force`: now, whatever changed.
   */
  tick(force = false): void {
    const nowMs = this.clock.now();
    const wait = this.#lastPostMs + MIN_POST_MS - nowMs;
    if (!force && wait > 0) {
      if (this.#timer === undefined)
        this.#timer = this.clock.after(wait, () => {
          this.#timer = undefined;
          this.tick();
        });
      return;
    }
    const now = this.clockUs();
    if (this.#mode === 'replay') this.#eventsUntil(now);
    const findings: DoctorFinding[] = Number.isFinite(now) ? this.#doctor.findings(now) : [];
    const diagnosis: DiagnosisStatus = {
      mode: this.#mode,
      findings,
      probeable: this.#mode === 'live' ? this.probeable() : [],
      probing: this.#probing,
    };
    const key = JSON.stringify(diagnosis);
    this.#lastPostMs = nowMs;
    if (key === this.#lastKey && !force) return;
    this.#lastKey = key;
    this.post({ type: 'diagnosis', diagnosis });
  }

  /**
   * Listens at `probe`'s line setting for `probe.listenUs` to confirm a finding, then reopens
   * the port at 115200 and reading goes on. Meanwhile the doctor gets the bytes and read errors
   * (what it recognises there makes its finding certain); the decoder does not. Returns why it
   * could not, or null.
   */
  async confirm(
    id: number,
    serial: SerialSource,
    signals: SerialOutputSignals | undefined,
    probe: ConfirmProbe,
    hooks: ProbeHooks,
  ): Promise<string | null> {
    if (this.#mode !== 'live' || this.#probing !== null) return 'A listen is already under way.';
    if (!PROBE_BAUDS.has(probe.baudRate) || !(probe.listenUs > 0) || probe.listenUs > MAX_LISTEN_US)
      return 'Not a line setting the doctor asked for.';
    const port = serial.port;
    if (port === undefined) return 'The port is not open.';
    const name = `${probe.baudRate} ${probe.parity === 'none' ? 'N' : probe.parity === 'even' ? 'E' : 'O'}${probe.stopBits}`;
    this.#probing = { source: id, baudRate: probe.baudRate };
    this.tick(true);
    await serial.close();
    const listener = new SerialSource(hooks.nowUs, {
      data: (bytes, timeUs) => {
        this.#doctor.bytes(id, bytes, timeUs);
        hooks.data(bytes, timeUs);
      },
      lineError: (error) => {
        const t = hooks.nowUs();
        this.#doctor.lineError(id, error, t);
        hooks.event(`line error: ${error}`, t);
      },
      lost: () => undefined,
    });
    let problem: string | null = null;
    try {
      await listener.open(port, signals, probe);
      const t = hooks.nowUs();
      this.#doctor.open(id, t, { baudRate: probe.baudRate });
      hooks.event(`port opened at ${probe.baudRate} baud`, t);
      hooks.state('probing', `listening at ${name}`);
      await new Promise((resolve) => this.clock.after(probe.listenUs / 1000, () => resolve(undefined)));
    } catch (error) {
      problem = `The port could not be opened at ${name}: ${error instanceof Error ? error.message : String(error)}`;
    }
    await listener.close();
    try {
      await serial.open(port, signals);
      const t = hooks.nowUs();
      this.#doctor.open(id, t);
      hooks.event('port opened at 115200 baud', t);
      hooks.state('reading');
    } catch (error) {
      problem = `The port did not reopen at 115200: ${error instanceof Error ? error.message : String(error)}. Connect it again.`;
      hooks.state('lost');
    }
    this.#probing = null;
    this.tick(true);
    return problem;
  }
}
