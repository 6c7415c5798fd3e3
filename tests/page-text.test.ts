import { describe, expect, it } from 'vitest';
import { setText } from '../src/app/text.js';

/** Just enough of a DOM element and its Text children for setText: what replaced what. */
class FakeText {
  readonly nodeType = 3;
  nextSibling: FakeText | null = null;
  writes = 0;
  #data: string;
  constructor(data: string) {
    this.#data = data;
  }
  get data(): string {
    return this.#data;
  }
  set data(v: string) {
    this.#data = v;
    this.writes++;
  }
}

class FakeElement {
  children: FakeText[] = [];
  ownerDocument = { createTextNode: (data: string) => new FakeText(data) };
  get firstChild(): FakeText | null {
    return this.children[0] ?? null;
  }
  get textContent(): string {
    return this.children.map((c) => c.data).join('');
  }
  set textContent(v: string) {
    this.children = v === '' ? [] : [new FakeText(v)];
  }
  appendChild(node: FakeText): FakeText {
    const last = this.children.at(-1);
    if (last !== undefined) last.nextSibling = node;
    this.children.push(node);
    return node;
  }
}

const asNode = (el: FakeElement) => el as unknown as Node;

describe('text that changes every frame', () => {
  it('changes the data of the one Text node instead of replacing it', () => {
    const el = new FakeElement();
    el.textContent = '—';
    const node = el.firstChild;
    for (const v of ['1500 µs', '1501 µs', '1502 µs']) setText(asNode(el), v);
    expect(el.firstChild).toBe(node);
    expect(el.children).toHaveLength(1);
    expect(el.textContent).toBe('1502 µs');
  });

  it('writes nothing when the text is the same', () => {
    const el = new FakeElement();
    setText(asNode(el), '12 ms ago');
    const node = el.firstChild;
    setText(asNode(el), '12 ms ago');
    expect(node?.writes).toBe(0);
  });

  it('keeps a Text node through an empty text, so the next value changes it in place', () => {
    const el = new FakeElement();
    setText(asNode(el), '');
    const node = el.firstChild;
    expect(node).not.toBeNull();
    setText(asNode(el), 'stale 1.2 s');
    setText(asNode(el), '');
    setText(asNode(el), 'stale 1.3 s');
    expect(el.firstChild).toBe(node);
    expect(el.textContent).toBe('stale 1.3 s');
  });
});
