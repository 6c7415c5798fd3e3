/**
 * Reading the capture a command names: the file's bytes through `readCapture`, or why not, in
 * the words and exit codes every command uses (2: the file cannot be read, 1: not a capture).
 */
import { readFileSync } from 'node:fs';
import { basename } from 'node:path';
import { CaptureFormatError, readCapture, type Capture, type ReadOptions } from '../capture/index.js';

export type LoadedCapture = { capture: Capture } | { error: string; exitCode: 1 | 2 };

/** `options.shared`: the columns in shared memory, for a command that hands them to worker threads (`ReadOptions`). */
export function loadCapture(file: string, options: ReadOptions = {}): LoadedCapture {
  let bytes: Uint8Array;
  try {
    bytes = readFileSync(file);
  } catch (error) {
    const code = (error as NodeJS.ErrnoException).code;
    const why =
      code === 'ENOENT'
        ? 'no such file'
        : code === 'EISDIR'
          ? 'it is a directory'
          : code === 'EACCES'
            ? 'permission denied'
            : String(error);
    return { error: `cannot read ${file}: ${why}`, exitCode: 2 };
  }
  try {
    return { capture: readCapture(new Uint8Array(bytes.buffer, bytes.byteOffset, bytes.byteLength), basename(file), options) };
  } catch (error) {
    if (error instanceof CaptureFormatError) return { error: `${file}: ${error.message}`, exitCode: 1 };
    throw error;
  }
}
