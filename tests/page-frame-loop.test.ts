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
  vi.useRealTimers();
});

describe('the frame loop', () => {
  it('runs every frame while there is news, a few times a second after a second without, and every frame again at once on news', async () => {
    vi.useFakeTimers({ toFake: ['setTimeout', 'clearTimeout', 'performance'] });
    vi.resetModules();
    let queued: FrameRequestCallback[] = [];
    vi.stubGlobal('requestAnimationFrame', (cb: FrameRequestCallback) => queued.push(cb));
    const { onFrame, wake } = await import('../src/app/frame-loop.js');
    let draws = 0;
    onFrame(() => {
      draws++;
    });
    /** Runs `ms` of time: each animation frame asked for runs after 16 ms, timers as they fall due. */
    const run = (ms: number) => {
      for (let t = 0; t < ms; t += 16) {
        vi.advanceTimersByTime(16);
        const due = queued;
        queued = [];
        for (const cb of due) cb(performance.now());
      }
    };
    run(960);
    expect(draws).toBeGreaterThanOrEqual(55);
    // A second with no news: a frame every 250 ms.
    run(1000);
    draws = 0;
    run(1000);
    expect(draws).toBeGreaterThanOrEqual(3);
    expect(draws).toBeLessThanOrEqual(5);
    // News: the next frame runs, not the next idle one.
    wake();
    draws = 0;
    run(32);
    expect(draws).toBe(2);
    run(480);
    expect(draws).toBeGreaterThanOrEqual(30);
  });
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
