import { describe, expect, it } from 'vitest';
import { detachEarly } from '../src/worker/detach-early.js';

describe('detachEarly', () => {
  it('detaches a buffer that has two views (what makes the engine drop its no-detach assumption)', () => {
    expect(detachEarly()).toBe(true);
  });
});
