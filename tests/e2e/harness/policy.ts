// Chromium enterprise policy granting origins every serial port without a picker
// (SerialAllowAllPortsForUrls), so navigator.serial.getPorts() lists them in windows and
// dedicated workers. Chromium reads the managed policy directory at launch: install before
// launching, remove after. Several files setting the same list policy do not merge (one
// wins), so all live origins go into ONE file, rewritten under a lock from a registry of
// owners (pid + origin); owners whose process is gone are dropped on every rewrite.
import { existsSync, mkdirSync, readdirSync, readFileSync, rmSync, writeFileSync, renameSync } from 'node:fs';
import { join } from 'node:path';
import { acquireLock, alive, LOCK_DIR } from './lock.js';
import { ensureReaper } from './reaper.js';

export const POLICY_DIR = '/etc/chromium/policies/managed';
export const POLICY_FILE = join(POLICY_DIR, 'satscope-e2e-serial.json');
export const POLICY_REGISTRY = '/tmp/satscope-e2e-policy-owners';
const REGISTRY = POLICY_REGISTRY;

export interface SerialPolicy {
  origin: string;
  file: string;
  /** Idempotent. */
  remove(): Promise<void>;
}

/** Rewrite the policy file from the live owners; delete it when there are none. Sync, no lock. */
function rewrite(): string[] {
  mkdirSync(REGISTRY, { recursive: true });
  const origins = new Set<string>();
  for (const name of readdirSync(REGISTRY)) {
    const pid = Number(name.split('-')[0]);
    const path = join(REGISTRY, name);
    if (!alive(pid)) {
      rmSync(path, { force: true });
      continue;
    }
    try {
      origins.add(readFileSync(path, 'utf8').trim());
    } catch {
      // removed concurrently
    }
  }
  if (origins.size === 0) {
    rmSync(POLICY_FILE, { force: true });
  } else {
    mkdirSync(POLICY_DIR, { recursive: true });
    // Atomic replace, so a Chromium launching meanwhile never reads half a file.
    const tmp = join(POLICY_DIR, `.satscope-e2e-serial.${process.pid}.tmp`);
    writeFileSync(tmp, JSON.stringify({ SerialAllowAllPortsForUrls: [...origins].sort() }, null, 2));
    renameSync(tmp, POLICY_FILE);
  }
  return [...origins];
}

let counter = 0;

/** Grant `origin` (e.g. "http://127.0.0.1:41234") all serial ports in Chromiums launched from now on. */
export async function installSerialPolicy(origin: string): Promise<SerialPolicy> {
  const normalized = new URL(origin).origin;
  const owner = join(REGISTRY, `${process.pid}-${Date.now()}-${counter++}`);
  ensureReaper({ lockDir: LOCK_DIR, registry: REGISTRY, policyFile: POLICY_FILE, policyDir: POLICY_DIR });
  const lock = await acquireLock('chromium-policy');
  try {
    mkdirSync(REGISTRY, { recursive: true });
    writeFileSync(owner, normalized);
    rewrite();
  } finally {
    lock.release();
  }
  let removed = false;
  const removeSync = () => {
    if (removed) return;
    removed = true;
    process.off('exit', removeSync);
    rmSync(owner, { force: true });
    rewrite();
  };
  process.on('exit', removeSync);
  return {
    origin: normalized,
    file: POLICY_FILE,
    async remove() {
      if (removed) return;
      const l = await acquireLock('chromium-policy');
      try {
        removeSync();
      } finally {
        l.release();
      }
    },
  };
}

/** Drop owners whose process is gone; removes the policy file when nobody is left. Idempotent. */
export async function cleanupStaleSerialPolicy(): Promise<string[]> {
  const lock = await acquireLock('chromium-policy');
  try {
    if (existsSync(REGISTRY)) return rewrite();
    rmSync(POLICY_FILE, { force: true });
    return [];
  } finally {
    lock.release();
  }
}
