/**
 * The doctor's rules about several remotes together: exactly one internal remote (§7.3), one
 * resolution and period, the weakest remote, remotes that fade together.
 */
import { plural } from './report-text.js';
import { BIN_COUNT, M_LOST, M_MISSED, TOGETHER_MIN_SECONDS, TOGETHER_RATIO, type PortState } from './doctor-state.js';
import type { AddFinding, DoctorPortSource, RuleContext } from './doctor-types.js';

/** Findings about several remotes together. */
export function systemFindings(ports: PortState[], now: number, ctx: RuleContext, add: AddFinding): void {
  if (ports.length < 2) return;
  const locked = ports.filter((p) => (p.source as DoctorPortSource).decoder.format.locked);
  const labels = (ps: PortState[]): string => ps.map((p) => p.label).join(', ');
  const all = locked.map((p) => p.port);
  // §7.3: exactly one internal ("A") remote.
  const internal = locked.filter((p) => (p.source as DoctorPortSource).decoder.format.remote === 'internal');
  // Remotes read internal on a header that reads both ways may be external: a count that rests
  // on them is a possibility, said as one, until their bytes settle it.
  const unsure = internal.filter((p) => (p.source as DoctorPortSource).decoder.format.remoteAmbiguous);
  if (locked.length >= 2 && internal.length !== 1) {
    add({
      code: 'internal-count',
      ports: all,
      severity: unsure.length > 0 ? 'warning' : 'problem',
      confidence: unsure.length > 0 ? 'possible' : 'certain',
      title:
        internal.length === 0
          ? 'No internal ("A") remote among these remotes'
          : `${internal.length} internal ("A") remotes: exactly one is allowed`,
      evidence: [
        {
          text:
            internal.length === 0
              ? `${labels(locked)} all send external frames (a 16-bit fade count, no system byte).`
              : `${labels(internal)} each send a system byte in byte 1 (internal frames).`,
          timeUs: null,
        },
        ...(unsure.length > 0
          ? [
              {
                text: `${labels(unsure)}: byte 1 has not moved and byte 0 has not either, so ${unsure.length === 1 ? 'it' : 'each'} may be an external remote whose fade count's low byte is a system byte; the first fade tells.`,
                timeUs: null,
              },
            ]
          : []),
      ],
      todo: [
        'Spec §7.3: exactly one remote binds internal ("A"); it negotiates with the transmitter for all. With none, binding fails; with several, "the results cannot be predicted".',
        'Bind all remotes again at the same time: one internal (DSMX 11 ms: 9 pulses), every other one external (10 pulses).',
      ],
      settings: [],
      confirm: null,
    });
  }
  // §8: all remotes 1024 or all 2048.
  const resolutions = new Set(locked.map((p) => (p.source as DoctorPortSource).decoder.format.resolution));
  const periods = new Set(locked.map((p) => (p.source as DoctorPortSource).link.stats.nominalPeriodUs).filter((x) => Number.isFinite(x)));
  if (resolutions.size > 1 || periods.size > 1) {
    add({
      code: 'resolution-mismatch',
      ports: all,
      severity: 'warning',
      confidence: 'likely',
      title: 'The remotes disagree on the format',
      evidence: locked.map((p) => {
        const s = p.source as DoctorPortSource;
        return {
          text: `${p.label}: ${s.decoder.format.resolution ?? '?'} resolution, ${Number.isFinite(s.link.stats.nominalPeriodUs) ? `${s.link.stats.nominalPeriodUs / 1000} ms` : '? ms'} frames (${s.decoder.format.remote ?? '?'}).`,
          timeUs: null,
        };
      }),
      todo: [
        'Spec §8: all remotes of one system are in 1024 mode or all in 2048, and the internal remote sets it. Remotes that differ were bound at different times or to different transmitters.',
        'Bind them again together: one internal, the others external, in DSMX 11 ms.',
      ],
      settings: [],
      confirm: null,
    });
  }
  // Who loses most frames, and do they lose them together (per second over the memory window).
  // Frames missed as the link monitor counts them (the receiver's count where it keeps one);
  // an SPM4649T counts no fades (byte 0 is RSSI): when one is among fade-counting remotes, they
  // are all compared by the frames that did not arrive, the one measure they share.
  const toS = Math.floor(now / 1e6);
  const fromS = toS - Math.min(BIN_COUNT - 1, Math.ceil(ctx.memoryUs / 1e6));
  // Remotes whose missed frames rest on different evidence (a counter, the frames that arrived)
  // are compared by the frames that did not arrive too.
  const modes = new Set(locked.map((p) => (p.source as DoctorPortSource).decoder.format.headerMode));
  const bases = new Set(locked.map((p) => (p.source as DoctorPortSource).link.stats.missedBasis));
  const mixed = modes.size > 1 || bases.size > 1;
  const metric = mixed ? M_LOST : M_MISSED;
  const lossOf = (p: PortState, s: number): number => p.bins.at(metric, s);
  // A whole capture: the monitor's own totals (what `info` and the report state); live: the window.
  const whole = ctx.memoryUs === Infinity;
  const totals = locked
    .map((p) => {
      const stats = (p.source as DoctorPortSource).link.stats;
      return { p, loss: whole ? (mixed ? stats.lostFrames : stats.missedFrames) : p.bins.sum(metric, fromS, toS) };
    })
    .sort((a, b) => b.loss - a.loss);
  // The window as far as it goes back: never before the first byte.
  const first = Math.min(...locked.map((p) => p.firstActivityUs));
  const seconds = Math.min(toS - fromS + 1, Math.ceil((now - first) / 1e6));
  const over = whole ? (ctx.timed ? 'in the capture' : 'in the file') : `in the last ${seconds} s`;
  const top = totals[0];
  const second = totals[1];
  if (top !== undefined && second !== undefined && top.loss >= 10 && top.loss >= 2 * Math.max(1, second.loss)) {
    add({
      code: 'weakest-remote',
      ports: [top.p.port],
      severity: 'warning',
      confidence: 'certain',
      title: `${top.p.label} fades most`,
      evidence: [
        ...totals.map((t) => ({
          text: `${t.p.label}: ${mixed ? plural(t.loss, 'frame that did not arrive', 'frames that did not arrive') : plural(t.loss, 'missed frame')} ${over}.`,
          timeUs: null,
        })),
        ...(mixed
          ? [
              {
                text: 'Compared by the frames that did not arrive: one remote sends RSSI in byte 0 (SPM4649T) and counts no fades.',
                timeUs: null,
              },
            ]
          : []),
      ],
      todo: [
        `Move or turn ${top.p.label}: 90° from the other remote, away from carbon and metal, with line of sight to the transmitter (spec §5).`,
      ],
      settings: [],
      confirm: null,
    });
  }
  let any = 0;
  let together = 0;
  let firstTogether = NaN;
  for (let s = fromS; s <= toS; s++) {
    let n = 0;
    for (const p of locked) if (lossOf(p, s) > 0) n++;
    if (n >= 1) any++;
    if (n >= 2) {
      together++;
      if (Number.isNaN(firstTogether)) firstTogether = s * 1e6;
    }
  }
  if (locked.length >= 2 && together >= TOGETHER_MIN_SECONDS && together >= TOGETHER_RATIO * any) {
    add({
      code: 'fades-together',
      ports: all,
      severity: 'warning',
      confidence: 'likely',
      title: 'The remotes fade together',
      evidence: [
        {
          text: `In ${together} of the ${any} seconds with fades or lost frames, two remotes or more lost frames in the same second (first at ${ctx.at(firstTogether)}).`,
          timeUs: firstTogether,
        },
      ],
      todo: [
        "A cause common to all remotes, not one remote's placement: the transmitter (range, antenna orientation, battery), or something on board that blankets every receiver (a VTX antenna next to them, ESC or motor noise).",
        'A power dip also stops every remote at once: check the 3.3 V supply they share.',
        'Range check with the transmitter in range-test mode; move the VTX antenna away from the satellites.',
      ],
      settings: [],
      confirm: null,
    });
  }
}
