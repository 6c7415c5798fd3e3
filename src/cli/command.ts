/**
 * The `satscope` command: decode, summarise and report on captures from scripts. A thin shell
 * over the library: open the file a window at a time (`openStreamed`) or read it whole
 * (`loadCapture`), hand it to the decoder, `summarizeCapture` or `healthReport`, print. Output streams with backpressure (output.ts).
 * Exit codes: 0 ok (also when the reader stops early), 1 the file could not be decoded or the
 * output not written, 2 bad usage or unreadable file.
 */
import { closeSync, readFileSync, writeFileSync } from 'node:fs';
import { basename } from 'node:path';
import { captureChunks, type Capture } from '../capture/model.js';
import type { AnyCapture, StreamedCapture } from '../capture/capture-windows.js';
import { openStreamed } from './streamed-file.js';
import { capturePorts } from '../capture/facts.js';
import { SpektrumDecoder } from '../decoder/decoder.js';
import { captureSpan } from '../report/capture-span.js';
import { reportHtml } from '../report/report-html.js';
import { noFramesHint } from '../report/report-text.js';
import { summarizeCapture } from '../report/summary.js';
import { threadedReport } from './report-threads.js';
import { parseCommandLine, UsageError, type Args } from './args.js';
import { fileProblem } from './file-problem.js';
import { loadCapture } from './input.js';
import { formatJsonLine, formatCsvHeader, formatCsvLine, formatReportVerdict, formatSummary } from './format.js';
import { TextOutput } from './output.js';
import { openRawFile, type RawFile, rawPieces as rawFilePieces } from './raw-file.js';

const USAGE = `Usage:
  satscope decode FILE [--format jsonl|csv] [--resolution auto|1024|2048] [--port N]
  satscope info FILE [--resolution auto|1024|2048] [--port N] [--json]
  satscope report FILE [--out REPORT.html] [--json] [--resolution auto|1024|2048]
  satscope doctor FILE [--json] [--resolution auto|1024|2048]   (satscope doctor --help)
  satscope --help | --version

FILE is a SatScope capture (.sscap), a raw byte dump (.bin) or a Saleae async-serial CSV export
(after --, a FILE may start with -). decode prints one line per frame as it decodes; info prints
a summary (system, remote, resolution and why, frames, channels, fades, frame period, gaps,
failsafe episodes) of every port, or with --json the summary of one as JSON. --port picks the
serial port of a capture that holds several (default 0; info prints them all). report makes a link-health report of every port (fades
per minute, lost frames, holds, failsafe episodes, frame-period jitter, channels, glitches, with
graphs) as one self-contained HTML page on stdout, or in the file --out names (then the findings
go to stdout); --json gives the same report as JSON.
Exit codes: 0 done (also when the reader of the output stops early, as head does), 1 the file
holds no frames (on that port) or is not a capture, or the output could not be written (a full
disk), 2 bad usage or a file that cannot be read.`;

async function main(argv: string[]): Promise<number> {
  let args: ReturnType<typeof parseCommandLine>;
  try {
    args = parseCommandLine(argv);
  } catch (error) {
    if (!(error instanceof UsageError)) throw error;
    process.stderr.write(`satscope: ${error.message}\n\n${USAGE}\n`);
    return 2;
  }
  const out = new TextOutput(process.stdout);
  if (args === 'help') {
    out.text(`${USAGE}\n`);
    return finish(out, 0);
  }
  if (args === 'version') {
    const pkg = JSON.parse(readFileSync(new URL('../../package.json', import.meta.url), 'utf8')) as { version: string };
    out.text(`${pkg.version}\n`);
    return finish(out, 0);
  }
  // A raw dump is decoded as it is read; on any other port, loadCapture says it has no data.
  if (args.command === 'decode' && (args.port ?? 0) === 0) {
    const raw = openRawFile(args.file);
    if (raw !== null) {
      try {
        return await decode(rawPieces(raw), args, 0, out);
      } finally {
        closeSync(raw.fd);
      }
    }
  }
  // Any other file is read a window at a time when it streams (openStreamed), else whole.
  const streamed = openStreamed(args.file);
  if (streamed !== null) {
    try {
      return await (args.command === 'decode' ? decodeStreamed(streamed.capture, args, out) : summed(streamed.capture, args, out));
    } finally {
      streamed.close();
    }
  }
  // The report decodes ports on two threads, which read the columns where they are.
  const loaded = loadCapture(args.file, { shared: args.command === 'report' });
  if ('error' in loaded) {
    process.stderr.write(`satscope: ${loaded.error}\n`);
    return loaded.exitCode;
  }
  const { capture } = loaded;
  if (args.command !== 'decode') return summed(capture, args, out);
  for (const issue of capture.issues) process.stderr.write(`satscope: ${args.file}: ${issue.message}\n`);
  const port = args.port ?? 0;
  const noData = portProblem(capture, args.port);
  if (noData !== null) {
    process.stderr.write(`satscope: ${args.file}: ${noData}\n`);
    return 1;
  }
  return decode(capturePieces(capture, port), args, port, out);
}

