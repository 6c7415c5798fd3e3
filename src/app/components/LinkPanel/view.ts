/**
 * What the link panel says, from what is true now: a receiver's link state only while frames
 * can arrive. A paused replay says it is paused and at which capture time, with the link state
 * there; an ended one says it ended; a port that is gone says so (no frame can arrive, so the
 * link's state is unknown), never "Live" or "Failsafe" of a link nobody can see.
 */
import { formatClock } from '../../../report/report-text.js';
import type { LinkState } from '../../../decoder/link-types.js';

export type LinkViewKey = LinkState | 'reading' | 'paused' | 'ended' | 'lost';

export interface LinkView {
  /** The panel's class (its colour). */
  key: LinkViewKey;
  /** The big word. */
  label: string;
  /** The sentence under it. */
  hint: string;
}

/** What the panel is showing, as the page knows it. */
export interface LinkFacts {
  state: LinkState;
  /** The selected source's kind and state ('reading', 'lost', 'playing', 'paused', 'ended'…). */
  kind: 'serial' | 'demo' | 'replay';
  sourceState: string;
  /** The remote's label (A, B…). */
  remote: string;
  /** The capture is still being read (replay only). */
  reading: boolean;
  /** The replay position on the capture's clock, from its start, µs (NaN: not a replay). */
  positionUs: number;
  /**
   * The source ended (a replay at its end), as of the batch whose figures the page shows: the
   * worker sends its last batch, then the status 'ended', and the figures are drawn on the next
   * animation frame. "Ended" waits for them (`sourceState` 'ended' alone says nothing here).
   */
  ended: boolean;
  /** A forced resolution matching no frame: the resolution the stream looks like. */
  mismatch: 1024 | 2048 | null;
  forced: 'auto' | 1024 | 2048;
}

const WORD = { waiting: 'Waiting', live: 'Live', hold: 'Hold', failsafe: 'Failsafe' } as const;
const HINT = {
  waiting: 'No frame yet. Nothing for long? Check RX on the grey DATA wire and that the satellite is bound.',
  live: 'Frames arriving.',
  hold: 'Frames missing: last values held.',
  failsafe: 'No frame for 1 s: failsafe.',
} as const;

/** The link state at a moment of a capture, as a clause: "the link was live there". */
const WAS = {
  waiting: 'no frame had come yet',
  live: 'the link was live',
  hold: 'the link was in hold (frames missing)',
  failsafe: 'the link was in failsafe',
} as const;

export function linkView(f: LinkFacts): LinkView {
  if (f.reading)
    return {
      key: 'reading',
      label: 'Reading',
      hint: 'Reading the capture: its link state shows once the whole file is read and it plays.',
    };
  if (f.kind === 'serial' && f.sourceState === 'lost')
    return {
      key: 'lost',
      label: 'Port lost',
      hint: `Remote ${f.remote}'s adapter is gone (unplugged?): no frame can arrive, so its link state is unknown. It reconnects by itself when plugged back in.`,
    };
  if (f.mismatch !== null && !f.ended)
    return {
      key: f.state,
      label: WORD[f.state],
      hint: `Forced ${f.forced}: no frame matches; the stream looks like ${f.mismatch}.`,
    };
  if (f.kind === 'replay') {
    const at = formatClock(f.positionUs);
    if (f.ended) return { key: 'ended', label: 'Ended', hint: `Replay ended at ${at}: there ${WAS[f.state]}.` };
    if (f.sourceState === 'paused')
      return { key: 'paused', label: 'Paused', hint: `Paused at ${at} of the capture: there ${WAS[f.state]}.` };
    if (f.state === 'waiting') return { key: 'waiting', label: WORD.waiting, hint: `No frame yet at ${at} of the capture.` };
    return {
      key: f.state,
      label: WORD[f.state],
      hint: `Replay at ${at}: ${HINT[f.state].charAt(0).toLowerCase()}${HINT[f.state].slice(1)}`,
    };
  }
  return { key: f.state, label: WORD[f.state], hint: HINT[f.state] };
}

/** A duration as the panel shows it: ms under a second, else seconds to a tenth. */
function duration(us: number): string {
  return us < 1e6 ? `${Math.round(us / 1000)} ms` : `${(us / 1e6).toFixed(1)} s`;
}

/**
 * The time since the last frame (`sinceUs`, NaN: none), as the panel says it: "ago" while time
 * runs (live, or a replay playing on its own clock); a paused replay's before the point it
 * stopped at, an ended one's before its end (its clock stands still there, and "1 ms ago"
 * would read as now). A frame the page's clock has not caught up with came just now, never
 * "−4 ms ago" (the page's clock runs on from the worker's last word, a little behind it).
 */
export function sinceLastFrame(sinceUs: number, f: Pick<LinkFacts, 'kind' | 'sourceState' | 'ended'>): string {
  if (!Number.isFinite(sinceUs)) return '—';
  const d = duration(Math.max(0, sinceUs));
  if (f.kind === 'replay' && f.ended) return `${d} before the end`;
  if (f.kind === 'replay' && f.sourceState === 'paused') return `${d} before this point`;
  return `${d} ago`;
}
