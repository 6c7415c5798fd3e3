/**
 * A row of buttons that picks one of a few values (the graph window, the replay speed): an ARIA
 * radio group, keyed as one. Tab reaches the chosen button only; the arrow keys, Home and End
 * move the choice and the focus along the row (wrapping), as a group of native radios does.
 */
import { useRef } from 'preact/hooks';
import './style.css';

export interface ChoiceProps<T> {
  /** What the group chooses, for a screen reader ("Window", "Speed"). */
  label: string;
  options: readonly (readonly [T, string])[];
  value: T;
  onChoose: (value: T) => void;
}

/** The index `key` moves the choice to from `at` among `n`, or null when the key is not one. */
export function movedTo(key: string, at: number, n: number): number | null {
  switch (key) {
    case 'ArrowRight':
    case 'ArrowDown':
      return (at + 1) % n;
    case 'ArrowLeft':
    case 'ArrowUp':
      return (at - 1 + n) % n;
    case 'Home':
      return 0;
    case 'End':
      return n - 1;
    default:
      return null;
  }
}

export function Choice<T>({ label, options, value, onChoose }: ChoiceProps<T>) {
  const row = useRef<HTMLDivElement>(null);
  const chosen = Math.max(
    0,
    options.findIndex(([v]) => v === value),
  );
  const onKeyDown = (e: KeyboardEvent): void => {
    const to = movedTo(e.key, chosen, options.length);
    const option = to === null ? undefined : options[to];
    if (to === null || option === undefined) return;
    e.preventDefault();
    onChoose(option[0]);
    row.current?.querySelectorAll<HTMLButtonElement>('button')[to]?.focus();
  };
  return (
    <div class="choice" role="radiogroup" aria-label={label} ref={row} onKeyDown={onKeyDown}>
      {options.map(([v, text], i) => (
        <button
          key={text}
          type="button"
          role="radio"
          aria-checked={i === chosen && v === value}
          tabIndex={i === chosen ? 0 : -1}
          class={v === value ? 'on' : ''}
          onClick={() => onChoose(v)}
        >
          {text}
        </button>
      ))}
    </div>
  );
}
