/** Text forms of frames and summaries for the CLI. */
import type { HealthReport, ReportFinding } from '../report/report-types.js';
import type { CaptureSummary } from '../report/summary.js';
import { formatClock, noFramesHint, plural } from '../report/report-text.js';
import type { CaptureTiming } from '../capture/model.js';
import { systemInfo } from '../decoder/spec.js';

// One frame a line, as `satscope decode` prints it: the library's, which the page's export uses too.
export { formatCsvHeader, formatCsvLine, formatJsonLine } from '../report/frame-text.js';

const ms = (us: number): string => `${(us / 1000).toFixed(us < 100_000 ? 2 : 0)} ms`;
const hex = (v: number): string => `0x${v.toString(16).toUpperCase().padStart(2, '0')}`;

/** A capture's timing in words: "a time per chunk", "no times". */
export const TIMING_WORDS: Record<CaptureTiming, string> = {
  'per-byte': 'a time per byte',
  'per-chunk': 'a time per chunk',
  none: 'no times',
};

/**
 * The human summary `satscope info` prints of one port. `ports` lists every port of the capture
 * with data, so that a summary of one of several says which one it is and names the others.
 */
export function formatSummary(s: CaptureSummary, name: string, ports: readonly number[] = [s.port], originUs = 0): string {
  const lines: string[] = [];
  const add = (label: string, value: string): void => {
    lines.push(`${label.padEnd(14)}${value}`);
  };
  const timed = s.timing !== 'none';
  add('File', `${name} (${s.kind}, ${TIMING_WORDS[s.timing]})`);
  const others = ports.filter((p) => p !== s.port);
  add(
    'Port',
    `${s.port}, ${plural(s.bytes, 'byte')}${others.length === 0 ? '' : ` (the capture also has ${others.length === 1 ? 'port' : 'ports'} ${others.join(', ')})`}`,
  );
  if (timed && Number.isFinite(s.durationUs)) add('Duration', `${(s.durationUs / 1e6).toFixed(3)} s`);
  const f = s.format;
  if (!f.locked && s.decoder.frames === 0) {
    add('Frames', `none found in ${s.bytes} bytes (${noFramesHint(f)})`);
    return lines.join('\n');
  }
  const sys = f.system === null ? undefined : systemInfo(f.system);
  add(
    'System',
    f.system === null
      ? 'no system byte (external remote or a receiver that sends none)'
      : `${hex(f.system)}${sys ? ` ${sys.name}` : ' (not a valid system byte)'}`,
  );
  const byte0 =
    f.headerMode === 'rssi' ? 'RSSI in dBm, SPM4649T' : f.headerMode === 'unknown' ? 'fades or RSSI, not yet known' : 'UINT8 fades';
  add('Remote', f.remote === 'internal' ? `internal (byte 0 = ${byte0})` : 'external (bytes 0–1 = UINT16 fades)');
  add('Resolution', `${f.resolution ?? '?'} — ${f.explanation}`);
  if (s.unprovenFrames > 0)
    add(
      'Alignment',
      f.alignmentUnproven
        ? `not yet proven in ${plural(s.unprovenFrames, 'frame')}: their channel values and fades may be each other's; move each stick in turn to decide it`
        : `proven after ${plural(s.unprovenFrames, 'frame')} read unproven (their channel values and fades may be each other's)`,
    );
  const d = s.decoder;
  add(
    'Frames',
    `${d.frames} (${plural(d.discardedBytes, 'byte')} discarded, ${plural(d.resyncs, 'resync')}, ${plural(d.badFrames, 'bad frame')}, ${plural(d.emptySlots, 'empty slot')}${d.vtxFrames ? `, ${plural(d.vtxFrames, 'VTX frame')}` : ''})`,
  );
  if (s.formatChanges > 0) add('', `the format changed ${plural(s.formatChanges, 'time')} during the capture`);
  add('Channels', s.channels.length === 0 ? 'none' : `${s.channels.length} (frames carrying each, lowest–highest, last)`);
  for (const c of s.channels)
    lines.push(
      `  ${String(c.id).padStart(2)} ${c.name.padEnd(9)} ${String(c.frames).padStart(7)} frames  ${c.minUs}–${c.maxUs} µs  last ${c.lastUs} µs`,
    );
  const l = s.link;
  const jumps = d.fadeJumps > 0 ? `; ${d.fadeJumps} implausible jump${d.fadeJumps === 1 ? '' : 's'} of the fade count not counted` : '';
  if (f.headerMode === 'rssi') add('RSSI', `last ${l.rssi} dBm, lowest ${l.minRssi} dBm`);
  else add('Fades', `${l.fades}${timed ? ` (${(l.fades / Math.max(s.durationUs / 60e6, 1e-9)).toFixed(1)} per minute)` : ''}${jumps}`);
  if (timed) {
    add(
      'Frame period',
      Number.isFinite(l.periodUs) ? `${ms(l.periodUs)} measured (${ms(l.nominalPeriodUs)} nominal)` : 'too few frames to measure',
    );
    add('Gaps', `${plural(l.missedFrames, 'missed frame')}, longest gap ${ms(l.longestGapUs)}`);
    add('Failsafe', `${plural(l.holds, 'hold')}, ${plural(l.failsafes, 'failsafe')}`);
    // Times from the capture's start, as the report and the doctor state them.
    for (const e of s.episodes) {
      const end = e.endUs === null ? 'to the end' : `until ${formatClock(e.endUs - originUs)}`;
      lines.push(`  ${e.kind.padEnd(8)} from ${formatClock(e.startUs - originUs)} ${end}`);
    }
  } else {
    add('Timing', 'none in this file: no frame period, gaps or failsafe episodes');
  }
  if (s.issues.length > 0) {
    const kinds = [...new Set(s.issues.map((i) => i.kind))].join(', ');
    add('File issues', `${s.issues.length} (${kinds}: what was damaged or skipped is listed above)`);
  }
  return lines.join('\n');
}

const STATUS_WORD: Record<HealthReport['status'], string> = { good: 'good', fair: 'fair', poor: 'poor', 'no-data': 'no data' };
const MARK: Record<ReportFinding['level'], string> = { problem: 'PROBLEM', warning: 'warning', info: 'info', ok: 'ok' };

/** What `satscope report --out FILE` prints: where the report went, the overall status and the findings. */
export function formatReportVerdict(r: HealthReport, written: string): string {
  const remotes = r.remotes.length;
  const lines = [`Report written to ${written}: link ${STATUS_WORD[r.status]} (${remotes} ${remotes === 1 ? 'port' : 'ports'})`];
  for (const f of r.verdict) lines.push(`  ${MARK[f.level].padEnd(9)}${f.text}`);
  return lines.join('\n');
}
