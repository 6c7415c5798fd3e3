/**
 * Each channel's lowest, highest and last pulse width and its frames, as `satscope info` prints
 * them (the library's `ChannelRanges`, counted by the worker's decode): folded away under the
 * bars, and written only while open, four times a second at most.
 */
import { useEffect, useRef, useState } from 'preact/hooks';
import { formatClock } from '../../../report/report-text.js';
import { channelName } from '../../../decoder/spec.js';
import { onFrame } from '../../frame-loop.js';
import type { Live } from '../../live.js';
import { current, replay } from '../../store.js';
import { setText } from '../../text.js';

const EVERY_MS = 250;

/** What the ranges cover: the whole stream so far, or from where a seek's decode started. */
function coverage(live: Live): string {
  const since = live.channels?.sinceUs ?? Number.NaN;
  if (Number.isNaN(since)) return 'Every frame so far.';
  const start = replay.peek()?.startUs ?? 0;
  return `Frames from ${formatClock(since - start)} of the capture on (where the seek's decode started).`;
}

export function ChannelRanges({ ids }: { ids: number[] }) {
  const [open, setOpen] = useState(false);
  const body = useRef<HTMLTableSectionElement>(null);
  const note = useRef<HTMLParagraphElement>(null);
  useEffect(() => {
    if (!open) return undefined;
    let at = Number.NEGATIVE_INFINITY;
    let shown: Live | undefined;
    let version = -1;
    return onFrame((nowMs) => {
      const live = current();
      if (live === shown && (live.version === version || nowMs - at < EVERY_MS)) return;
      shown = live;
      version = live.version;
      at = nowMs;
      const rows = body.current?.rows;
      if (rows === undefined || note.current === null) return;
      setText(note.current, coverage(live));
      const c = live.channels;
      ids.forEach((id, i) => {
        const cells = rows[i]?.cells;
        if (cells === undefined) return;
        const n = c?.frames[id] ?? 0;
        const v = (a: Float64Array | undefined) => (n === 0 || a === undefined ? '—' : `${a[id]} µs`);
        setText(cells[1] as Node, String(n));
        setText(cells[2] as Node, v(c?.minUs));
        setText(cells[3] as Node, v(c?.maxUs));
        setText(cells[4] as Node, v(c?.lastUs));
      });
    });
  }, [open, ids]);
  return (
    <details class="ranges" onToggle={(e) => setOpen((e.currentTarget as HTMLDetailsElement).open)}>
      <summary>Min / max / last per channel</summary>
      <p class="muted" ref={note} />
      <table data-testid="channel-ranges">
        <thead>
          <tr>
            <th scope="col">Channel</th>
            <th scope="col">Frames</th>
            <th scope="col">Min</th>
            <th scope="col">Max</th>
            <th scope="col">Last</th>
          </tr>
        </thead>
        <tbody ref={body}>
          {ids.map((id) => (
            <tr key={id} data-id={id}>
              <th scope="row">{channelName(id)}</th>
              <td>0</td>
              <td>—</td>
              <td>—</td>
              <td>—</td>
            </tr>
          ))}
        </tbody>
      </table>
    </details>
  );
}
