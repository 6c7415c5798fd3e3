/**
 * The conformance report of a drive: what was sent, how the writes were timed, what the flight
 * controller said about itself, and each graded check (what the spec says, what it did, the
 * verdict, and what to change on the flight controller where it is wrong, in its own words).
 * As JSON, and as one self-contained HTML page (no script, no outside resource).
 */
import type { DriveReceiver } from './builtins.js';
import type { DriveCheck } from './grade.js';
import type { DriveTimingStats } from './schedule.js';

/** What a drive's report says: when, what was sent and how it was timed, what the flight controller said of itself, and the graded checks. */
export interface DriveReport {
  /** When the drive ran (ISO 8601). */
  date: string;
  scenario: { name: string; title: string };
  receiver: DriveReceiver;
  timing: DriveTimingStats;
  /** What the flight controller said about itself (null: its port was not read). */
  fc: { variant: string | null; provider: string | null } | null;
  checks: DriveCheck[];
  /** Why checks are missing or limited, in words. */
  notes: string[];
}

/**
 * What to change on the flight controller when a check fails, in its stack's own words: its CLI
 * (Betaflight, iNav) or its parameters (ArduPilot, PX4), by the stack `report.fc` names
 * (Betaflight's where it names none).
 */
export function fixFor(check: DriveCheck, report: Pick<DriveReport, 'receiver'> & { fc?: DriveReport['fc'] }): string | null {
  if (check.verdict !== 'fail') return null;
  const stack = report.fc?.variant ?? null;
  if (stack === 'ArduPilot') {
    switch (check.id) {
      case 'channel-map':
        return "ArduPilot's DSM decoder puts the satellite's throttle on RC3: set RCMAP_ROLL 1, RCMAP_PITCH 2, RCMAP_THROTTLE 3, RCMAP_YAW 4 and check the radio calibration.";
      case 'values':
        return "Check RC_PROTOCOLS includes DSM; ArduPilot's own scale (1500 + (v − 1024) / 1.7 µs) differs from §9 by design, so calibrate the radio (RCn_MIN, RCn_MAX, RCn_TRIM).";
      case 'latency':
        return 'Check RC_PROTOCOLS, the SERIALn_PROTOCOL 23 (RCIN) port the satellite is on, and that no other RC source (RC_OVERRIDE from a GCS) feeds the channels.';
      case 'failsafe':
        return 'Check FS_THR_ENABLE and RC_FS_TIMEOUT (Copter; THR_FAILSAFE on Plane), and that the satellite is the only RC input.';
      case 'steady':
        return 'ArduPilot guesses 10 or 11 bits from the channel IDs it sees: a jump after a rebind, a period switch or frames it misread is that guess; check RC_PROTOCOLS (DSM only) and update the firmware if the jumps stay.';
    }
  }
  if (stack === 'PX4') {
    switch (check.id) {
      case 'channel-map':
        return "PX4's DSM decoder puts the satellite's throttle on channel 3: set RC_MAP_ROLL 1, RC_MAP_PITCH 2, RC_MAP_THROTTLE 3, RC_MAP_YAW 4 (or redo the radio setup).";
      case 'values':
        return "PX4's own scale (1500 + (v − 1024) / 1.7 µs) differs from §9 by design: redo the radio calibration (RCn_MIN, RCn_MAX, RCn_TRIM).";
      case 'latency':
        return 'Check RC_INPUT_PROTO (or the DSM port set up for RC input) and that no other RC source feeds the channels.';
      case 'failsafe':
        return 'Check COM_RC_LOSS_T and NAV_RCL_ACT, and that the satellite is the only RC input.';
      case 'steady':
        return 'PX4 guesses 10 or 11 bits from the channel IDs it sees: a jump after a rebind or frames it misread is that guess; check RC_INPUT_PROTO and update the firmware if the jumps stay.';
    }
  }
  const provider = report.receiver.system === 0x01 ? 'SPEKTRUM1024' : 'SPEKTRUM2048';
  switch (check.id) {
    case 'channel-map':
      return 'Spektrum sends throttle first: set `map TAER1234` (Betaflight, iNav) and check the Receiver tab.';
    case 'values':
      return `Check \`serialrx_provider = ${provider}\`; the stack's own scale (Betaflight and iNav: 988 + v/2 µs) differs from §9 by design, so endpoints set on the transmitter show it.`;
    case 'latency':
      return 'Check `serialrx_provider`, the UART the satellite is on, and that nothing else (a second receiver, RX_MSP) feeds the channels.';
    case 'failsafe':
      return 'Check the failsafe settings (`failsafe_delay`, `failsafe_procedure` in Betaflight; `failsafe_*` in iNav) and that the receiver is the only RC source.';
    case 'steady':
      return `The resolution is a setting here, not read from the frames: set \`serialrx_provider = ${provider}\` to match the receiver (a rebind to the other format needs it changed too); if the jumps stay, the firmware misreads frames §8 allows (update it).`;
  }
}

