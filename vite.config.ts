import { createHash } from 'node:crypto';
import { readFileSync } from 'node:fs';
import { resolve } from 'node:path';
import { defineConfig, type Plugin } from 'vite';

/**
 * The production page's Content-Security-Policy: nothing but this origin, no inline script,
 * no eval. Only in the build: the dev server injects inline scripts for hot reload.
 */
const CSP = [
  "default-src 'self'",
  "script-src 'self'",
  "worker-src 'self'",
  "style-src 'self'",
  "img-src 'self' data: blob:",
  "connect-src 'self'",
  "manifest-src 'self'",
  "object-src 'none'",
  "base-uri 'none'",
  "form-action 'none'",
].join('; ');

function contentSecurityPolicy(): Plugin {
  return {
    name: 'satscope-csp',
    apply: 'build',
    transformIndexHtml(html) {
      return html.replace(
        '<meta charset="utf-8" />',
        `<meta charset="utf-8" />\n    <meta http-equiv="Content-Security-Policy" content="${CSP}" />`,
      );
    },
  };
}

/**
 * The service worker that makes the page work offline (an installable PWA): at build time it
 * learns every file of the build, precaches them on install and answers from the cache first.
 */
function serviceWorker(): Plugin {
  return {
    name: 'satscope-sw',
    apply: 'build',
    generateBundle(_options, bundle) {
      const files = [
        './',
        ...Object.keys(bundle).map((f) => `./${f}`),
        './icon.svg',
        './icon-192.png',
        './icon-512.png',
        './manifest.webmanifest',
      ];
      const version = createHash('sha256')
        .update(files.join('\n'))
        .update(JSON.stringify(Object.values(bundle).map((b) => ('code' in b ? b.code.length : 0))))
        .digest('hex')
        .slice(0, 12);
      const source = readFileSync(resolve(import.meta.dirname, 'src/sw/sw.js'), 'utf8')
        .replace('__CACHE__', `satscope-${version}`)
        .replace('__FILES__', JSON.stringify(files));
      this.emitFile({ type: 'asset', fileName: 'sw.js', source });
    },
  };
}

export default defineConfig({
  base: './',
  plugins: [contentSecurityPolicy(), serviceWorker()],
  oxc: { jsx: { runtime: 'automatic', importSource: 'preact' } },
  worker: { format: 'es' },
  build: { outDir: 'dist-app', target: 'es2022', assetsInlineLimit: 0 },
  server: { port: 5173, strictPort: false },
});