/** `satscope decode` of a streamed capture: its issues, then the port's frames as its windows are read. */
function decodeStreamed(capture: StreamedCapture, args: Args, out: TextOutput): Promise<number> {
  for (const issue of capture.issues) process.stderr.write(`satscope: ${args.file}: ${issue.message}\n`);
  const port = args.port ?? 0;
  const noData = portProblem(capture, args.port);
  if (noData !== null) {
    process.stderr.write(`satscope: ${args.file}: ${noData}\n`);
    return Promise.resolve(1);
  }
  return decode(windowPieces(capture, port), args, port, out);
}

/** `satscope info` or `report` of a capture, held or streamed. */
async function summed(capture: AnyCapture, args: Args, out: TextOutput): Promise<number> {
  for (const issue of capture.issues) process.stderr.write(`satscope: ${args.file}: ${issue.message}\n`);
  if (args.command === 'report') return report(capture, args, out);
  if (args.command === 'info' && !args.json && args.port === null && capturePorts(capture).length > 1) return infoAll(capture, args, out);
  const port = args.port ?? 0;
  const noData = portProblem(capture, args.port);
  if (noData !== null) {
    process.stderr.write(`satscope: ${args.file}: ${noData}\n`);
    return 1;
  }
  if (args.command === 'info') {
    const summary = summarizeCapture(capture, { resolution: args.resolution, port });
    const text = () => formatSummary(summary, basename(args.file), capturePorts(capture), captureSpan(capture).startUs);
    out.text(args.json ? `${JSON.stringify(summary, null, 2)}\n` : `${text()}\n`);
    return finish(out, summary.decoder.frames > 0 ? 0 : 1);
  }
  return finish(out, 0);
}

/** `satscope info` of a capture with several ports and none chosen: each port's summary in turn. */
function infoAll(capture: AnyCapture, args: Args, out: TextOutput): Promise<number> {
  const ports = capturePorts(capture);
  const blocks = ports.map((port) => summarizeCapture(capture, { resolution: args.resolution, port }));
  const origin = captureSpan(capture).startUs;
  out.text(`${blocks.map((s) => formatSummary(s, basename(args.file), ports, origin)).join('\n\n')}\n`);
  return finish(out, blocks.some((s) => s.decoder.frames > 0) ? 0 : 1);
}

/** Why the port asked for (or port 0) cannot be decoded, naming the ports that have data; null when it can. */
function portProblem(capture: AnyCapture, asked: number | null): string | null {
  const ports = capturePorts(capture);
  const port = asked ?? 0;
  if (ports.includes(port)) return null;
  if (ports.length === 0) return 'the capture holds no data (no data records on any port)';
  const list = ports.length === 1 ? `port ${ports[0]}` : `ports ${ports.join(', ')}`;
  return `port ${port} has no data; this capture has data on ${list}${asked === null ? ` (choose one with --port ${ports[0]})` : ''}`;
}

/** Largest piece of a chunk pushed at once, so the decoder never holds a whole raw file. */
const PUSH_BYTES = 1 << 16;

/**
 * The pieces of a chunk to push. The decoder gives the same frames however bytes are split, so
 * a long chunk is cut into pieces, except one with a single chunk time: that time belongs to its
 * last byte, and splitting would stamp earlier bytes with it (the .sscap format bounds those
 * chunks to 16 MiB anyway).
 */
function* pieces(chunk: { bytes: Uint8Array; time: Time }): Generator<{ bytes: Uint8Array; time: Time }> {
  const { bytes, time } = chunk;
  if (typeof time === 'number' || bytes.length <= PUSH_BYTES) {
    yield { bytes, time };
    return;
  }
  for (let at = 0; at < bytes.length; at += PUSH_BYTES) {
    const end = Math.min(at + PUSH_BYTES, bytes.length);
    yield { bytes: bytes.subarray(at, end), time: time?.subarray(at, end) };
  }
}

/** A push's time argument. */
type Time = number | Float64Array | undefined;

/** The pieces of one port of a capture to push, in order. */
function* capturePieces(capture: Capture, port: number): Generator<{ bytes: Uint8Array; time: Time }> {
  for (const chunk of captureChunks(capture, port)) yield* pieces(chunk);
}

/**
 * The pieces of one port of a streamed capture to push, in order: those `capturePieces` gives of
 * the capture held (a chunk cut between windows is cut where `pieces` cuts it anyway).
 */
