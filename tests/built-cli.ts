/**
 * The built command line (dist/cli/main.js: `npm run build:lib` first; `npm test` does it), run
 * as a user runs it, for the tests that run it.
 */
import { type SpawnSyncOptions, spawnSync } from 'node:child_process';
import { resolve } from 'node:path';

export const CLI = resolve(import.meta.dirname, '../dist/cli/main.js');

/**
 * How long a test lets one run of the CLI take before stopping it (spawnSync's `timeout`). A test
 * blocked in spawnSync cannot reach its own timeout: a CLI that hangs would hang the whole run.
 * Stopped, it exits with no status, and the test fails there instead.
 */
export const CLI_TIMEOUT_MS = 60_000;

/** `satscope ...args`, waited for: its exit code (null when stopped), stdout and stderr. */
export function satscope(...args: string[]): { code: number | null; out: string; err: string } {
  return satscopeWith({}, ...args);
}

/** As `satscope`, with spawnSync options of the caller's (a working folder, the output's file). */
export function satscopeWith(options: SpawnSyncOptions, ...args: string[]): { code: number | null; out: string; err: string } {
  const r = spawnSync(process.execPath, [CLI, ...args], { encoding: 'utf8', timeout: CLI_TIMEOUT_MS, ...options });
  return { code: r.status, out: String(r.stdout ?? ''), err: String(r.stderr ?? '') };
}
