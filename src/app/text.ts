/**
 * Text that changes many times a second (pulse widths, counters, "12 ms ago"), written in place.
 * Setting `textContent` replaces the element's Text node: the old one leaves the layout tree
 * and a new one is inserted, styled and laid out from scratch, for each value. Changing the
 * data of the one Text node already there is a plain text change, which the browser lays out
 * again without restyling anything.
 */

const TEXT_NODE = 3;

/** Shows `text` in `el`, changing its lone Text node's data when it has one. */
export function setText(el: Node, text: string): void {
  const first = el.firstChild;
  if (first !== null && first.nodeType === TEXT_NODE && first.nextSibling === null) {
    const node = first as Text;
    if (node.data !== text) node.data = text;
  } else {
    // No lone Text node yet: one is made (an empty one for ''), and changed in place from then on.
    el.textContent = text;
    if (el.firstChild === null) el.appendChild((el.ownerDocument ?? document).createTextNode(''));
  }
}

/** A fade rate as the page words it everywhere: per minute, as the link monitor's rate (per second) times 60. */
export function fadesPerMinute(perSecond: number): string {
  return Number.isFinite(perSecond) ? `${(perSecond * 60).toFixed(0)}/min` : '—';
}
