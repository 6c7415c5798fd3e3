/**
 * Loads a component's code the first time it is shown (the bind panel and the frame inspector
 * are opened on demand, so the first page load does not carry them).
 */
import type { ComponentType } from 'preact';
import { useEffect, useState } from 'preact/hooks';

export function lazy<P extends object>(load: () => Promise<ComponentType<P>>): ComponentType<P> {
  let loaded: ComponentType<P> | undefined;
  return function Lazy(props: P) {
    const [Comp, setComp] = useState<ComponentType<P> | undefined>(() => loaded);
    useEffect(() => {
      if (Comp !== undefined) return;
      void load().then((c) => {
        loaded = c;
        setComp(() => c);
      });
    }, [Comp]);
    return Comp === undefined ? <p class="muted">Loading…</p> : <Comp {...props} />;
  };
}
