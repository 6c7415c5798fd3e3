/**
 * The doctor's rules about one satellite: the flight controller's settings, the mode it was
 * bound in, what its frames carry, and how weak its link is (failsafes, holds, fades, RSSI,
 * rebinds, restarts).
 */
import { systemInfo, type Resolution } from '../decoder/spec.js';
import type { FormatInfo } from '../decoder/types.js';
import type { LinkStats } from '../decoder/link-types.js';
import { becameFailsafe } from '../decoder/episode.js';
import { fadesPerMinute, REPORT_THRESHOLDS } from './report-thresholds.js';
import { formatDuration, plural, rate as rateText } from './report-text.js';
import { ARDUPILOT_GUESS_FRAMES, bindPulses, channelSetText, satelliteSettings } from './doctor-stacks.js';
import { GUESS_MIN_DECISIONS, M_FADES, MIN_FADES, type FormatSnapshot, type PortState } from './doctor-state.js';
import type { AddFinding, Confidence, DoctorPortSource, Evidence, RuleContext } from './doctor-types.js';

/** Advice from spec §5 for a weak link. */
export const LINK_ADVICE = [
  'Give the weak remote line of sight to the transmitter in every attitude; move it away from carbon fibre, metal, batteries and wiring (spec §5).',
  "Add a second remote mounted 90° from the first: each covers the other's blind orientation (spec §5).",
  'Check the antennas: undamaged, not touching carbon or metal, the two elements of a satellite at right angles.',
  'Do a range check with the transmitter in range-test mode before flying again.',
];

