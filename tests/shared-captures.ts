/** The real captures beside the repository (../shared/captures), for the tests that read them all. */
import { readdirSync, statSync } from 'node:fs';
import { join, resolve } from 'node:path';

export const CAPTURE_DIR = resolve(import.meta.dirname, '../../shared/captures');

/** Every file under `dir`, recursively, relative to it ([] when `dir` is not there). */
export function filesUnder(dir: string): string[] {
  let entries: string[];
  try {
    entries = readdirSync(dir);
  } catch {
    return [];
  }
  return entries.flatMap((name) => {
    const path = join(dir, name);
    return statSync(path).isDirectory() ? filesUnder(path).map((f) => join(name, f)) : [name];
  });
}
