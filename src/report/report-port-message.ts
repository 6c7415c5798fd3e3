/**
 * A port's report reading made on another thread: `readPortMessage` decodes one port of a
 * capture as the health report would (`decodePort`, with a doctor of its own listening) and
 * returns it as plain, structured-clonable data; `adoptPortMessage` turns that back into the
 * port's `PortData` on the report's thread, with a decoder, link monitor and series restored
 * from their checkpoints and the port's doctor state put into the report's doctor. The report is
 * then the one a single thread makes: the doctor keeps each port's state apart while it is fed
 * (only its findings read ports together), and the checkpoints are whole states.
 *
 * Which readings to make elsewhere is `likelyReadings`: a guess that costs nothing when wrong,
 * since the report decodes on its own thread whatever it asks for and nobody made.
 */
import type { AnyCapture } from '../capture/capture-windows.js';
import { SpektrumDecoder } from '../decoder/decoder.js';
import type { DecoderCheckpoint, LinkCheckpoint } from '../decoder/checkpoint.js';
import type { Resolution } from '../decoder/spec.js';
import { timingJitterUs } from './capture-pass.js';
import { Doctor } from './doctor.js';
import type { PortCheckpoint } from './doctor-state.js';
import type { DoctorOptions } from './doctor-types.js';
import { decodePort, type PortData } from './report-port.js';
import { REPORT_BIN_US } from './report-thresholds.js';
import { LinkSeries, monitorWithSeries, type LinkSeriesCheckpoint } from './series.js';

/** One port's reading to make: what `readPorts` passes to its decode, and the report's clock and doctor. */
export interface PortReadingJob {
  port: number;
  resolution: 'auto' | Resolution;
  from: 'user' | 'internal-remote';
  /** The report's time zero and end (`captureSpan`). */
  originUs: number;
  endUs: number;
  /** The report's doctor's options, or null when the report has no doctor (an untimed capture). */
  doctor: DoctorOptions | null;
}

/** A port's reading as data: `PortData` without its live objects, and their checkpoints. */
export interface PortReadingMessage {
  job: PortReadingJob;
  data: Omit<PortData, 'remote'>;
  decoder: DecoderCheckpoint;
  link: LinkCheckpoint;
  series: LinkSeriesCheckpoint;
  doctor: PortCheckpoint | null;
}

/** Whether a reading made for `job` is the one asked for. */
export function sameReading(job: PortReadingJob, port: number, resolution: 'auto' | Resolution, from: 'user' | 'internal-remote'): boolean {
  return job.port === port && job.resolution === resolution && job.from === from;
}

/** Makes `job`'s reading of `capture` (on any thread: pure, like the report). */
export function readPortMessage(capture: AnyCapture, job: PortReadingJob): PortReadingMessage {
  const doctor = job.doctor === null ? undefined : new Doctor(job.doctor);
  const { remote, ...data } = decodePort(capture, job.port, job.resolution, job.from, {
    originUs: job.originUs,
    endUs: job.endUs,
    doctor,
  });
  return {
    job,
    data,
    decoder: remote.decoder.checkpoint(),
    link: remote.link.checkpoint(),
    series: remote.series.checkpoint(),
    doctor: doctor?.portCheckpoint(job.port) ?? null,
  };
}

/**
 * The port's `PortData` from `message`, as `decodePort` would have returned it on this thread;
 * the port's doctor state goes into `doctor` (when the report has one), replacing what it held.
 */
export function adoptPortMessage(capture: AnyCapture, message: PortReadingMessage, doctor: Doctor | undefined): PortData {
  const { job } = message;
  const decoder = new SpektrumDecoder({ resolution: job.resolution, resolutionFrom: job.from });
  decoder.restore(message.decoder);
  const series = new LinkSeries(REPORT_BIN_US, job.originUs);
  series.restore(message.series);
  const link = monitorWithSeries({ jitterUs: timingJitterUs(capture.timing) }, series);
  link.restore(message.link);
  if (doctor !== undefined) {
    if (message.doctor === null) throw new TypeError(`port ${job.port}'s reading was made without a doctor`);
    doctor.restorePort(job.port, message.doctor, { decoder, link });
  }
  return { ...message.data, remote: { decoder, link, series } };
}
