/**
 * The recorder: raw bytes with their arrival times, written to the origin private file system
 * as they arrive (a synchronous access handle, only available in workers), so memory does not
 * grow with the recording and a reload, crash or unplug keeps everything written. Each record
 * carries a CRC, so an unfinished file is simply a capture that ends early: a marker file names
 * the recording in progress, and on the next start it is offered back.
 */
import { CaptureWriter } from '../capture/writer.js';
import { captureChunks, type Capture, type CaptureMeta } from '../capture/model.js';
import { capturePorts } from '../capture/facts.js';
import { parseCapture } from '../capture/reader.js';
import type { RecordingStatus } from './protocol.js';

const DIR = 'recordings';
/** Names the recordings not finished yet (the one in progress, and any a crash or reload left). */
const MARKER = 'in-progress.json';
/** Finished recordings kept in the private storage (older ones are deleted at start-up). */
const KEEP_FINISHED = 5;
/** Make written data durable about once a second. */
const FLUSH_EVERY_US = 1_000_000;

interface Marker {
  name: string;
  createdAt: string;
}

async function directory(): Promise<FileSystemDirectoryHandle> {
  const root = await navigator.storage.getDirectory();
  return root.getDirectoryHandle(DIR, { create: true });
}

async function readMarkers(dir: FileSystemDirectoryHandle): Promise<Marker[]> {
  try {
    const file = await (await dir.getFileHandle(MARKER)).getFile();
    const parsed: unknown = JSON.parse(await file.text());
    // Version 1 of this file held one object; now a list.
    const list = Array.isArray(parsed) ? parsed : [parsed];
    return list.filter((m): m is Marker => typeof m === 'object' && m !== null && typeof (m as Marker).name === 'string');
  } catch {
    return [];
  }
}

async function writeMarkers(dir: FileSystemDirectoryHandle, markers: readonly Marker[]): Promise<void> {
  if (markers.length === 0) {
    await dir.removeEntry(MARKER).catch(() => undefined);
    return;
  }
  const handle = await (await dir.getFileHandle(MARKER, { create: true })).createSyncAccessHandle();
  try {
    const bytes = new TextEncoder().encode(JSON.stringify(markers));
    handle.truncate(0);
    handle.write(bytes, { at: 0 });
    handle.flush();
  } finally {
    handle.close();
  }
}

/** Deletes all but the newest finished recordings (names sort by their start time). */
async function pruneFinished(dir: FileSystemDirectoryHandle, unfinished: readonly Marker[]): Promise<void> {
  const names: string[] = [];
  for await (const name of (dir as unknown as { keys(): AsyncIterable<string> }).keys()) {
    if (name.endsWith('.sscap') && !unfinished.some((m) => m.name === name)) names.push(name);
  }
  names.sort();
  for (const name of names.slice(0, Math.max(0, names.length - KEEP_FINISHED))) await dir.removeEntry(name).catch(() => undefined);
}

/** A capture's raw bytes, one file per port (`base.bin`, or `base-port0.bin`… with several ports). */
export function rawFiles(capture: Capture, base: string): { name: string; data: ArrayBuffer }[] {
  const ports = capturePorts(capture);
  if (ports.length <= 1) return [{ name: `${base}.bin`, data: capture.bytes.slice().buffer }];
  return ports.map((port) => {
    const parts = Array.from(captureChunks(capture, port), (c) => c.bytes);
    const out = new Uint8Array(parts.reduce((n, b) => n + b.length, 0));
    let at = 0;
    for (const b of parts) {
      out.set(b, at);
      at += b.length;
    }
    return { name: `${base}-port${port}.bin`, data: out.buffer };
  });
}

export class Recorder {
  #dir: FileSystemDirectoryHandle | undefined;
  #handle: FileSystemSyncAccessHandle | undefined;
  #writer: CaptureWriter | undefined;
  #name = '';
  #createdAt = '';
  #at = 0;
  #records = 0;
  #firstUs = NaN;
  #lastUs = NaN;
  #lastFlushUs = 0;
  /** The last finished recording, for export. */
  #last: string | null = null;
  /** Unfinished recordings from earlier sessions, newest last; the newest is offered. */
  #unfinished: (Marker & { bytes: number })[] = [];
  #error: string | null = null;
  /** Writing this recording failed: what was written stands, and nothing more (no final index) is added. */
  #failed = false;

  constructor(readonly onChange: (status: RecordingStatus) => void) {}

  /** Looks for recordings an earlier session left unfinished, and tidies the storage. */
  async init(): Promise<void> {
    try {
      const dir = (this.#dir = await directory());
      const kept: (Marker & { bytes: number })[] = [];
      for (const marker of await readMarkers(dir)) {
        try {
          const file = await (await dir.getFileHandle(marker.name)).getFile();
          kept.push({ ...marker, bytes: file.size });
        } catch {
          // The file is gone: forget its marker.
        }
      }
      this.#unfinished = kept;
      await writeMarkers(dir, kept);
      await pruneFinished(dir, kept);
    } catch (error) {
      this.#error = `Recording is not available: this browser gives the page no private file storage (${String(error)}).`;
    }
    this.#report();
  }

  get #recovered(): (Marker & { bytes: number }) | null {
    return this.#unfinished.at(-1) ?? null;
  }

  /** The markers of every unfinished recording, this one included while it runs. */
  #markers(): Marker[] {
    const list: Marker[] = this.#unfinished.map(({ name, createdAt }) => ({ name, createdAt }));
    if (this.#handle !== undefined) list.push({ name: this.#name, createdAt: this.#createdAt });
    return list;
  }

