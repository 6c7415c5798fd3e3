import { describe, expect, it } from 'vitest';
import type { DoctorFinding } from '../src/report/doctor-types.js';
import { splitFindings } from '../src/app/components/Diagnosis/current.js';
import { type LinkFacts, linkView, sinceLastFrame } from '../src/app/components/LinkPanel/view.js';
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

describe('the link panel', () => {
  const facts = (over: Partial<LinkFacts>): LinkFacts => ({
    state: 'live',
    kind: 'serial',
    sourceState: 'reading',
    remote: 'A',
    reading: false,
    positionUs: Number.NaN,
    ended: false,
    mismatch: null,
    forced: 'auto',
    ...over,
  });

  it('says Live and frames arriving only while a receiver is read', () => {
    expect(linkView(facts({}))).toEqual({ key: 'live', label: 'Live', hint: 'Frames arriving.' });
    expect(linkView(facts({ kind: 'demo', state: 'hold' }))).toMatchObject({ key: 'hold', label: 'Hold' });
  });

  it('says a paused replay is paused, at which capture time, and what the link was doing there', () => {
    const v = linkView(facts({ kind: 'replay', sourceState: 'paused', positionUs: 12_345_000 }));
    expect(v).toEqual({ key: 'paused', label: 'Paused', hint: 'Paused at 0:12.3 of the capture: there the link was live.' });
    expect(linkView(facts({ kind: 'replay', sourceState: 'paused', state: 'failsafe', positionUs: 61e6 })).hint).toBe(
      'Paused at 1:01.0 of the capture: there the link was in failsafe.',
    );
  });

  it('says an ended replay ended, whatever state it froze in', () => {
    for (const state of ['live', 'hold', 'failsafe', 'waiting'] as const) {
      const v = linkView(facts({ kind: 'replay', sourceState: 'ended', ended: true, state, positionUs: 3e6 }));
      expect(v.key).toBe('ended');
      expect(v.label).toBe('Ended');
      expect(v.hint).toMatch(/^Replay ended at 0:03\.0: there /);
    }
  });

  it('dates the last frame "ago" while time runs, and before the point a replay paused or ended at', () => {
    expect(sinceLastFrame(12_400, facts({}))).toBe('12 ms ago');
    expect(sinceLastFrame(3_250_000, facts({ kind: 'replay', sourceState: 'playing' }))).toBe('3.3 s ago');
    expect(sinceLastFrame(1_000, facts({ kind: 'replay', sourceState: 'ended', ended: true }))).toBe('1 ms before the end');
    expect(sinceLastFrame(1_000, facts({ kind: 'replay', sourceState: 'playing', ended: true }))).toBe('1 ms before the end');
    expect(sinceLastFrame(40_000, facts({ kind: 'replay', sourceState: 'paused' }))).toBe('40 ms before this point');
    expect(sinceLastFrame(Number.NaN, facts({}))).toBe('—');
    // The page's clock a little behind the frame's: just now.
    expect(sinceLastFrame(-4_000, facts({}))).toBe('0 ms ago');
  });

  it('gives a playing replay the link state at its position, named as the capture', () => {
    expect(linkView(facts({ kind: 'replay', sourceState: 'playing', state: 'hold', positionUs: 2e6 }))).toEqual({
      key: 'hold',
      label: 'Hold',
      hint: 'Replay at 0:02.0: frames missing: last values held.',
    });
  });

  it('says a lost port is lost, never Live or Failsafe of a link nobody can see', () => {
    for (const state of ['live', 'hold', 'failsafe'] as const) {
      const v = linkView(facts({ sourceState: 'lost', state, remote: 'B' }));
      expect(v.key).toBe('lost');
      expect(v.label).toBe('Port lost');
      expect(v.hint).toMatch(/^Remote B's adapter is gone/);
    }
  });

  it('says a capture is being read before anything else', () => {
    expect(linkView(facts({ kind: 'replay', reading: true, sourceState: 'paused' })).key).toBe('reading');
  });

  it('ends every hint with a full stop', () => {
    const all: LinkFacts[] = [];
    for (const state of ['waiting', 'live', 'hold', 'failsafe'] as const)
      for (const [kind, sourceState] of [
        ['serial', 'reading'],
        ['serial', 'lost'],
        ['demo', 'reading'],
        ['replay', 'playing'],
        ['replay', 'paused'],
        ['replay', 'ended'],
      ] as const)
        all.push(facts({ state, kind, sourceState, positionUs: 1e6 }), facts({ state, kind, sourceState, mismatch: 1024, forced: 2048 }));
    for (const f of all) expect(linkView(f).hint).toMatch(/\.$/);
  });
});

describe('the diagnosis', () => {
  const finding = (code: string, ports: number[]): DoctorFinding => ({ code, ports }) as unknown as DoctorFinding;

  it('keeps findings about ports that are all gone apart from the link now', () => {
    const list = [finding('weak-link', [0]), finding('two-remotes', [0, 1]), finding('session', []), finding('noise', [1])];
    const { current, before } = splitFindings(list, [0]);
    expect(current.map((f) => f.code)).toEqual(['two-remotes', 'session', 'noise']);
    expect(before.map((f) => f.code)).toEqual(['weak-link']);
    expect(splitFindings(list, []).before).toEqual([]);
    expect(splitFindings(list, [0, 1]).current.map((f) => f.code)).toEqual(['session']);
  });
});
