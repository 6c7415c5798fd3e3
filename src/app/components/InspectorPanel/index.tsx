/**
 * The frame inspector's data flow: closed by default; open, it asks the worker for the selected
 * remote's newest 1000 entries four times a second while following, and only on Refresh while
 * paused, so the list holds still to be scrolled.
 */
import { signal } from '@preact/signals';
import { useEffect } from 'preact/hooks';
import { inspection, selected, send } from '../../store.js';
import { Inspector } from '../Inspector/index.js';

const LIMIT = 1000;
const FOLLOW_MS = 250;
const open = signal(false);
const following = signal(true);

function refresh(): void {
  send({ type: 'inspect', source: selected.value, limit: LIMIT });
}

export function InspectorPanel() {
  const id = selected.value;
  useEffect(() => {
    if (!open.value) return undefined;
    // Paused: one snapshot of the remote now shown; following: one four times a second.
    refresh();
    if (!following.value) return undefined;
    const timer = setInterval(refresh, FOLLOW_MS);
    return () => clearInterval(timer);
  }, [open.value, following.value, id]);

  if (!open.value) {
    return (
      <div class="inspector-closed">
        <h2>Frame inspector</h2>
        <button
          type="button"
          onClick={() => {
            inspection.value = null;
            open.value = true;
          }}
        >
          Inspect frames…
        </button>
        <span class="muted">each frame in hex with its fields, discarded bytes and resyncs where they happened</span>
      </div>
    );
  }
  return (
    <div>
      <Inspector
        key={id}
        entries={inspection.value}
        following={following.value}
        onFollow={(on) => {
          following.value = on;
        }}
        onRefresh={refresh}
      />
      <button
        type="button"
        class="link"
        onClick={() => {
          open.value = false;
        }}
      >
        Close the inspector
      </button>
    </div>
  );
}
