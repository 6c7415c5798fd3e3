/**
 * How much of a capture has been read, as the replay bar says it while a long capture is still
 * being read. Never "0 %" once something was read (the overview already draws it), and never
 * more than was read: rounded down, with one decimal under 10 %, and "< 0.1 %" below that.
 */
export function readingPercent(readUntilUs: number, startUs: number, endUs: number): string {
  const fraction = (readUntilUs - startUs) / Math.max(1, endUs - startUs);
  const pct = 100 * Math.min(1, Math.max(0, fraction));
  if (pct <= 0) return '0 %';
  if (pct < 0.1) return '< 0.1 %';
  if (pct < 10) return `${(Math.floor(pct * 10) / 10).toFixed(1)} %`;
  return `${Math.floor(pct)} %`;
}
