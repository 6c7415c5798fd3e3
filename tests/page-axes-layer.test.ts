import { describe, expect, it } from 'vitest';
import { Redrawn, axesKey } from '../src/app/axes-layer.js';

const SIZE = { width: 1216, height: 140 };

/** What a live graph's draw sees on each of `frames` animation frames: a window of `spanS` ending at the source clock. */
function slidingFrames(frames: number, spanS: number, top: (i: number) => number = () => 1) {
  const clockStartS = 1_234.567;
  return Array.from({ length: frames }, (_, i) => {
    const end = clockStartS + i / 60;
    return { x: { min: end - spanS, max: end }, y: { min: 0, max: top(i) } };
  });
}

describe("a live chart's axes", () => {
  it('are drawn once while the window slides over ten seconds of frames with the same y range', () => {
    const axes = new Redrawn();
    for (const { x, y } of slidingFrames(600, 60)) axes.update(axesKey(SIZE, x, y), () => undefined);
    expect(axes.draws).toBe(1);
  });

  it('are drawn again when the y range changes, and only then', () => {
    const axes = new Redrawn();
    // The fade rate's top goes from 1 to 2 at frame 200 and to 5 at frame 400.
    const frames = slidingFrames(600, 60, (i) => (i < 200 ? 1 : i < 400 ? 2 : 5));
    for (const { x, y } of frames) axes.update(axesKey(SIZE, x, y), () => undefined);
    expect(axes.draws).toBe(3);
  });

  it('are drawn again for another window or another size', () => {
    const axes = new Redrawn();
    const [first] = slidingFrames(1, 60);
    const [tenSeconds] = slidingFrames(1, 10);
    if (first === undefined || tenSeconds === undefined) throw new Error('no frame');
    expect(axes.update(axesKey(SIZE, first.x, first.y), () => undefined)).toBe(true);
    expect(axes.update(axesKey(SIZE, first.x, first.y), () => undefined)).toBe(false);
    expect(axes.update(axesKey(SIZE, tenSeconds.x, tenSeconds.y), () => undefined)).toBe(true);
    expect(axes.update(axesKey({ width: 600, height: 140 }, tenSeconds.x, tenSeconds.y), () => undefined)).toBe(true);
  });
});