export function satelliteFindings(p: PortState, now: number, ctx: RuleContext, addFinding: AddFinding): void {
  const source = p.source as DoctorPortSource;
  const format: FormatInfo = source.decoder.format;
  const link = source.link;
  if (!format.locked || format.resolution === null || format.remote === null) return;
  // Where frames start is not proven: what they carry (channels, fades) may be misread, so no
  // finding about this remote is certain until a stick moves.
  const unaligned = format.alignmentUnproven;
  const add: AddFinding = unaligned ? (f) => addFinding(f.confidence === 'certain' ? { ...f, confidence: 'likely' } : f) : addFinding;
  if (unaligned) {
    addFinding({
      code: 'alignment-unproven',
      ports: [p.port],
      severity: 'info',
      confidence: 'certain',
      title: `${p.label}: where its frames start is not yet proven`,
      evidence: [{ text: format.explanation, timeUs: null }],
      todo: [
        'Move each stick and switch through its range, one at a time: a stick read as the fade count falls as no count does, and the decoder then reads the frames from where they start (its findings become certain).',
        'Until then the channel values and the fade count shown may be each other (an external remote at 22 ms with up to 7 channels, opened mid-stream, and a fade count of 256 or more: spec §8.4, §8.5).',
      ],
      settings: [],
      confirm: null,
    });
  }
  const resolution = format.resolution;
  const remote = format.remote;
  const period = link.stats.nominalPeriodUs;
  const info = format.system !== null ? systemInfo(format.system) : undefined;
  // A header that reads both ways (internal, or an external count whose low byte is a system
  // byte) leaves the remote's kind and bind mode unproven: never 'certain' until its bytes tell.
  const sure: Confidence = format.remoteAmbiguous ? 'likely' : format.resolutionReason === 'channel-ids' ? 'likely' : 'certain';
  const protocolText = format.remoteAmbiguous
    ? `${resolution}, ${Number.isFinite(period) ? `${period / 1000} ms` : 'period not yet measured'}`
    : info !== undefined
      ? info.name
      : `${resolution}, ${Number.isFinite(period) ? `${period / 1000} ms` : 'period not yet measured'}`;
  const remoteText = format.remoteAmbiguous ? 'internal or external' : remote;

  // What to set.
  const guessNote = guessNotes(p, resolution);
  add({
    code: 'fc-settings',
    ports: [p.port],
    severity: 'info',
    confidence: sure,
    title: `${p.label}: flight controller settings for this ${protocolText} ${remoteText} remote`,
    evidence: [{ text: format.explanation, timeUs: null }],
    todo: [`Betaflight / iNav: serialrx_provider = ${resolution === 2048 ? 'SPEK2048' : 'SPEK1024'} (lines below).`],
    settings: [
      ...satelliteSettings({ resolution, periodUs: period, remote, system: format.system }),
      { stack: 'ArduPilot', lines: [], note: guessNote.ardupilot },
      { stack: 'PX4', lines: [], note: guessNote.px4 },
    ],
    confirm: null,
  });

  // The mode it was bound in, against §7.2's recommendation.
  const slow = Number.isFinite(period) && period > 16_500;
  if (resolution === 1024 || slow || (info !== undefined && info.protocol === 'DSM2')) {
    const pulses = bindPulses('DSMX', 11, remote);
    add({
      code: 'bind-mode',
      ports: [p.port],
      severity: resolution === 1024 ? 'warning' : 'info',
      confidence: sure,
      title: `${p.label}: bound in ${protocolText}; DSMX 11 ms is better`,
      evidence: [
        {
          text: `${resolution === 1024 ? 'Servo positions have 1024 steps (DSM2 22 ms, spec §8.1), half the precision of 2048. ' : ''}${slow ? `A frame every ${(link.stats.periodUs / 1000 || period / 1000).toFixed(1)} ms, twice the latency of 11 ms. ` : ''}Spec §7.2 recommends binding DSMX 11 ms: 9 pulses internal, 10 external.`,
          timeUs: null,
        },
      ],
      todo: [
        `Bind again in DSMX 11 ms, ${remote}: ${pulses} pulses (Betaflight/iNav \`set spektrum_sat_bind = ${pulses}\`, save, power-cycle, bind, set it back to 0; or SatScope's Bind panel).`,
        'A DSM2-only satellite (SPM9545) cannot bind DSMX; a DSM2-only transmitter falls back to DSM2 by itself when bound in a DSMX mode (spec §7.2).',
        resolution === 1024
          ? 'Until then the flight controller must use SPEK1024, or every channel reads wrong.'
          : 'Until then SPEK2048 reads it correctly.',
      ],
      settings: [],
      confirm: null,
    });
  }

  if (format.resolutionReason === 'system-byte-contradicted') {
    add({
      code: 'system-byte-contradicted',
      ports: [p.port],
      severity: 'warning',
      confidence: 'certain',
      title: `${p.label}: the system byte names one resolution, the data is in the other`,
      evidence: [{ text: format.explanation, timeUs: null }],
      todo: [
        `Set Betaflight/iNav to ${resolution === 2048 ? 'SPEK2048' : 'SPEK1024'}, what the data is, not what the system byte says.`,
        'ArduPilot and PX4 ignore the system byte and guess the resolution from the channel IDs, so they are not misled by it; stacks or tools that trust byte 1 are.',
        'This is a clone or a misbehaving receiver: a genuine Spektrum remote sends a system byte that matches its data (spec §8.3).',
      ],
      settings: [],
      confirm: null,
    });
  }

  if (p.xplusMask !== 0) {
    const names = [];
    for (let i = 0; i < 8; i++) if ((p.xplusMask >> i) & 1) names.push(`X+${i + 1}`);
    add({
      code: 'xplus-channels',
      ports: [p.port],
      severity: 'warning',
      confidence: 'certain',
      title: `${p.label}: X-Plus channels ${names.join(', ')} are sent; flight controllers drop or mix them`,
      evidence: [
        { text: `X-Plus channels (ID 12 with a sub-ID, spec §8.6) seen${ctx.when('since', p.xplusFirstUs)}.`, timeUs: p.xplusFirstUs },
      ],
      todo: [
        'Betaflight and iNav read channel IDs 0–11 only (SPEKTRUM_MAX_SUPPORTED_CHANNEL_COUNT 12): X-Plus channels are dropped.',
        'ArduPilot (AP_RCProtocol_DSM.cpp) takes every X-Plus word as channel 13, whatever its sub-ID, and reports 13 channels as 12. PX4 reads them as channels 13 and up (its tests expect 16 channels from a DX9 with X+1…X+4).',
        'Put functions the flight controller needs on channels 1–12, and turn X-Plus off in the transmitter if nothing uses it.',
      ],
      settings: [],
      confirm: null,
    });
  }

  if (p.vtxFrames > 0) {
    add({
      code: 'vtx-frames',
      ports: [p.port],
      severity: 'info',
      confidence: 'certain',
      title: `${p.label}: the transmitter sends VTX control in the channel slots`,
      evidence: [
        {
          text: `${plural(p.vtxFrames, 'frame')} carried Spektrum VTX control in bytes 12–15 (0xE… 0xE…)${ctx.when(', first at', p.vtxFirstUs)}.`,
          timeUs: p.vtxFirstUs,
        },
      ],
      todo: [
        "Betaflight (spektrum.c, with USE_SPEKTRUM_VTX_CONTROL) and ArduPilot (AP_RCProtocol_DSM.cpp) take these frames' last two slots out of the channel data and set the VTX from them; a stack or build without Spektrum VTX support reads the two words as channel data.",
        'Turn VTX control off in the transmitter if the flight controller does not use it.',
      ],
      settings: [],
      confirm: null,
    });
  }

  const g = p.guess.outcomes;
  const tries = g[10] + g[11] + g.none;
  const want = resolution === 2048 ? 11 : 10;
  if (tries >= GUESS_MIN_DECISIONS && g[want] < tries / 2) {
    add({
      code: 'autopilot-detection',
      ports: [p.port],
      severity: 'warning',
      confidence: 'likely',
      title: `${p.label}: ArduPilot may not read this stream by itself`,
      evidence: [
        {
          text: `Channel IDs in ${ARDUPILOT_GUESS_FRAMES} frames read as 11-bit: ${channelSetText(p.guess.last11)}; as 10-bit: ${channelSetText(p.guess.last10)}.`,
          timeUs: null,
        },
        { text: guessNote.ardupilot, timeUs: null },
      ],
      todo: [
        'ArduPilot guesses 10- or 11-bit from the channel numbers, not from the system byte, and needs exactly one reading to give channels 0…n−1 (5 to 16 of them). Change the number of channels the transmitter sends, or bind in DSMX 11 ms (2048), which it tells apart easily.',
        "Check the result on ArduPilot's radio calibration page: every stick must move one bar.",
      ],
      settings: [],
      confirm: null,
    });
  }

  // The link, in the link monitor's own figures: the holds and failsafes every surface counts
  // (each failsafe began as a hold), and the fade rate the report states for a whole capture.
  const s = link.stats;
  const memoryStart = now - ctx.memoryUs;
  const episodes = link.episodes.filter((e) => (e.endUs ?? now) >= memoryStart);
  const failsafes = episodes.filter((e) => e.kind === 'failsafe');
  const holds = episodes.filter((e) => e.kind === 'hold');
  // Holds that line damage explains (the frame that ended them came after discarded bytes) are
  // the line's, not the link's: counted, but no reason to call the link weak.
  const byLine = (e: { lastFrameUs: number; endUs: number | null }) =>
    e.endUs !== null && p.damagedAtUs.some((d) => d > e.lastFrameUs && d <= e.endUs! + 50_000);
  // Silences a receiver restart ended are the restart's (its own finding), not the radio link's.
  const restarts = link.restarts.filter((r) => r.timeUs >= memoryStart);
  const byRestart = (e: { lastFrameUs: number }) => restarts.some((r) => r.timeUs - r.gapUs === e.lastFrameUs);
  const linkFailsafes = failsafes.filter((e) => !byRestart(e));
  const linkHolds = holds.filter((e) => !becameFailsafe(e.lastFrameUs, failsafes) && !byLine(e) && !byRestart(e));
  const rate = fadeRateOf(p, s, now, ctx);
  const fadeHigh = format.headerMode === 'fades' && rate !== null && rate.perMinute > REPORT_THRESHOLDS.fadeRateHighPerMin && rate.enough;
  const rssiLow = Number.isFinite(s.minRssi) && s.minRssi < REPORT_THRESHOLDS.rssiLowDbm;
  if (linkFailsafes.length > 0 || linkHolds.length > 0 || fadeHigh || rssiLow) {
    const evidence: Evidence[] = [];
    for (const e of failsafes.slice(-5))
      evidence.push({
        text: `Failsafe: no frame for over 1 s after ${ctx.at(e.lastFrameUs)}${e.endUs === null ? ', still now' : `, back at ${ctx.at(e.endUs)}`} (spec §7.1).`,
        timeUs: e.startUs,
      });
    if (holds.length > 0) {
      const last = holds[holds.length - 1] as (typeof holds)[number];
      const became = holds.filter((e) => becameFailsafe(e.lastFrameUs, failsafes)).length;
      const restarted = holds.filter((e) => byRestart(e) && !becameFailsafe(e.lastFrameUs, failsafes)).length;
      const line = holds.length - became - restarted - linkHolds.length;
      const parts = [
        became > 0 ? `${became} of them became ${became === 1 ? 'a failsafe' : 'failsafes'}` : '',
        restarted > 0 ? `${restarted} ended in a receiver restart` : '',
        line > 0 ? `${line} ended at line damage` : '',
      ].filter((x) => x !== '');
      evidence.push({
        text: `${plural(holds.length, 'hold')} (frames stopped, last values held${parts.length > 0 ? `; ${parts.join(', ')}` : ''}), the last at ${ctx.at(last.startUs)}.`,
        timeUs: last.startUs,
      });
    }
    if (fadeHigh && rate !== null)
      evidence.push({
        text: `Fade rate ${rateText(rate.perMinute)} a minute ${rate.over} (over ${REPORT_THRESHOLDS.fadeRateHighPerMin} a minute is high).`,
        timeUs: null,
      });
    if (rssiLow)
      evidence.push({
        text: `RSSI down to ${s.minRssi} dBm (below ${REPORT_THRESHOLDS.rssiLowDbm} dBm leaves little margin).`,
        timeUs: null,
      });
    add({
      code: 'weak-link',
      ports: [p.port],
      severity: linkFailsafes.length > 0 ? 'problem' : 'warning',
      confidence: linkFailsafes.length > 0 || fadeHigh || rssiLow || ctx.precise ? 'certain' : 'likely',
      title: `${p.label}: the link is weak${linkFailsafes.length > 0 ? ': failsafe' : linkHolds.length > 0 ? ': frames lost' : ''}`,
      evidence,
      todo: LINK_ADVICE,
      settings: [],
      confirm: null,
    });
  }

  // Setup, per remote.
  const changes = p.changes.filter((c) => c.timeUs >= memoryStart);
  if (changes.length > 0) {
    const c = changes[changes.length - 1] as (typeof changes)[number];
    const name = (f: FormatSnapshot): string =>
      `${f.system !== null ? (systemInfo(f.system)?.name ?? `system 0x${f.system.toString(16)}`) : `${f.resolution}`} ${f.remote}`;
    add({
      code: 'rebind',
      ports: [p.port],
      severity: 'warning',
      confidence: 'certain',
      title: `${p.label}: the receiver changed mode mid-session (a rebind?)`,
      evidence: [{ text: `From ${name(c.from)} to ${name(c.to)}${ctx.when('at', c.timeUs)}.`, timeUs: c.timeUs }],
      todo: [
        'A satellite changes mode only when it is bound again: check that the flight controller does not send bind pulses at every power-up (Betaflight/iNav: spektrum_sat_bind back to 0, or spektrum_sat_bind_autoreset on).',
        `Set the flight controller for the new mode: ${c.to.resolution === 2048 ? 'SPEK2048' : 'SPEK1024'}.`,
      ],
      settings: [],
      confirm: null,
      sinceUs: c.timeUs,
    });
  }
  if (restarts.length > 0) {
    const r = restarts[restarts.length - 1] as (typeof restarts)[number];
    const failsafe = restarts.some((x) => becameFailsafe(x.timeUs - x.gapUs, failsafes));
    add({
      code: 'receiver-restart',
      ports: [p.port],
      severity: failsafe ? 'problem' : 'warning',
      confidence: 'likely',
      title: `${p.label}: the receiver restarted (power dip?)${failsafe ? ': failsafe' : ''}`,
      evidence: [
        {
          text: `${plural(restarts.length, 'restart')}: the fade counter went from ${r.from} back to ${r.to} after ${formatDuration(r.gapUs)} without frames, at ${ctx.at(r.timeUs)}; a counter only starts again from 0 at power-up.`,
          timeUs: r.timeUs,
        },
        {
          text: `The flight controller held the last values through ${restarts.length === 1 ? 'that silence' : 'each silence'} (a hold${failsafe ? ', then failsafe' : ''}); the frames due in it are counted missed.`,
          timeUs: null,
        },
      ],
      todo: [
        'Check the 3.3 V supply (orange) under load: a brown-out restarts the satellite; power it from a regulator that does not sag when motors or servos draw current.',
        'Check the connector and wires for an intermittent contact.',
      ],
      settings: [],
      confirm: null,
      sinceUs: r.timeUs,
    });
  }
  if (s.stalls > 0 && ctx.timed) {
    const silences = `${plural(s.stalls, 'silence')}, the longest ${formatDuration(s.longestStallUs)}`;
    const sent = s.missedBasis === 'fade-counter' ? "the receiver's fade counter did not move" : 'the frames came afterwards, all at once';
    // A logic analyser's times are the line's own: no adapter held anything back there.
    add({
      code: 'delivery-stall',
      ports: [p.port],
      severity: 'info',
      confidence: 'likely',
      title: ctx.precise
        ? `${p.label}: gaps in the frames read that the link did not lose`
        : `${p.label}: frames reached the computer late (the link lost none of them)`,
      evidence: [
        {
          text: ctx.precise
            ? `${silences}, between frames read, ${s.stalls === 1 ? 'is' : 'are'} no loss of the link: ${sent}. On a logic analyser's capture no adapter holds bytes back: frames were lost to damage beside the gap, or the capture was cut there. Not counted as holds or failsafes.`
            : `${silences}, ${s.stalls === 1 ? 'was' : 'were'} the USB adapter or the computer holding frames back: ${sent}. Not counted as holds or failsafes: the flight controller, on the receiver's own line, had them in time.`,
          timeUs: null,
        },
      ],
      todo: [
        ctx.precise
          ? "Look at the gaps in Inspect frames: damaged bytes there are the line's (noise, a loose connection); a gap with no bytes at all is a cut in the capture."
          : 'For a recording that shows only the link: a USB port without a hub, no other program reading the port, the computer kept from sleeping or throttling USB; an FTDI adapter with a lower latency timer.',
      ],
      settings: [],
      confirm: null,
    });
  }
  if (format.headerMode === 'rssi') {
    add({
      code: 'rssi-receiver',
      ports: [p.port],
      severity: 'info',
      confidence: 'certain',
      title: `${p.label}: byte 0 carries RSSI (SPM4649T), not a fade count`,
      evidence: [
        {
          text: `Byte 0 is a signed dBm value (spec §8.3.1)${Number.isFinite(s.rssi) ? `: now ${s.rssi} dBm, lowest ${s.minRssi} dBm` : ''}; −128 marks a lost frame.`,
          timeUs: null,
        },
      ],
      todo: [
        'Judge this remote by RSSI and lost frames, not by fades: it counts none.',
        'PX4 reads a negative byte 0 as RSSI (dsm.cpp); stacks that read byte 0 as fades, or ignore it, show no RSSI for it.',
      ],
      settings: [],
      confirm: null,
    });
  }
}

