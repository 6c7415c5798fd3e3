/**
 * Bytes from a live source (a serial port, the demo) into its decode and the recording, and a
 * batch for the page scheduled. Bytes for a source that is gone (closed while its data was on
 * the way) go nowhere.
 */
import type { Batcher } from './batcher.js';
import type { Host } from './host.js';
import type { Recorder } from './recorder.js';
import type { SourceRegistry } from './registry.js';

/** Where a live source's bytes go: `timeUs` is their arrival on the worker's clock. */
export type LiveSink = (id: number, bytes: Uint8Array, timeUs: number) => void;

export function liveSink(host: Host, registry: SourceRegistry, recorder: Recorder, batcher: Batcher): LiveSink {
  return (id, bytes, timeUs) => {
    const source = registry.get(id);
    if (source === undefined || source.kind === 'replay') return;
    source.engine.push(bytes, timeUs, host.timeOriginMs + timeUs / 1000);
    recorder.data(bytes, timeUs, id);
    batcher.schedule();
  };
}
