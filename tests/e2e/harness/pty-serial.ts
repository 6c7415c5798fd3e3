// A fake serial device for Chromium's real WebSerial stack: a pseudo-terminal put in place of
// /dev/ttyS0 (which Chromium lists from sysfs; the node itself becomes a symlink to the pty
// slave). The pty is owned by pty-pump.py, a python3 helper spoken to over stdio; it restores
// /dev/ttyS0 when told, when our stdin closes (this process died) and on signals.
import { spawn, spawnSync, type ChildProcess } from 'node:child_process';
import { createHash } from 'node:crypto';
import { existsSync, lstatSync, readFileSync, readlinkSync, renameSync, unlinkSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { dirname, join } from 'node:path';
import { fileURLToPath } from 'node:url';
import { acquireLock, LOCK_DIR, type Lock } from './lock.js';
import { POLICY_DIR, POLICY_FILE, POLICY_REGISTRY } from './policy.js';
import { ensureReaper } from './reaper.js';

const HERE = dirname(fileURLToPath(import.meta.url));
const PUMP = join(HERE, 'pty-pump.py');
const SHIM_SOURCE = join(HERE, 'serial-shim.c');

export const SERIAL_DEVICE = '/dev/ttyS0';
export const BACKUP_SUFFIX = '.satscope-orig';

/** CLOCK_MONOTONIC in µs: the time base of every timestamp the harness reports. */
export function monotonicUs(): number {
  return Number(process.hrtime.bigint()) / 1000;
}

/** Why the fake port cannot work here, or null when it can. */
export function fakeSerialUnsupportedReason(device = SERIAL_DEVICE): string | null {
  if (process.platform !== 'linux') return 'not Linux';
  if (process.getuid?.() !== 0) return 'not root (needed to replace /dev/ttyS0 and write Chromium policy)';
  const name = device.split('/').pop()!;
  const listed = existsSync(`/sys/class/tty/${name}`);
  if (listed && !existsSync(device) && !existsSync(device + BACKUP_SUFFIX)) return `${device} is absent`;
  // pty-pump.py lists a device sysfs lacks under a virtual console's uevent (a bind mount).
  if (!listed && !(existsSync('/sys/class/tty/ttyS0') && existsSync('/sys/devices/virtual/tty/tty63/uevent')))
    return `/sys/class/tty/${name} is absent and cannot be listed`;
  if (spawnSync('python3', ['-c', 'import os; os.openpty()']).status !== 0) return 'python3 with os.openpty() is missing';
  return null;
}

function isHarnessLink(path: string): boolean {
  try {
    return lstatSync(path).isSymbolicLink() && readlinkSync(path).startsWith('/dev/pts/');
  } catch {
    return false;
  }
}

/**
 * Put the original device back if a harness symlink is in its place. Idempotent and sync (safe
 * in 'exit' handlers). Returns true when something was restored.
 */
export function restoreSerialDevice(device = SERIAL_DEVICE): boolean {
  let changed = false;
  for (const p of [device, `${device}.satscope-new`]) {
    if (isHarnessLink(p)) {
      try {
        unlinkSync(p);
        changed = true;
      } catch {
        // raced with the helper's own restore
      }
    }
  }
  const backup = device + BACKUP_SUFFIX;
  if (existsSync(backup) && !existsSync(device) && !isHarnessLink(device)) {
    try {
      renameSync(backup, device);
      changed = true;
    } catch {
      // raced with the helper's own restore
    }
  }
  return changed;
}

let shimPromise: Promise<string | null> | undefined;

/**
 * Compile serial-shim.c (an LD_PRELOAD that gives ptys DTR/RTS/CTS/DSR/CD/RI and reports
 * setSignals() to the FakeSerialPort) with the system C compiler, cached in tmpdir by source
 * hash. Returns null when there is no compiler: then setSignals()/getSignals() on the fake port
 * reject with NetworkError, as they do on any pty.
 */
export function buildSignalShim(): Promise<string | null> {
  shimPromise ??= (async () => {
    const source = readFileSync(SHIM_SOURCE);
    const hash = createHash('sha256').update(source).digest('hex').slice(0, 16);
    const out = join(tmpdir(), `satscope-serial-shim-${hash}.so`);
    if (existsSync(out)) return out;
    for (const cc of ['cc', 'gcc', 'clang']) {
      const tmp = `${out}.${process.pid}.tmp`;
      const r = spawnSync(cc, ['-shared', '-fPIC', '-O2', '-o', tmp, SHIM_SOURCE, '-ldl'], { encoding: 'utf8' });
      if (r.status === 0) {
        renameSync(tmp, out);
        return out;
      }
    }
    return null;
  })();
  return shimPromise;
}

export type PaceTiming =
  /** Per-byte arrival times in µs (any origin: the first byte goes out at once). */
  | Float64Array
  | number[]
  /** A steady byte rate, e.g. 11520 for a saturated 115200-baud 8N1 line. */
  | { bytesPerSecond: number }
  /** Chunks of chunkSize bytes every periodUs, e.g. 16-byte frames every 11000 µs. */
  | { chunkSize: number; periodUs: number };

export interface PacedResult {
  bytes: number;
  /** Worst lateness of a write against its schedule, µs. */
  lateMaxUs: number;
  /** Monotonic µs when the last byte was written. */
  endUs: number;
}

export interface SignalChange {
  op: 'set' | 'break-on' | 'break-off';
  dataTerminalReady: boolean;
  requestToSend: boolean;
  /** CLOCK_MONOTONIC µs, taken inside Chromium's ioctl: compare with monotonicUs(). */
  tUs: number;
}

export interface InputSignals {
  clearToSend?: boolean;
  dataSetReady?: boolean;
  dataCarrierDetect?: boolean;
  ringIndicator?: boolean;
}

export interface FakeSerialPort {
  /** The path Chromium opens: /dev/ttyS0. */
  readonly path: string;
  /** The current pty slave behind it, e.g. /dev/pts/3 (changes on reconnect()). */
  readonly ptsPath: string;
  /** True between hangup() and reconnect(). */
  readonly hungUp: boolean;
  /** Write bytes now (after earlier queued writes); resolves once in the pty. */
  write(bytes: Uint8Array): Promise<void>;
  /** Write bytes on a schedule; resolves when the last is written. Queued after earlier writes. */
  writePaced(bytes: Uint8Array, timing: PaceTiming): Promise<PacedResult>;
  /** Bytes the page wrote that no read() has returned yet; waits for at least one. */
  read(timeoutMs?: number): Promise<Uint8Array>;
  /** Exactly n bytes the page wrote (keeps any surplus for the next read). */
  readExactly(n: number, timeoutMs?: number): Promise<Uint8Array>;
  /** Every chunk the page writes, with its monotonic µs arrival. Returns an unsubscribe. */
  onData(listener: (bytes: Uint8Array, tUs: number) => void): () => void;
  /** DTR/RTS/break changes made through setSignals() (needs the shim: see buildSignalShim). */
  readonly signalChanges: readonly SignalChange[];
  onSignals(listener: (change: SignalChange) => void): () => void;
  /** Resolves with the first change (past or future) matching `predicate`. */
  waitForSignals(predicate: (change: SignalChange) => boolean, timeoutMs?: number): Promise<SignalChange>;
  /** The lines getSignals() reports (needs the shim). Default CTS, DSR and CD asserted. */
  setInputSignals(signals: InputSignals): Promise<void>;
  /**
   * Close the pty master: the device vanishes. Chromium's pending read fails with NetworkError
   * "The device has been lost.", port.readable becomes null; no 'disconnect' event (no udev).
   * /dev/ttyS0 keeps pointing at the dead pty, so open() fails until reconnect().
   */
  hangup(): Promise<void>;
  /** A fresh pty in place of /dev/ttyS0 (hangs up the current one first). */
  reconnect(): Promise<void>;
  /** Hang up, restore /dev/ttyS0, release the device lock. Idempotent. */
  close(): Promise<void>;
}

export interface FakeSerialPortOptions {
  device?: string;
  /** Paced bytes due within this many µs of each other go out in one write(). Default 500. */
  coalesceUs?: number;
  /** Waiting for another test (process) using the same device. Default 120 s. */
  lockTimeoutMs?: number;
  /**
   * Run the pump at a real-time priority (SCHED_FIFO, where `chrt` may), so that on a loaded
   * machine it reads the page's writes as they come and stamps them on time: what it reads in one
   * piece was then written together, not held up by the reader. Default false.
   */
  realtime?: boolean;
}

function frame(kind: string, payload: Uint8Array): Buffer {
  const head = Buffer.alloc(5);
  head.write(kind, 0, 'latin1');
  head.writeUInt32LE(payload.length, 1);
  return Buffer.concat([head, payload]);
}

function scheduleFor(n: number, timing: PaceTiming): Float64Array {
  const times = new Float64Array(n);
  if (timing instanceof Float64Array || Array.isArray(timing)) {
    if (timing.length < n) throw new Error(`writePaced: ${timing.length} times for ${n} bytes`);
    const t0 = timing[0] ?? 0;
    for (let i = 0; i < n; i++) times[i] = timing[i]! - t0;
  } else if ('bytesPerSecond' in timing) {
    for (let i = 0; i < n; i++) times[i] = (i * 1e6) / timing.bytesPerSecond;
  } else {
    for (let i = 0; i < n; i++) times[i] = Math.floor(i / timing.chunkSize) * timing.periodUs;
  }
  return times;
}

/**
 * Replace /dev/ttyS0 with a pty until close(). Waits for other users of the device (a lock
 * across processes), restores a swap left behind by a crashed run first.
 */
export async function openFakeSerialPort(options: FakeSerialPortOptions = {}): Promise<FakeSerialPort> {
  const device = options.device ?? SERIAL_DEVICE;
  const reason = fakeSerialUnsupportedReason(device);
  if (reason) throw new Error(`fake serial port unavailable: ${reason}`);
  ensureReaper({ lockDir: LOCK_DIR, registry: POLICY_REGISTRY, policyFile: POLICY_FILE, policyDir: POLICY_DIR });
  const lock: Lock = await acquireLock(`serial-${device.replaceAll('/', '_')}`, options.lockTimeoutMs);
  restoreSerialDevice(device); // stale swap from a crashed run (its owner is gone: we hold the lock)

  const pump = ['python3', '-u', PUMP, device, String(options.coalesceUs ?? 500)];
  const realtime = options.realtime === true && spawnSync('chrt', ['-f', '20', 'true']).status === 0;
  const [command, ...args] = realtime ? ['chrt', '-f', '20', ...pump] : pump;
  const child: ChildProcess = spawn(command as string, args, {
    stdio: ['pipe', 'pipe', 'pipe'],
  });
  let stderr = '';
  child.stderr!.setEncoding('utf8');
  child.stderr!.on('data', (d: string) => (stderr += d));

  const dataListeners = new Set<(b: Uint8Array, t: number) => void>();
  const signalListeners = new Set<(c: SignalChange) => void>();
  const signalChanges: SignalChange[] = [];
  const received: Uint8Array[] = [];
  let receivedWake: (() => void) | undefined;
  /** What pty-pump.py reports, one JSON object per 'E' message (the pump is ours: trusted). */
  type Ev =
    | { type: 'ready'; pts: string }
    | { type: 'signals'; op: SignalChange['op']; bits: number; t: number }
    | { type: 'paced'; id: number; ok: true; bytes: number; lateMaxUs: number; t: number }
    | { type: 'paced'; id: number; ok: false; reason: string }
    | { type: 'signals-in' }
    | { type: 'hungup' }
    | { type: 'error'; message: string };
  const eventWaiters: { match: (e: Ev) => boolean; resolve: (e: Ev) => void; reject: (e: Error) => void }[] = [];
  let exited = false;
  let exitError: Error | undefined;
  let ptsPath = '';
  let hungUp = false;

  const waitEvent = (match: (e: Ev) => boolean, what: string, timeoutMs = 10_000) =>
    new Promise<Ev>((resolve, reject) => {
      if (exited) return reject(exitError ?? new Error('pty helper exited'));
      const w = {
        match,
        resolve: (e: Ev) => {
          clearTimeout(timer);
          resolve(e);
        },
        reject: (e: Error) => {
          clearTimeout(timer);
          reject(e);
        },
      };
      const timer = setTimeout(() => {
        eventWaiters.splice(eventWaiters.indexOf(w), 1);
        reject(new Error(`pty helper: timed out waiting for ${what}; stderr: ${stderr}`));
      }, timeoutMs);
      eventWaiters.push(w);
    });

  const onEvent = (e: Ev) => {
    if (e.type === 'ready') ptsPath = e.pts;
    if (e.type === 'signals') {
      const change: SignalChange = {
        op: e.op,
        dataTerminalReady: (e.bits & 0x002) !== 0, // TIOCM_DTR
        requestToSend: (e.bits & 0x004) !== 0, // TIOCM_RTS
        tUs: e.t,
      };
      signalChanges.push(change);
      for (const l of signalListeners) l(change);
    }
    if (e.type === 'error') exitError = new Error(`pty helper: ${e.message}`);
    for (const w of [...eventWaiters]) {
      if (w.match(e)) {
        eventWaiters.splice(eventWaiters.indexOf(w), 1);
        w.resolve(e);
      }
    }
  };

  let inbuf: Buffer = Buffer.alloc(0);
  child.stdout!.on('data', (chunk: Buffer) => {
    inbuf = inbuf.length ? Buffer.concat([inbuf, chunk]) : chunk;
    while (inbuf.length >= 5) {
      const len = inbuf.readUInt32LE(1);
      if (inbuf.length < 5 + len) break;
      const kind = String.fromCharCode(inbuf[0]!);
      const payload = inbuf.subarray(5, 5 + len);
      inbuf = inbuf.subarray(5 + len);
      if (kind === 'D') {
        const t = payload.readDoubleLE(0);
        const bytes = new Uint8Array(payload.subarray(8)); // copy
        received.push(bytes);
        for (const l of dataListeners) l(bytes, t);
        receivedWake?.();
      } else if (kind === 'E') {
        onEvent(JSON.parse(payload.toString('utf8')) as Ev);
      }
    }
  });

  const exitPromise = new Promise<void>((resolve) => {
    child.on('exit', (code, sig) => {
      exited = true;
      exitError ??= code === 0 ? new Error('pty helper exited') : new Error(`pty helper exited (${code ?? sig}): ${stderr}`);
      for (const w of eventWaiters.splice(0)) w.reject(exitError);
      receivedWake?.();
      resolve();
    });
  });
  child.on('error', (e) => {
    exitError = e;
  });
  child.stdin!.on('error', () => {
    /* helper gone: reported through exit */
  });

  // Last resort if this process exits without close(): the helper restores on stdin EOF too.
  const onExit = () => {
    try {
      child.kill('SIGTERM');
    } catch {
      // already gone
    }
    restoreSerialDevice(device);
    lock.release();
  };
  process.on('exit', onExit);

  const send = (kind: string, payload: Uint8Array = new Uint8Array(0)) => {
    if (exited) throw exitError ?? new Error('pty helper exited');
    child.stdin!.write(frame(kind, payload));
  };

  try {
    await waitEvent((e) => e.type === 'ready', 'the pty', 10_000);
  } catch (e) {
    child.kill('SIGTERM');
    await exitPromise;
    process.off('exit', onExit);
    restoreSerialDevice(device);
    lock.release();
    throw e;
  }

  let nextJob = 1;
  const writePaced = async (bytes: Uint8Array, timing: PaceTiming): Promise<PacedResult> => {
    if (hungUp) throw new Error('fake serial port is hung up: reconnect() first');
    const n = bytes.length;
    const times = scheduleFor(n, timing);
    const id = nextJob++;
    const payload = Buffer.alloc(8 + 9 * n);
    payload.writeUInt32LE(id, 0);
    payload.writeUInt32LE(n, 4);
    Buffer.from(times.buffer, times.byteOffset, times.byteLength).copy(payload, 8);
    payload.set(bytes, 8 + 8 * n);
    const done = waitEvent((e) => e.type === 'paced' && e.id === id, `paced write ${id}`, (times[n - 1] ?? 0) / 1000 + 30_000);
    send('P', payload);
    const e = await done;
    if (e.type !== 'paced') throw new Error(`pty helper: expected a paced write's end, got ${e.type}`);
    if (!e.ok) throw new Error(`paced write interrupted: ${e.reason}`);
    return { bytes: e.bytes, lateMaxUs: e.lateMaxUs, endUs: e.t };
  };

  const takeReceived = (max = Infinity): Uint8Array => {
    const total = received.reduce((s, b) => s + b.length, 0);
    const n = Math.min(total, max);
    const out = new Uint8Array(n);
    let off = 0;
    while (off < n) {
      const b = received[0]!;
      const take = Math.min(b.length, n - off);
      out.set(b.subarray(0, take), off);
      off += take;
      if (take === b.length) received.shift();
      else received[0] = b.subarray(take);
    }
    return out;
  };
  const pending = () => received.reduce((s, b) => s + b.length, 0);
  const waitReceived = async (n: number, timeoutMs: number) => {
    const deadline = Date.now() + timeoutMs;
    while (pending() < n) {
      if (exited) throw exitError ?? new Error('pty helper exited');
      const left = deadline - Date.now();
      if (left <= 0) throw new Error(`fake serial port: timed out waiting for ${n} bytes from the page (have ${pending()})`);
      await new Promise<void>((r) => {
        const t = setTimeout(r, left);
        receivedWake = () => {
          clearTimeout(t);
          r();
        };
      });
      receivedWake = undefined;
    }
  };

  let closed: Promise<void> | undefined;
  const port: FakeSerialPort = {
    path: device,
    get ptsPath() {
      return ptsPath;
    },
    get hungUp() {
      return hungUp;
    },
    async write(bytes) {
      await writePaced(bytes, new Float64Array(bytes.length));
    },
    writePaced,
    async read(timeoutMs = 10_000) {
      await waitReceived(1, timeoutMs);
      return takeReceived();
    },
    async readExactly(n, timeoutMs = 10_000) {
      await waitReceived(n, timeoutMs);
      return takeReceived(n);
    },
    onData(listener) {
      dataListeners.add(listener);
      return () => dataListeners.delete(listener);
    },
    signalChanges,
    onSignals(listener) {
      signalListeners.add(listener);
      return () => signalListeners.delete(listener);
    },
    waitForSignals(predicate, timeoutMs = 10_000) {
      const past = signalChanges.find(predicate);
      if (past) return Promise.resolve(past);
      return new Promise((resolve, reject) => {
        const timer = setTimeout(() => {
          off();
          reject(new Error('fake serial port: timed out waiting for a signal change'));
        }, timeoutMs);
        const off = port.onSignals((c) => {
          if (predicate(c)) {
            clearTimeout(timer);
            off();
            resolve(c);
          }
        });
      });
    },
    async setInputSignals(s) {
      const bits =
        ((s.clearToSend ?? true) ? 0x020 : 0) | // TIOCM_CTS
        ((s.dataSetReady ?? true) ? 0x100 : 0) | // TIOCM_DSR
        ((s.dataCarrierDetect ?? true) ? 0x040 : 0) | // TIOCM_CD
        ((s.ringIndicator ?? false) ? 0x080 : 0); // TIOCM_RI
      const p = Buffer.alloc(4);
      p.writeUInt32LE(bits);
      const ack = waitEvent((e) => e.type === 'signals-in', 'input signals');
      send('S', p);
      await ack;
    },
    async hangup() {
      if (hungUp) return;
      const ack = waitEvent((e) => e.type === 'hungup', 'hangup');
      send('H');
      await ack;
      hungUp = true;
    },
    async reconnect() {
      const ack = waitEvent((e) => e.type === 'ready', 'the new pty');
      send('N');
      await ack;
      hungUp = false;
    },
    close() {
      closed ??= (async () => {
        if (!exited) {
          try {
            send('Q');
            child.stdin!.end();
          } catch {
            // gone
          }
          const t = setTimeout(() => child.kill('SIGKILL'), 5000);
          await exitPromise;
          clearTimeout(t);
        }
        hungUp = true;
        process.off('exit', onExit);
        restoreSerialDevice(device);
        lock.release();
      })();
      return closed;
    },
  };
  return port;
}