/** What ArduPilot's guess makes of this remote's frames, and what is known of PX4, as sentences. */
function guessNotes(p: PortState, resolution: Resolution): { ardupilot: string; px4: string } {
  const d = p.guess.outcomes;
  const want = resolution === 2048 ? 11 : 10;
  const other = want === 11 ? 10 : 11;
  const n = d[10] + d[11] + d.none;
  const where = 'AP_RCProtocol_DSM.cpp, replayed';
  let ardupilot =
    n === 0
      ? `Detects the DSM protocol by itself (${where}: not enough frames yet).`
      : d[want] === n
        ? `Detects it by itself: its 10/11-bit guess settles on ${want}-bit (${resolution}) (${where}).`
        : d.none === n
          ? `Its 10/11-bit guess never settles (${n} tries), so it would output no channels (${where}).`
          : `Its 10/11-bit guess settled on ${want}-bit in ${d[want]} of ${n} tries${d[other] > 0 ? `, on the wrong ${other}-bit reading in ${d[other]}` : ''} (${where}).`;
  if (p.xplusMask !== 0)
    ardupilot +=
      ' It takes every X-Plus word as channel 13 whatever its sub-ID, and reports 13 channels as 12: X-Plus channels are not usable.';
  const px4 = `rc_input detects DSM by itself and guesses the resolution from the channel IDs (src/lib/rc/dsm.cpp)${p.xplusMask !== 0 ? '; its tests expect X-Plus channels as channels 13 and up (rc_tests/RCTest.cpp, 16 channels from a DX9)' : ''}.`;
  return { ardupilot, px4 };
}

/**
 * The fade rate to judge, a minute, and over what: a whole capture's (the report's figure,
 * `fadesPerMinute`), or live the link monitor's over its last frames; none without timing.
 * `enough`: fades enough behind it (one corrupted header is not a weak link).
 */
function fadeRateOf(
  p: PortState,
  s: Readonly<LinkStats>,
  now: number,
  ctx: RuleContext,
): { perMinute: number; over: string; enough: boolean } | null {
  if (!ctx.timed) return null;
  if (ctx.memoryUs === Infinity) {
    const perMinute = fadesPerMinute(s.fades, p.firstFrameUs, p.prevFrameUs);
    return perMinute === null ? null : { perMinute, over: 'over the capture', enough: s.fades >= MIN_FADES };
  }
  const recent = p.bins.sum(M_FADES, Math.floor(now / 1e6) - 9, Math.floor(now / 1e6));
  return { perMinute: s.fadeRate * 60, over: 'over the last ~500 frames', enough: recent >= MIN_FADES };
}
