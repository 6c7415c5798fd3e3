/**
 * The package as npm would publish it: what `npm pack` puts in, publint and
 * arethetypeswrong on the tarball, and the tarball installed into an empty folder and used by a
 * plain Node script and through its `satscope` command. Needs `npm run build:lib` first
 * (`npm test` does it).
 */
import { execFileSync } from 'node:child_process';
import { existsSync, mkdtempSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join, resolve } from 'node:path';
import { afterAll, beforeAll, describe, expect, it } from 'vitest';
import { publint } from 'publint';

const root = resolve(import.meta.dirname, '..');
const pkg = JSON.parse(readFileSync(join(root, 'package.json'), 'utf8')) as Record<string, unknown>;
let scratch = '';
let tarball = '';
let files: string[] = [];

function run(cmd: string, args: string[], cwd: string): string {
  return execFileSync(cmd, args, { cwd, encoding: 'utf8', stdio: ['ignore', 'pipe', 'pipe'] });
}

beforeAll(() => {
  // dist/ was built by npm test; --ignore-scripts keeps prepack from rebuilding it under the tests that read it.
  if (!existsSync(join(root, 'dist/decoder/index.js'))) throw new Error('dist/ is missing: run `npm run build:lib` first (npm test does)');
  scratch = mkdtempSync(join(tmpdir(), 'satscope-pack-'));
  const out = JSON.parse(run('npm', ['pack', '--json', '--ignore-scripts', '--pack-destination', scratch], root)) as {
    filename: string;
    files: { path: string }[];
  }[];
  tarball = join(scratch, out[0]!.filename);
  files = out[0]!.files.map((f) => f.path).sort();
});

afterAll(() => {
  if (scratch) rmSync(scratch, { recursive: true, force: true });
});

describe('the npm package', () => {
  it('declares an ESM package with types first in its exports, no side effects and no runtime dependencies', () => {
    expect(pkg.name).toBe('satscope');
    expect(pkg.type).toBe('module');
    expect(pkg.sideEffects).toBe(false);
    expect(pkg.dependencies ?? {}).toEqual({});
    const exports = pkg.exports as Record<string, Record<string, string> | string>;
    expect(Object.keys(exports)).toEqual(['.', './capture', './report', './simulator', './drive', './package.json']);
    for (const [name, entry] of Object.entries(exports))
      if (name !== './package.json') expect(Object.keys(entry)).toEqual(['types', 'default']);
    expect((exports['./report'] as Record<string, string>).default).toBe('./dist/report/index.js');
    expect(pkg.bin).toEqual({ satscope: './dist/cli/main.js' });
  });

  it('packs only the built library, capture files, simulator, doctor, drive, CLI, README, LICENSE and package.json', () => {
    expect(files).toContain('dist/decoder/index.js');
    expect(files).toContain('dist/capture/index.js');
    expect(files).toContain('dist/decoder/index.d.ts');
    expect(files).toContain('dist/simulator/index.js');
    expect(files).toContain('dist/report/index.js');
    expect(files).toContain('dist/drive/index.js');
    expect(files).toContain('dist/cli/main.js');
    expect(files).toContain('README.md');
    expect(files).toContain('LICENSE');
    const stray = files.filter(
      (f) => !/^(dist\/(decoder|capture|report|simulator|drive|cli)\/.+\.(js|d\.ts)|README\.md|LICENSE|package\.json)$/.test(f),
    );
    expect(stray).toEqual([]);
  });

  it('passes publint with no errors or warnings', async () => {
    const { messages } = await publint({ pkgDir: root, level: 'warning', strict: true });
    expect(messages.map((m) => `${m.type}: ${m.code} ${JSON.stringify(m.args)}`)).toEqual([]);
  });

  it('has types that resolve for ESM consumers (arethetypeswrong)', () => {
    let output = '';
    try {
      output = run(join(root, 'node_modules/.bin/attw'), [tarball, '--profile', 'esm-only', '--format', 'json', '--no-color'], root);
    } catch (error) {
      const e = error as { stdout?: string };
      throw new Error(`attw found problems:\n${e.stdout ?? String(error)}`);
    }
    // An ESM-only package: CommonJS and node10 resolution are out of scope (the esm-only profile).
    const report = JSON.parse(output) as { analysis: { problems: { resolutionKind?: string }[] } };
    const relevant = report.analysis.problems.filter(
      (p) => p.resolutionKind === undefined || p.resolutionKind === 'node16-esm' || p.resolutionKind === 'bundler',
    );
    expect(relevant).toEqual([]);
  });

  it('installs from the tarball into an empty project and decodes from a plain Node script', () => {
    const app = join(scratch, 'app');
    run('mkdir', ['-p', app], scratch);
    writeFileSync(join(app, 'package.json'), JSON.stringify({ name: 'consumer', private: true, type: 'module' }));
    run('npm', ['install', '--no-audit', '--no-fund', '--offline', tarball], app);
    writeFileSync(
      join(app, 'use.mjs'),
      `
      import { SpektrumDecoder, channelName } from 'satscope';
      import { encodeInternalFrame, encodeServo2048 } from 'satscope/simulator';
      const d = new SpektrumDecoder();
      for (let i = 0; i < 6; i++) d.push(encodeInternalFrame({ fades: 0, system: 0xb2 }, [encodeServo2048(0, 1024), encodeServo2048(1, 341)]));
      d.end();
      const f = d.next();
      console.log(JSON.stringify({ system: f.system, first: channelName(f.ids[0]), pos: f.positions[1] }));
    `,
    );
    expect(JSON.parse(run('node', ['use.mjs'], app))).toEqual({ system: 0xb2, first: 'Throttle', pos: 341 });
    expect(run(join(app, 'node_modules/.bin/satscope'), ['--help'], app)).toMatch(/satscope decode FILE/);
  });

  it('runs the README example as written against the installed package', () => {
    const readme = readFileSync(join(root, 'README.md'), 'utf8');
    const block = /<!-- README example[^>]*-->\s*```js\n([\s\S]*?)```/.exec(readme);
    expect(block, 'README example block').not.toBeNull();
    const app = join(scratch, 'app');
    writeFileSync(join(app, 'readme.mjs'), block![1]!);
    const lines = run('node', ['readme.mjs'], app).trim().split('\n');
    expect(lines[0]).toMatch(/^18\d frames, 2048 resolution, internal remote$/);
    expect(lines[1]).toBe('Throttle is channel 0; period 11000 µs; state failsafe');
  });

  it('runs the README drive example as written against the installed package', () => {
    const readme = readFileSync(join(root, 'README.md'), 'utf8');
    const block = /<!-- README drive example[^>]*-->\s*```js\n([\s\S]*?)```/.exec(readme);
    expect(block, 'README drive example block').not.toBeNull();
    const app = join(scratch, 'app');
    writeFileSync(join(app, 'drive.mjs'), block![1]!);
    const lines = run('node', ['drive.mjs'], app).trim().split('\n');
    expect(lines).toEqual(['1637 frames written, 0 skipped', 'channel-map pass, values pass, latency pass, failsafe unknown, steady pass']);
  });
});
