/**
 * The command line, read with `node:util` `parseArgs` in strict mode: each command accepts only
 * its own options, and anything else is a `UsageError` that names the option and the command.
 */
import { parseArgs } from 'node:util';

/** Bad usage: the CLI prints the message and the usage text, and exits with 2. */
export class UsageError extends Error {
  override readonly name = 'UsageError';
}

export type Command = 'decode' | 'info' | 'report';

export interface Args {
  command: Command;
  file: string;
  format: 'jsonl' | 'csv';
  resolution: 'auto' | 1024 | 2048;
  /** The port asked for with --port; null when none was (then port 0 is decoded). */
  port: number | null;
  json: boolean;
  /** report: the file to write instead of stdout. */
  out: string | null;
}

/** Every option of every command, as `parseArgs` describes them. */
const OPTIONS = {
  format: { type: 'string' },
  resolution: { type: 'string' },
  port: { type: 'string' },
  json: { type: 'boolean' },
  out: { type: 'string' },
  help: { type: 'boolean', short: 'h' },
  version: { type: 'boolean' },
} as const;

type OptionName = keyof typeof OPTIONS;

/** The options each command takes (--help and --version are taken everywhere). */
const COMMAND_OPTIONS: Record<Command, readonly OptionName[]> = {
  decode: ['format', 'resolution', 'port'],
  info: ['resolution', 'port', 'json'],
  report: ['out', 'json', 'resolution'],
};

/** Why a command does not take an option, where a better hint than "it does not" exists. */
const HINTS: Partial<Record<`${Command} ${OptionName}`, string>> = {
  'report port': 'report covers every port of the capture; --port is for decode and info',
  'info format': 'info prints a summary; --format (jsonl or csv) is for decode, and info --json gives the summary as JSON',
  'report format': 'report writes HTML, or JSON with --json; --format is for decode',
  'decode json': 'decode prints JSON lines already; --json is for info and report',
};

const isCommand = (c: string | undefined): c is Command => c === 'decode' || c === 'info' || c === 'report';
const isOption = (name: string): name is OptionName => Object.hasOwn(OPTIONS, name);

/**
 * Reads `argv` (without the node and script paths).
 * @throws {UsageError} on anything it cannot take, with a message that says what and why.
 */
export function parseCommandLine(argv: readonly string[]): Args | 'help' | 'version' {
  // A lenient pass first, for messages that name the command and what it takes; the strict
  // pass after it is the authority on anything this one lets through.
  const { values, positionals, tokens } = parseArgs({
    args: [...argv],
    options: OPTIONS,
    strict: false,
    allowPositionals: true,
    tokens: true,
  });
  if (values.help === true) return 'help';
  if (values.version === true) return 'version';
  const [command, file, ...extra] = positionals;
  if (!isCommand(command)) {
    const unknown = tokens.find((t) => t.kind === 'option' && !isOption(t.name));
    if (unknown?.kind === 'option') throw new UsageError(`unknown option '${unknown.rawName}'`);
    throw new UsageError(command === undefined ? 'no command given' : `unknown command '${command}'`);
  }
  const allowed = COMMAND_OPTIONS[command];
  const seen = new Set<string>();
  for (const t of tokens) {
    if (t.kind !== 'option') continue;
    if (t.name === 'help' || t.name === 'version') continue;
    if (!isOption(t.name)) throw new UsageError(`unknown option '${t.rawName}'`);
    if (!allowed.includes(t.name)) {
      const takes = allowed.map((o) => `--${o}`).join(', ');
      const hint = HINTS[`${command} ${t.name}`];
      throw new UsageError(`unknown option '${t.rawName}' for ${command}${hint ? `: ${hint}` : ` (${command} takes ${takes})`}`);
    }
    if (seen.has(t.name)) throw new UsageError(`${t.rawName} is given more than once`);
    seen.add(t.name);
    if (OPTIONS[t.name].type === 'string') {
      if (t.value === undefined) throw new UsageError(`${t.rawName} needs a value`);
      if (!t.inlineValue && t.value.startsWith('-') && t.value !== '-') {
        throw new UsageError(
          `${t.rawName} needs a value, not the option '${t.value}' (for a value that starts with '-', write ${t.rawName}=${t.value})`,
        );
      }
    } else if (t.inlineValue) {
      throw new UsageError(`${t.rawName} takes no value`);
    }
  }
  try {
    parseArgs({ args: [...argv], options: OPTIONS, strict: true, allowPositionals: true });
  } catch (error) {
    throw new UsageError(error instanceof Error ? error.message : String(error));
  }
  if (file === undefined || file === '') throw new UsageError('no FILE given');
  if (extra.length > 0) throw new UsageError(`unexpected argument '${extra[0]}' (${command} takes one FILE)`);

  const str = (name: OptionName): string | undefined => {
    const v = values[name];
    return typeof v === 'string' ? v : undefined;
  };
  const args: Args = { command, file, format: 'jsonl', resolution: 'auto', port: null, json: values.json === true, out: null };
  const format = str('format');
  if (format !== undefined) {
    if (format !== 'jsonl' && format !== 'csv') throw new UsageError(`--format must be jsonl or csv, not '${format}'`);
    args.format = format;
  }
  const resolution = str('resolution');
  if (resolution !== undefined) {
    if (resolution === 'auto') args.resolution = 'auto';
    else if (resolution === '1024' || resolution === '2048') args.resolution = Number(resolution) as 1024 | 2048;
    else throw new UsageError(`--resolution must be auto, 1024 or 2048, not '${resolution}'`);
  }
  const port = str('port');
  if (port !== undefined) {
    if (!/^\d{1,3}$/.test(port) || Number(port) > 255) throw new UsageError(`--port must be an integer 0–255, not '${port}'`);
    args.port = Number(port);
  }
  const out = str('out');
  if (out !== undefined) {
    if (out === '') throw new UsageError('--out needs a file name');
    args.out = out;
  }
  return args;
}
