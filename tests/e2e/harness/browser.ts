// Debian's Chromium through playwright-core (never a downloaded browser), and a tiny static
// file server on 127.0.0.1 for the pages under test.
import { existsSync, promises as fsp } from 'node:fs';
import { createServer, type OutgoingHttpHeaders } from 'node:http';
import type { AddressInfo } from 'node:net';
import { extname, join, resolve, sep } from 'node:path';
import { chromium, type Browser, type LaunchOptions } from 'playwright-core';

/** The real binary: /usr/bin/chromium is Debian's wrapper script. */
export const CHROMIUM_PATH = '/usr/lib/chromium/chromium';
export const CHROMIUM_ARGS = [
  '--no-sandbox', // we run as root
  '--disable-gpu',
  '--disable-background-networking',
  '--disable-component-update',
  '--no-first-run',
  '--disable-sync',
  '--disable-quic',
];

export function chromiumAvailable(): boolean {
  return existsSync(CHROMIUM_PATH);
}

export interface LaunchChromiumOptions {
  /** Extra command-line switches. */
  args?: string[];
  /** Extra environment variables for the browser (merged over process.env). */
  env?: Record<string, string>;
  /** Shared objects to LD_PRELOAD into the browser (e.g. the serial signal shim). */
  preload?: string[];
  /** Anything else for playwright's launch(). */
  launch?: LaunchOptions;
}

export async function launchChromium(options: LaunchChromiumOptions = {}): Promise<Browser> {
  const env: Record<string, string> = { ...(process.env as Record<string, string>), ...options.env };
  if (options.preload?.length) {
    env.LD_PRELOAD = [...options.preload, env.LD_PRELOAD].filter(Boolean).join(':');
  }
  return chromium.launch({
    executablePath: CHROMIUM_PATH,
    headless: true,
    args: [...CHROMIUM_ARGS, ...(options.args ?? [])],
    env,
    ...options.launch,
  });
}

export const MIME_TYPES: Record<string, string> = {
  '.html': 'text/html; charset=utf-8',
  '.js': 'text/javascript; charset=utf-8',
  '.mjs': 'text/javascript; charset=utf-8',
  '.css': 'text/css; charset=utf-8',
  '.svg': 'image/svg+xml',
  '.webmanifest': 'application/manifest+json',
  '.json': 'application/json',
  '.wasm': 'application/wasm',
  '.png': 'image/png',
  '.ico': 'image/x-icon',
  '.map': 'application/json',
  '.txt': 'text/plain; charset=utf-8',
  '.bin': 'application/octet-stream',
  '.sscap': 'application/octet-stream',
  '.csv': 'text/csv; charset=utf-8',
};

export interface StaticServerOptions {
  /** Headers for every response, or per request path (e.g. COOP/COEP for cross-origin isolation). */
  headers?: OutgoingHttpHeaders | ((path: string) => OutgoingHttpHeaders | undefined);
  /** Served for "/" and directories. Default index.html. */
  index?: string;
}

export interface StaticServer {
  /** e.g. "http://127.0.0.1:41234" (no trailing slash): the origin to grant serial access. */
  origin: string;
  port: number;
  /** origin + path */
  url(path?: string): string;
  close(): Promise<void>;
}

/** Serve `root` on 127.0.0.1 on a random port. Only GET/HEAD, no directory listings, no `..`. */
export async function startStaticServer(root: string, options: StaticServerOptions = {}): Promise<StaticServer> {
  const base = resolve(root);
  const index = options.index ?? 'index.html';
  const server = createServer(async (req, res) => {
    const pathname = decodeURIComponent(new URL(req.url ?? '/', 'http://x').pathname);
    const extra = typeof options.headers === 'function' ? options.headers(pathname) : options.headers;
    if (req.method !== 'GET' && req.method !== 'HEAD') {
      res.writeHead(405, { allow: 'GET, HEAD' }).end();
      return;
    }
    let file = resolve(join(base, pathname));
    if (file !== base && !file.startsWith(base + sep)) {
      res.writeHead(403).end();
      return;
    }
    try {
      let st = await fsp.stat(file);
      if (st.isDirectory()) {
        file = join(file, index);
        st = await fsp.stat(file);
      }
      const body = await fsp.readFile(file);
      res.writeHead(200, {
        'content-type': MIME_TYPES[extname(file).toLowerCase()] ?? 'application/octet-stream',
        'content-length': body.length,
        'cache-control': 'no-store',
        ...extra,
      });
      res.end(req.method === 'HEAD' ? undefined : body);
    } catch {
      res.writeHead(404, { 'content-type': 'text/plain' }).end('not found');
    }
  });
  server.keepAliveTimeout = 1000;
  await new Promise<void>((ok, fail) => {
    server.once('error', fail);
    server.listen(0, '127.0.0.1', () => ok());
  });
  const port = (server.address() as AddressInfo).port;
  const origin = `http://127.0.0.1:${port}`;
  return {
    origin,
    port,
    url: (path = '/') => origin + (path.startsWith('/') ? path : `/${path}`),
    close: () =>
      new Promise<void>((ok) => {
        server.closeAllConnections();
        server.close(() => ok());
      }),
  };
}