  get active(): boolean {
    return this.#handle !== undefined;
  }

  status(): RecordingStatus {
    return {
      active: this.active,
      bytes: this.#at,
      records: this.#records,
      durationUs: Number.isFinite(this.#firstUs) ? this.#lastUs - this.#firstUs : 0,
      recovered:
        this.#recovered === null
          ? null
          : { name: this.#recovered.name, bytes: this.#recovered.bytes, createdAt: this.#recovered.createdAt },
      error: this.#error,
    };
  }

  #report(): void {
    this.onChange(this.status());
  }

  async start(meta: CaptureMeta, createdAt: string): Promise<void> {
    if (this.#handle !== undefined) return;
    let handle: FileSystemSyncAccessHandle | undefined;
    try {
      const dir = this.#dir ?? (this.#dir = await directory());
      const name = `satscope-${createdAt.replace(/[:.]/g, '-')}.sscap`;
      handle = await (await dir.getFileHandle(name, { create: true })).createSyncAccessHandle();
      handle.truncate(0);
      this.#writer = new CaptureWriter({ ...meta, createdAt });
      this.#failed = false;
      this.#handle = handle;
      this.#name = name;
      this.#createdAt = createdAt;
      this.#at = 0;
      this.#records = 0;
      this.#firstUs = this.#lastUs = NaN;
      this.#write(this.#writer.header());
      handle.flush();
      await writeMarkers(dir, this.#markers());
      this.#error = null;
    } catch (error) {
      handle?.close();
      this.#handle = undefined;
      this.#error = `Could not start recording: ${String(error)}`;
    }
    this.#report();
  }

  #write(bytes: Uint8Array): void {
    const handle = this.#handle as FileSystemSyncAccessHandle;
    const written = handle.write(bytes, { at: this.#at });
    if (written !== bytes.length) throw new Error(`storage accepted ${written} of ${bytes.length} bytes (disk full?)`);
    this.#at += written;
  }

  /** Appends raw bytes as they arrived. */
  data(bytes: Uint8Array, timeUs: number, port = 0): void {
    if (this.#handle === undefined || this.#writer === undefined) return;
    try {
      this.#write(this.#writer.data(bytes, timeUs, port));
    } catch (error) {
      this.#fail(error);
      return;
    }
    this.#records++;
    if (Number.isNaN(this.#firstUs)) this.#firstUs = timeUs;
    this.#lastUs = timeUs;
    if (timeUs - this.#lastFlushUs >= FLUSH_EVERY_US) {
      this.#handle.flush();
      this.#lastFlushUs = timeUs;
      this.#report();
    }
  }

  /** Notes something that happened to the port (lost, reconnected) in the recording. */
  event(text: string, timeUs: number, port = 0): void {
    if (this.#handle === undefined || this.#writer === undefined) return;
    try {
      this.#write(this.#writer.event(text, timeUs, port));
      this.#handle.flush();
    } catch (error) {
      this.#fail(error);
    }
  }

  #fail(error: unknown): void {
    this.#failed = true;
    this.#error = `Recording stopped: ${String(error)}. Everything written before this point is kept.`;
    void this.stop();
  }

  async stop(): Promise<void> {
    const handle = this.#handle;
    if (handle === undefined) return;
    try {
      // The final index, unless writing already failed (the file then ends with what was written).
      if (!this.#failed && this.#writer !== undefined) this.#write(this.#writer.close());
    } catch (error) {
      this.#error = `The recording's index could not be written (${String(error)}): the file is read by a plain scan instead.`;
    }
    this.#handle = undefined;
    try {
      handle.flush();
    } finally {
      handle.close();
    }
    this.#last = this.#name;
    if (this.#dir !== undefined) await writeMarkers(this.#dir, this.#markers());
    this.#report();
  }

  /**
   * The last (or recovered) recording: the .sscap file itself, or the raw serial bytes alone,
   * one file per port (every intact record's data of that port, in order). A raw file has no
   * room to say which port a byte came from, so two ports' bytes in one would interleave into
   * a stream no decoder can read.
   */
  async export(which: 'last' | 'recovered', what: 'sscap' | 'raw'): Promise<{ name: string; data: ArrayBuffer }[] | string> {
    const name = which === 'last' ? this.#last : (this.#recovered?.name ?? null);
    if (name === null || this.#dir === undefined) return which === 'last' ? 'Nothing recorded yet.' : 'No unfinished recording.';
    const file = await (await this.#dir.getFileHandle(name)).getFile();
    const data = await file.arrayBuffer();
    if (what === 'sscap') return [{ name, data }];
    return rawFiles(parseCapture(new Uint8Array(data)), name.replace(/\.sscap$/, ''));
  }

  /**
   * The recording so far (while recording, read through the open handle) or the last finished
   * one, for a report on the live session; null when nothing was recorded.
   */
  async current(): Promise<Uint8Array | null> {
    const handle = this.#handle;
    if (handle !== undefined) {
      handle.flush();
      const out = new Uint8Array(this.#at);
      handle.read(out, { at: 0 });
      return out;
    }
    if (this.#last === null || this.#dir === undefined) return null;
    const file = await (await this.#dir.getFileHandle(this.#last)).getFile();
    return new Uint8Array(await file.arrayBuffer());
  }

  async discardRecovered(): Promise<void> {
    const recovered = this.#recovered;
    if (recovered === null || this.#dir === undefined) return;
    await this.#dir.removeEntry(recovered.name).catch(() => undefined);
    this.#unfinished = this.#unfinished.filter((m) => m.name !== recovered.name);
    await writeMarkers(this.#dir, this.#markers());
    this.#report();
  }
}
