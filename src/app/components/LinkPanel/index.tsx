/**
 * The failsafe state at a glance (spec §7.1): Live, Hold (frames missing, last values held) or
 * Failsafe (a second without a frame), the time since the last frame, hold and failsafe counts,
 * and a timeline of the episodes over the graphs' window.
 */
import { computed, type Signal } from '@preact/signals';
import { useEffect, useRef } from 'preact/hooks';
import { onFrame } from '../../frame-loop.js';
import type { Live } from '../../live.js';
import { current, linkEnded, linkMismatch, linkState, replayReading, resolutionOverride, status } from '../../store.js';
import { setText } from '../../text.js';
import { drawEpisodes } from '../../timeline.js';
import { TopFinding } from '../Diagnosis/index.js';
import './style.css';

const LABEL = { waiting: 'Waiting', live: 'Live', hold: 'Hold', failsafe: 'Failsafe' } as const;
const HINT = {
  waiting: 'No frame yet. Nothing for long? Check RX on the grey DATA wire and that the satellite is bound.',
  live: 'Frames arriving',
  hold: 'Frames missing: last values held',
  failsafe: 'No frame for 1 s: failsafe',
} as const;

function ago(us: number): string {
  if (!Number.isFinite(us)) return '—';
  if (us < 1e6) return `${Math.round(us / 1000)} ms`;
  return `${(us / 1e6).toFixed(1)} s`;
}

// The state, its hint and the panel's colour as signals bound to the DOM: a Live/Hold flip
// changes two texts and a class, and re-renders nothing.
const sectionClass = computed(() => `link ${linkState.value}`);
// A capture being read has no link yet, and a replayed port no frame yet: that is said, not a
// receiver's "waiting" with its wiring hint.
const label = computed(() => (replayReading.value ? 'Reading' : LABEL[linkState.value]));
// A replay at its end keeps its last state, frozen, and says it ended; a forced resolution
// that matches no frame is not link loss.
const hint = computed(() =>
  replayReading.value
    ? 'Reading the capture: its link state shows once the whole file is read and it plays.'
    : linkEnded.value
      ? 'Replay ended: the state at the end of the capture'
      : linkMismatch.value !== null
        ? `Forced ${resolutionOverride.value}: no frame matches; the stream looks like ${linkMismatch.value}`
        : linkState.value === 'waiting' && status.value.kind === 'replay'
          ? 'No frame yet at this point of the capture.'
          : HINT[linkState.value],
);

export function LinkPanel({ windowUs }: { windowUs: Signal<number> }) {
  const since = useRef<HTMLSpanElement>(null);
  const counts = useRef<HTMLSpanElement>(null);
  const strip = useRef<HTMLDivElement>(null);
  useEffect(() => {
    let shown = '';
    let shownEpisodes = '';
    let stripAt = 0;
    let stripLive: Live | undefined;
    return onFrame((nowMs) => {
      const live = current();
      const l = live.link;
      const now = live.nowUs();
      const text = l === null ? 'none yet' : `${ago(now - l.lastFrameUs)} ago`;
      if (text !== shown && since.current !== null) {
        setText(since.current, text);
        shown = text;
      }
      // The counts change with the batch that changed them, as the counters beside them do.
      const episodes = l === null ? 'none' : `${l.holds} holds · ${l.failsafes} failsafes`;
      if (episodes !== shownEpisodes && counts.current !== null) {
        setText(counts.current, episodes);
        shownEpisodes = episodes;
      }
      // The timeline moves with time: redrawn four times a second (and at once for another
      // remote), not for every batch.
      if (strip.current === null || (live === stripLive && nowMs - stripAt < 250)) return;
      stripLive = live;
      stripAt = nowMs;
      const parts = drawEpisodes(strip.current, live.episodes.values(), now, windowUs.value);
      const el = strip.current;
      el.setAttribute(
        'aria-label',
        parts.length === 0
          ? 'No hold or failsafe in this window'
          : `${parts.filter((p) => p === 'failsafe').length} failsafe and ${parts.filter((p) => p === 'hold').length} hold episodes in this window`,
      );
    });
  }, [windowUs]);

  return (
    <section class={sectionClass} aria-label="Link state">
      <div class="state" role="status" aria-live="polite" data-testid="link-state">
        {label}
      </div>
      <div class="hint" data-testid="link-hint">
        {hint}
      </div>
      <dl>
        <dt>Last frame</dt>
        <dd>
          <span ref={since}>none yet</span>
        </dd>
        <dt>Episodes</dt>
        <dd>
          <span ref={counts}>none</span>
        </dd>
      </dl>
      <TopFinding />
      <div class="timeline" ref={strip} role="img" aria-label="No hold or failsafe in this window" />
    </section>
  );
}
