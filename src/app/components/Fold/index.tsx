/**
 * A panel that folds away on a phone. A phone's first screen is for what a user looks at first
 * (the link state and the channel bars); the rest (diagnosis, remotes, graphs, traces, system,
 * counters) waits behind a disclosure of its own, one tap to open, each remembered while the
 * page is open. On a wider screen every panel is open and the disclosure is not shown (style.css).
 */
import { type Signal, signal } from '@preact/signals';
import type { ComponentChildren } from 'preact';
import { useEffect, useRef } from 'preact/hooks';
import './style.css';

/** Each fold's state on a phone, by name: closed until opened. */
const unfolded = new Map<string, Signal<boolean>>();

function stateOf(name: string): Signal<boolean> {
  let s = unfolded.get(name);
  if (s === undefined) {
    s = signal(false);
    unfolded.set(name, s);
  }
  return s;
}

/**
 * @param name the panel's name (its class is `panel p-<name>`)
 * @param title what the disclosure says
 * @param hint a few words on what is inside (e.g. "2 findings"), shown beside the title while folded
 * @param anchor the id of an element inside that links elsewhere on the page point to: following
 *   one while the panel is folded opens it and goes there
 */
export function Fold({
  name,
  title,
  hint,
  anchor,
  children,
}: {
  name: string;
  title: string;
  hint?: string;
  anchor?: string;
  children: ComponentChildren;
}) {
  const open = stateOf(name);
  const id = `fold-${name}`;
  const body = useRef<HTMLDivElement>(null);
  useEffect(() => {
    if (anchor === undefined) return undefined;
    const follow = (e: MouseEvent) => {
      const el = body.current;
      const link = e.target instanceof Element ? e.target.closest(`a[href="#${anchor}"]`) : null;
      // Only while folded away (on a wider screen the link works as it is).
      if (link === null || el === null || el.offsetParent !== null) return;
      e.preventDefault();
      open.value = true;
      requestAnimationFrame(() => document.getElementById(anchor)?.scrollIntoView());
    };
    document.addEventListener('click', follow, true);
    return () => document.removeEventListener('click', follow, true);
  }, [anchor]);
  return (
    <div class={`panel p-${name} fold${open.value ? ' unfolded' : ''}`}>
      <button
        type="button"
        class="fold-toggle"
        aria-expanded={open.value}
        aria-controls={id}
        onClick={() => {
          open.value = !open.value;
        }}
      >
        <span class="fold-title">{title}</span>
        {hint !== undefined && !open.value ? <span class="fold-hint">{hint}</span> : null}
      </button>
      <div class="fold-body" id={id} ref={body}>
        {children}
      </div>
    </div>
  );
}
