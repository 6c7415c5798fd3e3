/** What went wrong (or right), with what to do: each notice stays until dismissed. */
import { dismiss, notices } from '../../store.js';
import './style.css';

export function Notices() {
  const list = notices.value;
  if (list.length === 0) return null;
  return (
    <section class="notices" aria-label="Messages">
      {list.map((n) => (
        <div key={n.id} class={`notice ${n.level}`} role={n.level === 'error' ? 'alert' : 'status'}>
          <strong>{n.title}</strong>
          <span>{n.detail}</span>
          <button type="button" class="link" aria-label="Dismiss" onClick={() => dismiss(n.id)}>
            ✕
          </button>
        </div>
      ))}
    </section>
  );
}
