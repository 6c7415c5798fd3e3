#!/usr/bin/env node
/**
 * The `satscope` command: decode, summarise and report on captures from scripts. A thin shell
 * over the library: read the file, hand it to `readCapture`, `decodeCapture`,
 * `summarizeCapture` or `healthReport`, print. Exit codes: 0 ok, 1 the file could not be decoded, 2 bad usage or unreadable file.
 */
import { readFileSync, writeFileSync } from 'node:fs';
import { basename } from 'node:path';
import { CaptureFormatError, readCapture, type Capture } from '../decoder/capture/index.js';
import { healthReport, reportHtml } from '../decoder/report.js';
import { decodeCapture, summarizeCapture, type DecodeCaptureOptions } from '../decoder/summary.js';
import type { DecodedFrame } from '../decoder/types.js';
import { formatJsonLine, formatCsvHeader, formatCsvLine, formatReportVerdict, formatSummary } from './format.js';

const USAGE = `Usage:
  satscope decode FILE [--format jsonl|csv] [--resolution auto|1024|2048] [--port N]
  satscope info FILE [--resolution auto|1024|2048] [--port N] [--json]
  satscope report FILE [--out REPORT.html] [--json] [--resolution auto|1024|2048]
  satscope doctor FILE [--json] [--resolution auto|1024|2048]   (satscope doctor --help)
  satscope --help | --version

FILE is a SatScope capture (.sscap), a raw byte dump (.bin) or a Saleae async-serial CSV export.
decode prints one line per frame; info prints a summary (system, remote, resolution and why,
frames, channels, fades, frame period, gaps, failsafe episodes). report makes a link-health
report of every port (fades per minute, lost frames, holds, failsafe episodes, frame-period
jitter, channels, glitches, with graphs) as one self-contained HTML page on stdout, or in the
file --out names (then the findings go to stdout); --json gives the same report as JSON.`;

class UsageError extends Error {}

type Command = 'decode' | 'info' | 'report';

interface Args {
  command: Command;
  file: string;
  format: 'jsonl' | 'csv';
  resolution: 'auto' | 1024 | 2048;
  port: number;
  json: boolean;
  /** report: the file to write instead of stdout. */
  out: string | null;
}

const COMMANDS: readonly string[] = ['decode', 'info', 'report'];
const isCommand = (c: string | undefined): c is Command => c !== undefined && COMMANDS.includes(c);

function parseArgs(argv: string[]): Args | 'help' | 'version' {
  if (argv.includes('--help') || argv.includes('-h')) return 'help';
  if (argv.includes('--version')) return 'version';
  const [command, ...rest] = argv;
  if (!isCommand(command)) throw new UsageError(command === undefined ? 'no command given' : `unknown command '${command}'`);
  const args: Args = { command, file: '', format: 'jsonl', resolution: 'auto', port: 0, json: false, out: null };
  for (let i = 0; i < rest.length; i++) {
    const arg = rest[i] as string;
    const value = (): string => {
      const v = rest[++i];
      if (v === undefined) throw new UsageError(`${arg} needs a value`);
      return v;
    };
    if (arg === '--format' && command !== 'report') {
      const v = value();
      if (v !== 'jsonl' && v !== 'csv') throw new UsageError(`--format must be jsonl or csv, not '${v}'`);
      args.format = v;
    } else if (arg === '--resolution') {
      const v = value();
      if (v === 'auto') args.resolution = 'auto';
      else if (v === '1024' || v === '2048') args.resolution = Number(v) as 1024 | 2048;
      else throw new UsageError(`--resolution must be auto, 1024 or 2048, not '${v}'`);
    } else if (arg === '--port' && command === 'report') {
      throw new UsageError('report covers every port of the capture; --port is for decode and info');
    } else if (arg === '--port') {
      const v = Number(value());
      if (!Number.isInteger(v) || v < 0 || v > 255) throw new UsageError('--port must be an integer 0–255');
      args.port = v;
    } else if (arg === '--json' && command !== 'decode') {
      args.json = true;
    } else if (arg === '--out' && command === 'report') {
      args.out = value();
      if (args.out === '') throw new UsageError('--out needs a file name');
    } else if (arg.startsWith('-')) {
      throw new UsageError(`unknown option '${arg}'`);
    } else if (args.file === '') {
      args.file = arg;
    } else {
      throw new UsageError(`unexpected argument '${arg}'`);
    }
  }
  if (args.file === '') throw new UsageError('no FILE given');
  return args;
}

