import { afterEach, describe, expect, it, vi } from 'vitest';

/** The page's frame loop with requestAnimationFrame played by hand: `frame()` runs one animation frame. */
async function frameLoop() {
  vi.resetModules();
  let queued: FrameRequestCallback[] = [];
  vi.stubGlobal('requestAnimationFrame', (cb: FrameRequestCallback) => {
    queued.push(cb);
    return queued.length;
  });
  const loop = await import('../src/app/frame-loop.js');
  let now = 0;
  const frame = () => {
    const run = queued;
    queued = [];
    now += 16.7;
    for (const cb of run) cb(now);
  };
  return { ...loop, frame };
}

afterEach(() => {
  vi.unstubAllGlobals();
});

describe('the charts that redraw a few times a second', () => {
  it('redraw in different animation frames when both are due in the same one', async () => {
    const { onFrame, chartTurn, frame } = await frameLoop();
    const drawn: string[][] = [];
    const due = { graphs: false, remotes: false };
    let now: string[] = [];
    onFrame(() => {
      now = [];
      drawn.push(now);
    });
    for (const name of ['graphs', 'remotes'] as const) {
      onFrame(() => {
        if (!due[name] || !chartTurn()) return;
        due[name] = false;
        now.push(name);
      });
    }
    due.graphs = due.remotes = true;
    frame();
    frame();
    frame();
    expect(drawn).toEqual([['graphs'], ['remotes'], []]);
  });

  it('each redraw at once when it is the only one due', async () => {
    const { onFrame, chartTurn, frame } = await frameLoop();
    let draws = 0;
    onFrame(() => {
      if (chartTurn()) draws++;
    });
    frame();
    frame();
    expect(draws).toBe(2);
  });
});
