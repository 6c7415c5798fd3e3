/**
 * The resolution across the session's sources: external remotes take theirs from the internal
 * remote (spec §8: "the internal remote provides the key for … all remotes") unless their bytes
 * refuse it, and a forced resolution that matches no frame is told to the user once.
 */
import { resolutionKey } from '../report/resolution-key.js';
import { type Host, notice } from './host.js';
import type { Source, SourceRegistry } from './registry.js';

/** Bytes an external remote may discard at the internal remote's resolution before it is given up. */
const REFUSE_AFTER_BYTES = 512;

/** Gives external remotes the internal remote's resolution, or takes it back when it does not fit. */
export function shareResolution(registry: SourceRegistry, host: Host): void {
  const sources = registry.list();
  const key = resolutionKey(sources.map((s) => s.engine.decoder.format));
  for (const s of sources) {
    const d = s.engine.decoder;
    if (d.format.remote === 'internal' || registry.resolution !== 'auto' || (key !== undefined && s.refusedKey === key)) continue;
    if (s.sharedKey !== key) {
      s.engine.setResolution(key ?? 'auto', registry.clockUs(), 'internal-remote');
      s.sharedKey = key;
      s.sharedAt = { frames: d.stats.frames, discarded: d.stats.discardedBytes };
    } else if (
      s.sharedAt !== undefined &&
      d.stats.frames === s.sharedAt.frames &&
      d.stats.discardedBytes - s.sharedAt.discarded > REFUSE_AFTER_BYTES
    ) {
      // Its bytes do not read at that resolution (a remote of another system?): its own reading wins.
      s.engine.setResolution('auto', registry.clockUs());
      s.refusedKey = key;
      s.sharedKey = undefined;
      notice(
        host,
        'warning',
        `Remote ${s.label} does not read at the internal remote's resolution`,
        `Its frames only make sense at the other resolution; it is decoded on its own (${key ?? ''} did not fit). Are both remotes bound to the same transmitter?`,
      );
    }
  }
}

/**
 * Tells the user once when the resolution they forced matches no frame: the link counts
 * nothing meanwhile (no hold, failsafe or missed frame), and the page shows it as waiting.
 */
export function tellMismatch(s: Source, forced: 'auto' | 1024 | 2048, host: Host): void {
  const m = s.engine.mismatch;
  if (m === (s.toldMismatch ?? null)) return;
  s.toldMismatch = m;
  if (m === null || forced === 'auto') return;
  notice(
    host,
    'warning',
    `Remote ${s.label}: forced ${forced}: no frame matches; the stream looks like ${m}`,
    `Nothing is counted as missed while no frame decodes. Choose Auto or ${m} to decode it again.`,
  );
}

/** The user chose a resolution: every decode takes it, and the frames pausing meanwhile is not link loss. */
export function setResolution(registry: SourceRegistry, resolution: 'auto' | 1024 | 2048): void {
  registry.resolution = resolution;
  for (const s of registry.list()) {
    s.engine.setResolution(resolution, registry.linkNowUs(s.id));
    s.sharedKey = undefined;
  }
}
