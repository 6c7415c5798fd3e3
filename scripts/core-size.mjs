#!/usr/bin/env node
/**
 * What `import { … } from 'satscope'` costs a web bundle: each package entry bundled alone,
 * minified, and gzipped (npm run size). The core must not pull in the capture importers or the
 * report's HTML; tests/package.test.ts holds it to that.
 */
import { mkdtempSync, readFileSync, readdirSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { gzipSync } from 'node:zlib';
import { build } from 'vite';

const ENTRIES = {
  satscope: 'src/decoder/index.ts',
  'satscope/capture': 'src/capture/index.ts',
  'satscope/report': 'src/report/index.ts',
  'satscope/drive': 'src/drive/index.ts',
};

export async function entrySizes() {
  const sizes = {};
  for (const [name, entry] of Object.entries(ENTRIES)) {
    const out = mkdtempSync(join(tmpdir(), 'satscope-size-'));
    try {
      await build({
        configFile: false,
        logLevel: 'silent',
        build: { outDir: out, minify: true, lib: { entry, formats: ['es'], fileName: 'entry' }, rollupOptions: { treeshake: true } },
      });
      const file = readdirSync(out).find((f) => f.endsWith('.js'));
      const code = readFileSync(join(out, file));
      sizes[name] = { min: code.length, gzip: gzipSync(code, { level: 9 }).length, text: code.toString('utf8') };
    } finally {
      rmSync(out, { recursive: true, force: true });
    }
  }
  return sizes;
}

if (import.meta.url === `file://${process.argv[1]}`) {
  for (const [name, s] of Object.entries(await entrySizes()))
    console.log(`${name.padEnd(17)} ${(s.min / 1024).toFixed(1)} kB minified, ${(s.gzip / 1024).toFixed(1)} kB gzipped`);
}
