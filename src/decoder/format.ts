/**
 * What a decoder has decided about the format, and why, from its state: `format` and the
 * sentence it explains itself in.
 */
import { B0_FADES, B0_UNKNOWN } from './header.js';
import { type Resolution, systemInfo } from './spec.js';
import type { DecoderState } from './state.js';
import type { FormatInfo, HeaderReading } from './types.js';

export function formatOf(s: Readonly<DecoderState>): FormatInfo {
  return {
    locked: s.locked,
    resolution: s.everLocked ? s.resolution : null,
    resolutionReason: s.reason,
    explanation: explain(s),
    remote: s.everLocked ? s.remote : null,
    system: s.system,
    systemValid: s.system !== null && systemInfo(s.system) !== undefined,
    headerMode: headerReading(s),
    forcedMismatch: s.forcedMismatch,
    withheld: s.withheld,
    remoteAmbiguous: s.ambiguous,
    alignmentUnproven: s.alignAlts !== 0,
  };
}

function headerReading(s: DecoderState): HeaderReading {
  if (s.remote !== 'internal') return 'fades';
  if (s.b0Mode === B0_UNKNOWN) return 'unknown';
  return s.b0Mode === B0_FADES ? 'fades' : 'rssi';
}

/** Sets `s.reason`: why the lock reads `resolution`. */
export function setReason(s: DecoderState, resolution: Resolution): void {
  if (s.opts.resolution !== 'auto') {
    s.reason = s.fixedBy === 'internal-remote' ? 'internal-remote' : 'override';
    return;
  }
  const info = s.system === null ? undefined : systemInfo(s.system);
  if (info === undefined) s.reason = 'channel-ids';
  else s.reason = info.resolution === resolution ? 'system-byte' : 'system-byte-contradicted';
}

function explain(s: DecoderState): string {
  const other = s.forcedMismatch;
  if (other !== null) {
    return `Forced ${s.opts.resolution}: no frame matches; the stream looks like ${other}.`;
  }
  if (!s.locked && s.withheld === 'forced') {
    const { resolution, remote, headerMode } = s.opts;
    const set = [
      resolution === 'auto' ? '' : `resolution ${resolution}`,
      remote === 'auto' ? '' : `remote ${remote}`,
      headerMode === 'auto' ? '' : `header mode ${headerMode}`,
    ].filter((x) => x !== '');
    return `No frame matches the forced ${set.join(', ')}: the bytes are frames, read another way; nothing is decoded.`;
  }
  if (!s.locked && s.withheld === 'filler') {
    return `${s.everLocked ? 'Looking for frames again' : 'No frames'}: the bytes read as frames only of empty slots (0xFFFF) or 0x00/0xFF filler, which carry no channel.`;
  }
  if (!s.everLocked) return 'Not locked on to frames yet.';
  if (!s.locked) return 'Looking for frames again: the format changed or the frames stopped making sense.';
  const res = s.resolution;
  const sys = s.system === null ? undefined : systemInfo(s.system);
  const hex = (v: number) => `0x${v.toString(16).padStart(2, '0').toUpperCase()}`;
  let remote = 'external remote (or a receiver that sends no system byte): bytes 0–1 are a UINT16 fade count';
  if (s.remote === 'internal') {
    const b0 =
      s.b0Mode === B0_UNKNOWN
        ? '; byte 0 has stayed at values that are fades above 155 or SPM4649T RSSI, without falling: not yet known which'
        : s.b0Mode === B0_FADES
          ? ''
          : '; byte 0 is SPM4649T RSSI';
    const or = s.ambiguous
      ? `; or an external remote whose fade count's low byte is ${hex(s.system ?? 0)}: not yet known which (byte 0 moving says internal, byte 1 moving external)`
      : '';
    remote = sys
      ? `internal remote (system byte ${hex(s.system ?? 0)}, ${sys.name})${b0}${or}`
      : `internal remote (system byte ${hex(s.system ?? 0)} is none of the four in §8.3: ignored)${b0}`;
  }
  if (s.alignAlts !== 0) remote += unproven(s.alignAlts);
  switch (s.reason) {
    case 'override':
      return `${res} resolution set by the user; ${remote}.`;
    case 'internal-remote':
      return `${res} resolution from the internal remote's system byte (on another port: it holds the key for every remote); ${remote}.`;
    case 'system-byte':
      return `${res} resolution from the system byte, confirmed by the channel IDs; ${remote}.`;
    case 'system-byte-contradicted':
      return `${res} resolution inferred from the channel IDs: the system byte says ${sys?.resolution ?? '?'} but its channel IDs only make sense at ${res}; ${remote}.`;
    default:
      return `${res} resolution inferred from the channel IDs (no valid system byte); ${remote}.`;
  }
}

/** What an unproven frame alignment (`alignAlts`: bit j, frames j bytes later) means, and what decides it. */
function unproven(alts: number): string {
  let bytes = '';
  for (let j = 1; j < 16; j++) if ((alts >> j) & 1) bytes += `${bytes ? ', ' : ''}${j}`;
  return `; where frames start is not yet proven: they read as well ${bytes} bytes later (a held stick as the fade count, the count as a channel): move each stick in turn to decide it`;
}