/** Collects output and writes it in large blocks: one write per line would dominate the run time. */
class Output {
  #parts: string[] = [];
  #size = 0;
  line(text: string): void {
    this.#parts.push(text, '\n');
    this.#size += text.length + 1;
    if (this.#size > 1 << 16) this.flush();
  }
  flush(): void {
    if (this.#parts.length === 0) return;
    process.stdout.write(this.#parts.join(''));
    this.#parts = [];
    this.#size = 0;
  }
}

function load(file: string): Capture {
  let bytes: Uint8Array;
  try {
    bytes = readFileSync(file);
  } catch (error) {
    const code = (error as NodeJS.ErrnoException).code;
    const why = code === 'ENOENT' ? 'no such file' : code === 'EISDIR' ? 'it is a directory' : code === 'EACCES' ? 'permission denied' : String(error);
    throw new UsageError(`cannot read ${file}: ${why}`);
  }
  const capture = readCapture(new Uint8Array(bytes.buffer, bytes.byteOffset, bytes.byteLength), basename(file));
  for (const issue of capture.issues) process.stderr.write(`satscope: ${file}: ${issue.message}\n`);
  return capture;
}

function main(argv: string[]): number {
  let args: ReturnType<typeof parseArgs>;
  try {
    args = parseArgs(argv);
  } catch (error) {
    if (!(error instanceof UsageError)) throw error;
    process.stderr.write(`satscope: ${error.message}\n\n${USAGE}\n`);
    return 2;
  }
  if (args === 'help') {
    process.stdout.write(`${USAGE}\n`);
    return 0;
  }
  if (args === 'version') {
    const pkg = JSON.parse(readFileSync(new URL('../../package.json', import.meta.url), 'utf8')) as { version: string };
    process.stdout.write(`${pkg.version}\n`);
    return 0;
  }
  let capture: Capture;
  try {
    capture = load(args.file);
  } catch (error) {
    if (error instanceof UsageError) {
      process.stderr.write(`satscope: ${error.message}\n`);
      return 2;
    }
    if (error instanceof CaptureFormatError) {
      process.stderr.write(`satscope: ${args.file}: ${error.message}\n`);
      return 1;
    }
    throw error;
  }
  if (args.command === 'report') return report(capture, args);
  const options: DecodeCaptureOptions = { resolution: args.resolution, port: args.port };
  if (args.command === 'info') {
    const summary = summarizeCapture(capture, options);
    process.stdout.write(args.json ? `${JSON.stringify(summary, null, 2)}\n` : `${formatSummary(summary, basename(args.file))}\n`);
    return summary.decoder.frames > 0 ? 0 : 1;
  }
  const out = new Output();
  if (args.format === 'csv') out.line(formatCsvHeader());
  const write = args.format === 'csv' ? formatCsvLine : formatJsonLine;
  const { decoder } = decodeCapture(capture, options, (f: DecodedFrame) => out.line(write(f)));
  out.flush();
  const s = decoder.stats;
  if (s.frames === 0) {
    process.stderr.write(`satscope: ${args.file}: no Spektrum frames found in ${s.bytes} bytes (is this the satellite's DATA line at 115200 baud?)\n`);
    return 1;
  }
  if (s.discardedBytes > 0) {
    process.stderr.write(`satscope: ${args.file}: ${s.frames} frames; ${s.discardedBytes} bytes discarded (partial, truncated or corrupted frames), ${s.resyncs} resyncs\n`);
  }
  return 0;
}

/** `satscope report`: the health report of every port, as HTML or JSON, to stdout or --out. */
function report(capture: Capture, args: Args): number {
  const name = basename(args.file);
  const r = healthReport(capture, { resolution: args.resolution, name });
  const text = args.json ? `${JSON.stringify(r, null, 2)}\n` : reportHtml(r);
  if (args.out !== null) {
    try {
      writeFileSync(args.out, text);
    } catch (error) {
      const code = (error as NodeJS.ErrnoException).code;
      const why = code === 'ENOENT' ? 'no such directory' : code === 'EISDIR' ? 'it is a directory' : code === 'EACCES' ? 'permission denied' : String(error);
      process.stderr.write(`satscope: cannot write ${args.out}: ${why}\n`);
      return 2;
    }
    process.stdout.write(`${formatReportVerdict(r, args.out)}\n`);
  } else {
    process.stdout.write(text);
  }
  const frames = r.remotes.reduce((n, x) => n + x.frames, 0);
  if (frames === 0) {
    process.stderr.write(`satscope: ${args.file}: no Spektrum frames found in ${r.source.bytes} bytes (is this the satellite's DATA line at 115200 baud?)\n`);
    return 1;
  }
  return 0;
}

// A reader that stops early (`| head`) closes the pipe: that is not an error.
process.stdout.on('error', (error: NodeJS.ErrnoException) => {
  if (error.code === 'EPIPE') process.exit(0);
  throw error;
});
const argv = process.argv.slice(2);
// `doctor` has its own file (src/cli/doctor.ts), loaded only when it is asked for.
process.exitCode = argv[0] === 'doctor' ? (await import('./doctor.js')).doctorCommand(argv.slice(1)) : main(argv);
