/**
 * A button that opens a small panel of more actions or settings below it (the disclosure
 * pattern: a real button with aria-expanded, the panel's controls in the tab order after it).
 * Escape closes it and puts focus back on the button; so does a click or focus outside.
 */
import type { ComponentChildren } from 'preact';
import { useEffect, useId, useLayoutEffect, useRef, useState } from 'preact/hooks';
import './style.css';

export function Menu({
  label,
  title,
  align = 'start',
  disabled = false,
  className = '',
  children,
}: {
  /** The button's text (and accessible name). */
  label: ComponentChildren;
  title?: string;
  /** Which edge of the button the panel lines up with. */
  align?: 'start' | 'end';
  disabled?: boolean;
  className?: string;
  /** The panel's content; `close` shuts the panel (call it after an action). */
  children: (close: () => void) => ComponentChildren;
}) {
  const [open, setOpen] = useState(false);
  const root = useRef<HTMLDivElement>(null);
  const button = useRef<HTMLButtonElement>(null);
  const pop = useRef<HTMLDivElement>(null);
  const id = useId();
  // A layout effect, so Escape works from the moment the panel shows: a plain effect waits for
  // the next animation frame, and a key pressed before it (a busy page, a quick hand) was lost.
  useLayoutEffect(() => {
    if (!open) return undefined;
    const outside = (e: Event) => {
      if (root.current !== null && !root.current.contains(e.target as Node)) setOpen(false);
    };
    const key = (e: KeyboardEvent) => {
      if (e.key !== 'Escape') return;
      setOpen(false);
      button.current?.focus();
    };
    document.addEventListener('pointerdown', outside);
    document.addEventListener('focusin', outside);
    document.addEventListener('keydown', key);
    return () => {
      document.removeEventListener('pointerdown', outside);
      document.removeEventListener('focusin', outside);
      document.removeEventListener('keydown', key);
    };
  }, [open]);
  // On a narrow screen a panel lined up with its button can run past the viewport's edge (the
  // Report menu's, on a phone): it is moved back inside, 8 px from the edge, before it paints.
  useLayoutEffect(() => {
    const el = pop.current;
    if (!open || el === null) return;
    el.style.translate = '';
    const r = el.getBoundingClientRect();
    const shift = r.left < 8 ? 8 - r.left : r.right > innerWidth - 8 ? Math.max(8 - r.left, innerWidth - 8 - r.right) : 0;
    if (shift !== 0) el.style.translate = `${shift}px 0`;
  }, [open]);
  useEffect(() => {
    if (disabled) setOpen(false);
  }, [disabled]);
  const close = () => {
    setOpen(false);
    button.current?.focus();
  };
  return (
    <div class={`menu ${className}`} ref={root}>
      <button
        ref={button}
        type="button"
        class="menu-button"
        aria-expanded={open}
        aria-controls={id}
        disabled={disabled}
        title={title}
        onClick={() => setOpen(!open)}
      >
        {label}
        <span class="caret" aria-hidden="true" />
      </button>
      <div id={id} ref={pop} class={`menu-pop ${align}`} hidden={!open}>
        {open ? children(close) : null}
      </div>
    </div>
  );
}
