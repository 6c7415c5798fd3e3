/**
 * The one walk of a .sscap's records a replay from the File makes (replay-session.ts): every
 * record checked by its CRC and fed to the replay's decode (replay-pass.ts), its overview sent as
 * it grows, the playback and messages let through between slices; and what the walk finds that
 * decides whether the file's windows play it as recorded (`WalkCheck`).
 */
import { CaptureFormatError } from '../../capture/model.js';
import { recordTimeUs, type WalkedRecords, walkDataRecords } from '../../capture/record-walk.js';
import { TIME_BACK_TOLERANCE_US, timeInLine } from '../../capture/time-rule.js';
import { type CaptureSpan, SpanTally } from '../../report/capture-span.js';
import { stopsPort } from '../../report/doctor-events.js';
import type { Clock } from '../host.js';
import type { OverviewSender } from './overview-sender.js';
import { PASS_SLICE_MS, type ReplayPass } from './replay-pass.js';
import type { SliceReaderMaker } from './slice-reader.js';

/** A file is walked this much at a time, the next two read (slice-reader.ts) while one is decoded. */
const WALK_SLICE_BYTES = 4 << 20;
const WALK_READ_AHEAD = 2;

/**
 * What a walk of a file's records finds that decides whether its windows play it as recorded:
 * every time in line (time-rule.ts: a reader steps over none, so a window's times are the
 * whole file's), no damage, and its span (the rule every surface starts and ends a capture at).
 */
export class WalkCheck {
  inLine = true;
  damaged = false;
  readonly #span = new SpanTally();
  /** The last data record's time, and the latest event since it (an event must come no later than the data after it). */
  readonly #at = new Float64Array([Number.NaN, Number.NaN]);

  /**
   * A data record whose payload is `view`'s bytes [start, end) (a RecordSink's): its time read
   * here, not handed over (a double handed to a call not inlined is boxed, a record at a time).
   */
  data(view: DataView, start: number, end: number): void {
    const timeUs = recordTimeUs(view, start);
    const count = end - start;
    const at = this.#at;
    if (!timeInLine(at[0] ?? Number.NaN, timeUs) || (at[1] ?? Number.NaN) > timeUs + TIME_BACK_TOLERANCE_US) this.inLine = false;
    at[0] = timeUs;
    at[1] = Number.NaN;
    if (count > 0) this.#span.chunk(timeUs, count);
  }

  /** An event recorded at `timeUs` (NaN: unknown, as a reader keeps it). */
  event(timeUs: number): void {
    if (Number.isNaN(timeUs)) return;
    const at = this.#at;
    if (!timeInLine(at[0] ?? Number.NaN, timeUs)) this.inLine = false;
    if (!(timeUs <= (at[1] ?? Number.NaN))) at[1] = timeUs;
    this.#span.event(timeUs);
  }

  get span(): CaptureSpan {
    return this.#span.span;
  }
}

/**
 * Walks `file`'s records into `pass`, sending its overview through `sender` as it grows, until
 * the end or `stopped()`; `walked` null when it stopped or found damage (`check.damaged`). The
 * file is read through a reader `readSlices` makes, let go at the end.
 * @throws what reading the file throws, but a damaged record
 */
export async function walkFile(
  file: Blob,
  readSlices: SliceReaderMaker,
  pass: ReplayPass,
  sender: OverviewSender,
  clock: Pick<Clock, 'now' | 'after'>,
  stopped: () => boolean,
): Promise<{ walked: WalkedRecords | null; check: WalkCheck }> {
  const check = new WalkCheck();
  const utf8 = new TextDecoder();
  let yieldedMs = clock.now();
  let walked: WalkedRecords | null = null;
  const reader = readSlices(file);
  try {
    walked = await walkDataRecords(
      { size: file.size, slice: (start, end) => file.slice(start, end), view: (start, end) => reader.read(start, end) },
      (bytes, view, start, end, port, at) => {
        check.data(view, start, end);
        pass.feedRecord(bytes, view, start, end, port, at);
      },
      {
        checked: () => true,
        events: (bytes, view, start, end, port) => {
          const atUs = recordTimeUs(view, start);
          check.event(atUs);
          // A recorded stop ("device lost") is the adapter's absence, not the link's (LinkMonitor.stopped).
          if (stopsPort(utf8.decode(bytes.subarray(start, end)))) pass.stopped(port, atUs);
        },
        goOn: async () => {
          if (sender.due()) sender.offer(pass.overview());
          // Playback and messages go through every PASS_SLICE_MS.
          if (clock.now() - yieldedMs >= PASS_SLICE_MS) {
            await new Promise<void>((resolve) => clock.after(0, resolve));
            yieldedMs = clock.now();
          }
          return !stopped();
        },
        sliceBytes: WALK_SLICE_BYTES,
        readAhead: WALK_READ_AHEAD,
      },
    );
  } catch (error) {
    if (!(error instanceof CaptureFormatError)) throw error;
    check.damaged = true;
  } finally {
    reader.close();
  }
  return { walked, check };
}
