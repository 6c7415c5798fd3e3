#!/usr/bin/env node
/**
 * The `satscope` command: decode and summarise captures from scripts. A thin shell over the
 * library: read the file, hand it to `readCapture`, `decodeCapture` and `summarizeCapture`,
 * print. Exit codes: 0 ok, 1 the file could not be decoded, 2 bad usage or unreadable file.
 */
import { readFileSync } from 'node:fs';
import { basename } from 'node:path';
import { CaptureFormatError, readCapture, type Capture } from '../decoder/capture/index.js';
import { decodeCapture, summarizeCapture, type DecodeCaptureOptions } from '../decoder/summary.js';
import type { DecodedFrame } from '../decoder/types.js';
import { formatJsonLine, formatCsvHeader, formatCsvLine, formatSummary } from './format.js';

const USAGE = `Usage:
  satscope decode FILE [--format jsonl|csv] [--resolution auto|1024|2048] [--port N]
  satscope info FILE [--resolution auto|1024|2048] [--port N] [--json]
  satscope --help | --version

FILE is a SatScope capture (.sscap), a raw byte dump (.bin) or a Saleae async-serial CSV export.
decode prints one line per frame; info prints a summary (system, remote, resolution and why,
frames, channels, fades, frame period, gaps, failsafe episodes).`;

class UsageError extends Error {}

interface Args {
  command: 'decode' | 'info';
  file: string;
  format: 'jsonl' | 'csv';
  resolution: 'auto' | 1024 | 2048;
  port: number;
  json: boolean;
}

function parseArgs(argv: string[]): Args | 'help' | 'version' {
  if (argv.includes('--help') || argv.includes('-h')) return 'help';
  if (argv.includes('--version')) return 'version';
  const [command, ...rest] = argv;
  if (command !== 'decode' && command !== 'info') throw new UsageError(command === undefined ? 'no command given' : `unknown command '${command}'`);
  const args: Args = { command, file: '', format: 'jsonl', resolution: 'auto', port: 0, json: false };
  for (let i = 0; i < rest.length; i++) {
    const arg = rest[i] as string;
    const value = (): string => {
      const v = rest[++i];
      if (v === undefined) throw new UsageError(`${arg} needs a value`);
      return v;
    };
    if (arg === '--format') {
      const v = value();
      if (v !== 'jsonl' && v !== 'csv') throw new UsageError(`--format must be jsonl or csv, not '${v}'`);
      args.format = v;
    } else if (arg === '--resolution') {
      const v = value();
      if (v === 'auto') args.resolution = 'auto';
      else if (v === '1024' || v === '2048') args.resolution = Number(v) as 1024 | 2048;
      else throw new UsageError(`--resolution must be auto, 1024 or 2048, not '${v}'`);
    } else if (arg === '--port') {
      const v = Number(value());
      if (!Number.isInteger(v) || v < 0 || v > 255) throw new UsageError('--port must be an integer 0–255');
      args.port = v;
    } else if (arg === '--json' && command === 'info') {
      args.json = true;
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

// A reader that stops early (`| head`) closes the pipe: that is not an error.
process.stdout.on('error', (error: NodeJS.ErrnoException) => {
  if (error.code === 'EPIPE') process.exit(0);
  throw error;
});
process.exitCode = main(process.argv.slice(2));
