/**
 * `satscope doctor FILE`: what is wrong with the setup a capture was recorded from, and what to
 * change, in plain text (or `--json` for scripts). A thin shell over `doctorCapture`.
 *
 * Exit codes: 0 no problem found at the end of the capture, 1 a problem found (or the file is
 * not a capture), 2 bad usage or an unreadable file.
 */
import { basename } from 'node:path';
import { parseArgs } from 'node:util';
import { doctorCapture, type DoctorReport } from '../report/doctor-capture.js';
import { formatClock } from '../report/report-text.js';
import type { DoctorFinding } from '../report/doctor-types.js';
import { loadCapture } from './input.js';
import { openStreamed } from './streamed-file.js';
import type { AnyCapture } from '../capture/capture-windows.js';
import { TIMING_WORDS } from './format.js';
import { plural } from '../report/report-text.js';

export const DOCTOR_USAGE = `Usage:
  satscope doctor FILE [--json] [--resolution auto|1024|2048]

Diagnoses a capture (.sscap, raw .bin or Saleae CSV): nothing arriving, bytes that are not a
Spektrum satellite (an inverted line, SRXL, SRXL2, IBUS, SBUS, CRSF, noise), flight-controller
settings that will read the stream wrong (Betaflight/iNav serialrx_provider and
spektrum_sat_bind, ArduPilot and PX4 auto-detection), a weak link and a wrong setup. Prints each
finding with its evidence, how sure it is and what to do; --json prints the same as JSON.
Exit code 0: no problem found; 1: a problem found, or not a capture; 2: bad usage.`;

export interface DoctorIo {
  out(text: string): void;
  err(text: string): void;
}

const defaultIo: DoctorIo = {
  out: (t) => process.stdout.write(t),
  err: (t) => process.stderr.write(t),
};

/** Runs `satscope doctor` with the arguments after the command name; returns the exit code. */
export function doctorCommand(argv: string[], io: DoctorIo = defaultIo): number {
  let values: { json?: boolean; resolution?: string; help?: boolean };
  let positionals: string[];
  try {
    ({ values, positionals } = parseArgs({
      args: argv,
      options: { json: { type: 'boolean' }, resolution: { type: 'string' }, help: { type: 'boolean', short: 'h' } },
      allowPositionals: true,
      strict: true,
    }));
  } catch (error) {
    io.err(`satscope doctor: ${(error as Error).message}\n\n${DOCTOR_USAGE}\n`);
    return 2;
  }
  if (values.help === true) {
    io.out(`${DOCTOR_USAGE}\n`);
    return 0;
  }
  const usage = (message: string): number => {
    io.err(`satscope doctor: ${message}\n\n${DOCTOR_USAGE}\n`);
    return 2;
  };
  if (positionals.length === 0) return usage('no FILE given');
  if (positionals.length > 1) return usage(`unexpected argument '${positionals[1] as string}'`);
  const resolution = values.resolution ?? 'auto';
  if (resolution !== 'auto' && resolution !== '1024' && resolution !== '2048')
    return usage(`--resolution must be auto, 1024 or 2048, not '${resolution}'`);
  const file = positionals[0] as string;

  // Read a window at a time when the file streams (openStreamed), else whole.
  const streamed = openStreamed(file);
  try {
    let capture: AnyCapture;
    if (streamed !== null) capture = streamed.capture;
    else {
      const loaded = loadCapture(file);
      if ('error' in loaded) {
        io.err(`satscope doctor: ${loaded.error}\n`);
        return loaded.exitCode;
      }
      capture = loaded.capture;
    }
    return diagnose(capture, file, resolution, values.json === true, io);
  } finally {
    streamed?.close();
  }
}

/** The doctor's report of `capture`, printed; the exit code. */
function diagnose(capture: AnyCapture, file: string, resolution: string, json: boolean, io: DoctorIo): number {
  for (const issue of capture.issues) io.err(`satscope doctor: ${file}: ${issue.message}\n`);
  const report = doctorCapture(capture, { resolution: resolution === 'auto' ? 'auto' : (Number(resolution) as 1024 | 2048) });
  io.out(json ? `${JSON.stringify(report, null, 2)}\n` : formatDoctorReport(report, basename(file)));
  return report.findings.some((f) => f.severity === 'problem') ? 1 : 0;
}

const LABEL: Record<DoctorFinding['severity'], string> = { problem: 'PROBLEM', warning: 'WARNING', info: 'INFO' };

/** "0:02.1" from the capture's start. */
function clock(us: number | null, origin: number | null): string {
  return us === null || origin === null || !Number.isFinite(us) ? '' : formatClock(us - origin);
}

/** The report as text a person reads in a terminal. */
export function formatDoctorReport(r: DoctorReport, name: string): string {
  const lines: string[] = [];
  const origin = r.source.startUs;
  const span = r.source.startUs !== null && r.source.endUs !== null ? `, ${((r.source.endUs - r.source.startUs) / 1e6).toFixed(1)} s` : '';
  lines.push(
    `satscope doctor: ${name} (${r.source.kind}, ${TIMING_WORDS[r.source.timing]}, ${plural(r.source.ports.length, 'port')}, ${plural(r.source.bytes, 'byte')}${span})`,
  );
  lines.push('');
  if (r.findings.length === 0) lines.push('No findings: nothing wrong was seen at the end of the capture.');
  for (const f of r.findings) {
    const since = clock(f.sinceUs, origin);
    lines.push(`${LABEL[f.severity]}  ${f.title}  [${f.confidence}${since !== '' ? `, since ${since}` : ''}]`);
    for (const e of f.evidence) lines.push(`  - ${e.text}`);
    if (f.todo.length > 0) {
      lines.push('  What to do:');
      f.todo.forEach((t, i) => {
        lines.push(`    ${i + 1}. ${t}`);
      });
    }
    const withLines = f.settings.filter((s) => s.lines.length > 0 || s.note !== '');
    if (withLines.length > 0) {
      lines.push('  Settings:');
      for (const s of withLines) {
        lines.push(`    ${s.stack}: ${s.note}`);
        for (const l of s.lines) lines.push(`      ${l}`);
      }
    }
    if (f.confirm !== null)
      lines.push(
        `  To confirm: listen at ${f.confirm.baudRate} baud, ${f.confirm.parity} parity, ${f.confirm.stopBits} stop bit${f.confirm.stopBits === 1 ? '' : 's'}. ${f.confirm.note}`,
      );
    lines.push('');
  }
  const earlier = r.timeline.filter((e) => e.toUs !== null);
  if (earlier.length > 0) {
    lines.push('Seen earlier in the capture, cleared by its end:');
    for (const e of earlier)
      lines.push(`  ${LABEL[e.severity].toLowerCase()}: ${e.title} (${clock(e.fromUs, origin)}–${clock(e.toUs, origin)})`);
    lines.push('');
  }
  return `${lines.join('\n')}\n`;
}
