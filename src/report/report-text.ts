/**
 * How the report writes numbers: rounding for its JSON (0.1 µs is far below any timing a capture
 * carries) and the words for times, durations, counts and ratios its findings and page use.
 */

export const finite = (x: number): number | null => (Number.isFinite(x) ? x : null);
/** µs values in the report: 0.1 µs is far below any timing the capture carries. */
export const r1 = (x: number): number => Math.round(x * 10) / 10;
export const r1n = (x: number): number | null => (Number.isFinite(x) ? r1(x) : null);
export const r3 = (x: number): number => Math.round(x * 1000) / 1000;

/** "1:02.3" (minutes:seconds), "1:02:03" past an hour. */
export function formatClock(us: number): string {
  if (!Number.isFinite(us)) return '?';
  const s = Math.max(0, us / 1e6);
  if (s >= 3600) {
    const h = Math.floor(s / 3600);
    const m = Math.floor((s % 3600) / 60);
    return `${h}:${String(m).padStart(2, '0')}:${String(Math.floor(s % 60)).padStart(2, '0')}`;
  }
  // Rounded to a tenth before it is split: 9.96 s is 0:10.0 (not 0:010.0), 59.96 s 1:00.0.
  const tenths = Math.round(s * 10);
  return `${Math.floor(tenths / 600)}:${((tenths % 600) / 10).toFixed(1).padStart(4, '0')}`;
}

/** "2.4 s", "350 ms", "1.20 ms", "6.7 µs". */
export function formatDuration(us: number): string {
  if (!Number.isFinite(us)) return '?';
  if (us < 1000) return `${us < 100 ? (Math.round(us * 10) / 10).toString() : Math.round(us).toString()} µs`;
  if (us >= 1e6) return `${(us / 1e6).toFixed(us >= 100e6 ? 0 : 1)} s`;
  if (us >= 10_000) return `${Math.round(us / 1000)} ms`;
  return `${(us / 1000).toFixed(2)} ms`;
}

export const plural = (n: number, one: string, many = `${one}s`): string => `${n} ${n === 1 ? one : many}`;

/**
 * Why bytes gave no Spektrum frame, as the decoder's format says it (every surface words it so):
 * an option forced that fits none of the frames there are, filler, or else the question to ask.
 */
export function noFramesHint(format: { withheld: 'filler' | 'forced' | null; forcedMismatch: 1024 | 2048 | null }): string {
  if (format.withheld === 'forced') {
    return format.forcedMismatch !== null
      ? `the resolution forced reads none of them: they are ${format.forcedMismatch}-resolution frames; leave the resolution on auto`
      : 'the options forced read none of them; leave them on auto';
  }
  if (format.withheld === 'filler') return "they are filler (runs of 0xFF or 0x00), no transmitter's frames";
  return "is this the satellite's DATA line at 115200 baud?";
}
export const pctText = (ratio: number): string => `${(ratio * 100).toFixed(ratio < 0.001 && ratio > 0 ? 3 : ratio < 0.1 ? 2 : 1)} %`;
export const rate = (x: number): string => (x === 0 ? '0' : x >= 10 ? x.toFixed(0) : x.toFixed(1));

/** Escapes text for HTML content and attribute values. */
export function escapeHtml(text: string): string {
  return text.replace(/[&<>"']/g, (c) => (c === '&' ? '&amp;' : c === '<' ? '&lt;' : c === '>' ? '&gt;' : c === '"' ? '&quot;' : '&#39;'));
}
