/**
 * The failsafe state at a glance (spec §7.1): Live, Hold (frames missing, last values held) or
 * Failsafe (a second without a frame), the time since the last frame, hold and failsafe counts,
 * and a timeline of the episodes over the graphs' window.
 */
import { computed, type Signal } from '@preact/signals';
import { useEffect, useRef } from 'preact/hooks';
import { onFrame } from '../../frame-loop.js';
import type { Live } from '../../live.js';
import { current, linkEnded, linkMismatch, linkState, replay, replayReading, resolutionOverride, status } from '../../store.js';
import { setText } from '../../text.js';
import { drawEpisodes } from '../../timeline.js';
import { TopFinding } from '../Diagnosis/index.js';
import { linkView, sinceLastFrame } from './view.js';
import { plural } from '../../../report/report-text.js';
import './style.css';

// The state, its hint and the panel's colour as signals bound to the DOM: a Live/Hold flip
// changes two texts and a class, and re-renders nothing.
const view = computed(() => {
  const s = status.value;
  const r = replay.value;
  return linkView({
    state: linkState.value,
    kind: s.kind,
    sourceState: s.state,
    remote: s.label,
    reading: replayReading.value,
    positionUs: r === null ? Number.NaN : r.positionUs - r.startUs,
    ended: linkEnded.value,
    mismatch: linkMismatch.value,
    forced: resolutionOverride.value,
  });
});
const sectionClass = computed(() => `link ${view.value.key}`);
const label = computed(() => view.value.label);
const hint = computed(() => view.value.hint);

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
      const s = status.value;
      const text =
        l === null ? 'none yet' : sinceLastFrame(now - l.lastFrameUs, { kind: s.kind, sourceState: s.state, ended: linkEnded.value });
      if (text !== shown && since.current !== null) {
        setText(since.current, text);
        shown = text;
      }
      // The counts change with the batch that changed them, as the counters beside them do.
      const episodes = l === null ? 'none' : `${plural(l.holds, 'hold')} · ${plural(l.failsafes, 'failsafe')}`;
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
          : `${plural(parts.filter((p) => p === 'failsafe').length, 'failsafe')} and ${plural(parts.filter((p) => p === 'hold').length, 'hold')} in this window`,
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
