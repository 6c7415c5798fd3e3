/**
 * The package's public surface: what its five entries export, read from their index files. It
 * stays small (what a user's workflow needs; the app's, worker's and CLI's plumbing imports
 * modules directly) and every name is documented where it is declared.
 */
import { readFileSync } from 'node:fs';
import { join } from 'node:path';
import { describe, expect, it } from 'vitest';

const ENTRIES = {
  satscope: 'decoder',
  'satscope/capture': 'capture',
  'satscope/report': 'report',
  'satscope/simulator': 'simulator',
  'satscope/drive': 'drive',
};
const SRC = join(import.meta.dirname, '../src');

/** Each exported name of an entry and the module (file name) that declares it. */
function exportsOf(folder: string): { name: string; module: string }[] {
  const text = readFileSync(join(SRC, folder, 'index.ts'), 'utf8')
    .replace(/\/\*[\s\S]*?\*\//g, '')
    .replace(/\/\/.*$/gm, '');
  const names: { name: string; module: string }[] = [];
  for (const m of text.matchAll(/export\s+(?:type\s+)?\{([^}]*)\}\s*from\s*'\.\/([^']+)\.js'/g)) {
    for (const part of (m[1] ?? '').split(',')) {
      const name = part.trim().replace(/^type\s+/, '');
      if (name !== '') names.push({ name, module: m[2] ?? '' });
    }
  }
  // Nothing is exported any other way (a declaration or `export *` would escape this count).
  expect(text.replace(/export\s+(?:type\s+)?\{[^}]*\}\s*from\s*'[^']+';/g, '')).not.toMatch(/\bexport\b/);
  return names;
}

/** Whether `name` is declared in `source` with a doc comment right before it. */
function documented(source: string, name: string): boolean {
  const decl = new RegExp(
    `\\*/\\s*\\n\\s*export\\s+(?:declare\\s+)?(?:abstract\\s+)?(?:const|function\\*?|class|interface|type|enum)\\s+${name}\\b`,
  );
  return decl.test(source);
}

describe('the public surface', () => {
  const all = Object.entries(ENTRIES).map(([entry, folder]) => ({ entry, folder, names: exportsOf(folder) }));

  it('is at most 120 names over the decoding entries and 32 for satscope/drive, each exported once', () => {
    const names = all.flatMap((e) => e.names.map((n) => n.name));
    const drive = all.find((e) => e.entry === 'satscope/drive')?.names ?? [];
    expect(names.length - drive.length).toBeLessThanOrEqual(120);
    expect(drive.length).toBeLessThanOrEqual(32);
    expect(new Set(names).size).toBe(names.length);
  });

  it('documents every name where it is declared', () => {
    const missing: string[] = [];
    for (const { entry, folder, names } of all) {
      for (const { name, module } of names) {
        const source = readFileSync(join(SRC, folder, `${module}.ts`), 'utf8');
        if (!documented(source, name)) missing.push(`${entry}: ${name} (src/${folder}/${module}.ts)`);
      }
    }
    expect(missing).toEqual([]);
  });
});