function* windowPieces(capture: StreamedCapture, port: number): Generator<{ bytes: Uint8Array; time: Time }> {
  for (const { bytes, chunkEnds, chunkTimesUs, chunkPorts, byteTimesUs } of capture.windows(port)) {
    let from = 0;
    for (let k = 0; k < chunkEnds.length; k++) {
      const to = chunkEnds[k] ?? from;
      if (chunkPorts[k] === port) {
        const t = chunkTimesUs[k] ?? NaN;
        const times = byteTimesUs?.subarray(from, to);
        yield* pieces({ bytes: bytes.subarray(from, to), time: times ?? (Number.isNaN(t) ? undefined : t) });
      }
      from = to;
    }
  }
}

/** The pieces of a raw dump read from its file, untimed. */
function* rawPieces(raw: RawFile): Generator<{ bytes: Uint8Array; time: Time }> {
  for (const bytes of rawFilePieces(raw)) yield* pieces({ bytes, time: undefined });
}

/**
 * `satscope decode`: one line per frame, written as it is decoded. Nothing grows with the
 * capture: the decoder gets the bytes a piece at a time, each frame is formatted and handed to
 * the output at once, and decoding waits whenever the reader of stdout is behind.
 */
async function decode(input: Iterable<{ bytes: Uint8Array; time: Time }>, args: Args, port: number, out: TextOutput): Promise<number> {
  const decoder = new SpektrumDecoder({ resolution: args.resolution });
  const format = args.format === 'csv' ? formatCsvLine : formatJsonLine;
  if (args.format === 'csv' && out.line(formatCsvHeader())) await out.ready();
  const drain = async (): Promise<void> => {
    for (let f = decoder.next(); f !== undefined; f = decoder.next()) {
      // The frame is borrowed: it is formatted before anything else touches the decoder.
      if (out.line(format(f))) await out.ready();
      if (out.stopped) return;
    }
  };
  for (const piece of input) {
    decoder.push(piece.bytes, piece.time);
    await drain();
    if (out.stopped) return finish(out, 0);
  }
  decoder.end();
  await drain();
  await out.end();
  if (out.stopped) return finish(out, 0);
  const s = decoder.stats;
  if (s.frames === 0) {
    process.stderr.write(
      `satscope: ${args.file}: no Spektrum frames found in ${s.bytes} bytes on port ${port} (${noFramesHint(decoder.format)})\n`,
    );
    return 1;
  }
  if (s.discardedBytes > 0) {
    process.stderr.write(
      `satscope: ${args.file}: ${s.frames} frames; ${s.discardedBytes} bytes discarded (partial, truncated or corrupted frames), ${s.resyncs} resyncs\n`,
    );
  }
  return 0;
}

/**
 * The exit code once the output is written: `code`, or 1 when writing failed. A reader that
 * stopped early (`| head`) is a normal end and keeps `code`.
 */
async function finish(out: TextOutput, code: number): Promise<number> {
  await out.end();
  if (out.error !== null) {
    process.stderr.write(`satscope: cannot write the output: ${out.error.code ?? out.error.message}\n`);
    return 1;
  }
  return code;
}

/** `satscope report`: the health report of every port with the doctor's findings, as HTML or JSON, to stdout or --out. */
async function report(capture: AnyCapture, args: Args, out: TextOutput): Promise<number> {
  const name = basename(args.file);
  // A streamed capture's second thread streams the file on its own.
  const r = threadedReport(capture, { resolution: args.resolution, name }, undefined, args.file).report;
  const text = args.json ? `${JSON.stringify(r, null, 2)}\n` : reportHtml(r);
  if (args.out !== null) {
    try {
      writeFileSync(args.out, text);
    } catch (error) {
      process.stderr.write(`satscope: cannot write ${args.out}: ${fileProblem(error, 'no such directory')}\n`);
      return Promise.resolve(2);
    }
    out.text(`${formatReportVerdict(r, args.out)}\n`);
  } else {
    out.text(text);
  }
  const frames = r.remotes.reduce((n, x) => n + x.frames, 0);
  if (frames === 0) {
    process.stderr.write(
      `satscope: ${args.file}: no Spektrum frames found in ${r.source.bytes} bytes (is this the satellite's DATA line at 115200 baud?)\n`,
    );
    return finish(out, 1);
  }
  return finish(out, 0);
}

/** Runs the command `argv` (the words after `satscope`); resolves to its exit code. */
export async function run(argv: string[]): Promise<number> {
  // `doctor` has its own file (src/cli/doctor.ts), loaded only when it is asked for.
  return argv[0] === 'doctor' ? (await import('./doctor.js')).doctorCommand(argv.slice(1)) : main(argv);
}