/** A fix's text in pieces: what it names to type (between backticks) apart from its words. */
export function codeSpans(text: string): { code: boolean; text: string }[] {
  return text
    .split('`')
    .map((piece, i) => ({ code: i % 2 === 1, text: piece }))
    .filter((p) => p.text !== '');
}

const esc = (s: string) => s.replace(/[&<>"']/g, (c) => `&#${c.charCodeAt(0)};`);
const fixHtml = (fix: string) =>
  codeSpans(fix)
    .map((p) => (p.code ? `<code>${esc(p.text)}</code>` : esc(p.text)))
    .join('');
const ms = (us: number) => `${(us / 1000).toFixed(1)} ms`;

/** The report as one self-contained HTML page. */
export function driveReportHtml(r: DriveReport): string {
  const t = r.timing;
  const rows = r.checks
    .map((c) => {
      const fix = fixFor(c, r);
      return `<tr class="${c.verdict}"><th>${esc(c.id)}</th><td>${esc(c.expects)}</td><td>${esc(c.found)}</td><td class="v">${c.verdict}</td><td>${fix === null ? '' : fixHtml(fix)}</td></tr>`;
    })
    .join('\n');
  const interval = t.interval === null ? 'none' : `${ms(t.interval.p1)} / ${ms(t.interval.p50)} / ${ms(t.interval.p99)}`;
  return `<!doctype html>
<html lang="en"><head><meta charset="utf-8"><meta name="viewport" content="width=device-width, initial-scale=1">
<title>Drive report: ${esc(r.scenario.name)}</title>
<style>
:root { color-scheme: light dark; font-family: system-ui, sans-serif; }
body { max-width: 1100px; margin: 16px auto; padding: 0 12px; line-height: 1.4; }
table { border-collapse: collapse; width: 100%; }
th, td { text-align: left; vertical-align: top; padding: 4px 8px; border-bottom: 1px solid #8884; }
tr.fail .v { color: #c62a2f; font-weight: 700; } tr.pass .v { color: #0a6e4f; } tr.unknown .v { color: #8a5a00; }
.scroll { overflow-x: auto; }
</style></head><body>
<h1>Drive report: ${esc(r.scenario.name)}</h1>
<p>${esc(r.scenario.title)} ${esc(r.date)}.</p>
<p>Sent: system byte 0x${r.receiver.system.toString(16).toUpperCase().padStart(2, '0')}, ${r.receiver.remote} remote, ${r.receiver.channels} channels.
Written: ${t.frames} frames, intervals 1st / median / 99th percentile ${interval}, shortest silence before a frame ${Number.isFinite(t.minSilenceUs) ? ms(t.minSilenceUs) : 'none'}, ${t.skipped} skipped.</p>
<p>Flight controller: ${r.fc === null ? 'not read' : `${esc(r.fc.variant ?? 'did not say its stack')}, receiver setting ${esc(r.fc.provider ?? 'not said')}`}.</p>
<div class="scroll"><table>
<thead><tr><th>Check</th><th>What it should do</th><th>What it did</th><th>Verdict</th><th>What to change</th></tr></thead>
<tbody>
${rows}
</tbody></table></div>
${r.notes.map((n) => `<p>${esc(n)}</p>`).join('\n')}
</body></html>
`;
}
