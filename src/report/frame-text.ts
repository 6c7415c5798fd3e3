/**
 * One decoded frame as a line of text: the documented JSONL and CSV forms that `satscope
 * decode` prints and the page's "decoded frames" export saves, so both give the same file.
 */
import { channelResolution, servoToMicros, CHANNEL_COUNT } from '../decoder/spec.js';
import type { DecodedFrame } from '../decoder/types.js';

const seconds = (us: number): string => (Number.isFinite(us) ? String(us / 1e6) : 'null');
const usOf = (f: DecodedFrame, i: number): number => servoToMicros(f.positions[i] ?? 0, channelResolution(f.ids[i] ?? 0, f.resolution));

/**
 * One frame as the documented JSONL line:
 * {"t": s|null, "remote": …, "system": byte|null, "resolution": …, "fades": n|null, "rssi": dBm|null, "channels": [{"id", "pos", "us"}, …]}
 */
export function formatJsonLine(f: DecodedFrame): string {
  let channels = '';
  for (let i = 0; i < f.count; i++) {
    if (i > 0) channels += ', ';
    channels += `{"id": ${f.ids[i] ?? 0}, "pos": ${f.positions[i] ?? 0}, "us": ${usOf(f, i)}}`;
  }
  return `{"t": ${seconds(f.timeUs)}, "remote": "${f.remote}", "system": ${f.system ?? 'null'}, "resolution": ${f.resolution}, "fades": ${f.fades ?? 'null'}, "rssi": ${f.rssi ?? 'null'}, "channels": [${channels}]}`;
}

const CHANNEL_COLUMNS = Array.from({ length: CHANNEL_COUNT }, (_, id) => `ch${id}_us`);

/** The header row of `satscope decode --format csv`, matching `formatCsvLine`. */
export function formatCsvHeader(): string {
  return ['t', 'remote', 'system', 'resolution', 'fades', 'rssi', ...CHANNEL_COLUMNS].join(',');
}

/** One frame as a CSV row: pulse widths in µs per channel ID, empty where the frame has none. */
export function formatCsvLine(f: DecodedFrame): string {
  const cells: string[] = new Array<string>(CHANNEL_COUNT).fill('');
  for (let i = 0; i < f.count; i++) cells[f.ids[i] ?? 0] = String(usOf(f, i));
  const t = Number.isFinite(f.timeUs) ? String(f.timeUs / 1e6) : '';
  return [t, f.remote, f.system ?? '', f.resolution, f.fades ?? '', f.rssi ?? '', ...cells].join(',');
}
