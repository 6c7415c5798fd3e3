/**
 * One requestAnimationFrame loop for every high-rate view. A renderer is called each frame and
 * decides itself whether anything it shows changed (data version, or a displayed age rolling over).
 * With no news for a while (no remote's data from the worker, no input: a page left open with
 * nothing plugged in, a paused replay, a long capture being read) the loop runs a few times a
 * second instead of every frame: what still moves then (an age, an axis sliding with time) moves
 * at that pace, and an idle page stops costing a frame's work sixty times a second. News wakes
 * it at once.
 */
export type Renderer = (nowMs: number) => void;

/** No news for this long: the loop slows down. */
const IDLE_AFTER_MS = 1000;
/** Between frames while idle. */
const IDLE_FRAME_MS = 250;

const renderers = new Set<Renderer>();
/** A frame or an idle wait is scheduled. */
let scheduled = false;
let idleTimer: ReturnType<typeof setTimeout> | undefined;
let lastNewsMs = Number.NEGATIVE_INFINITY;
/** Counts animation frames; the frame in which a chart last redrew. */
let frame = 0;
let chartFrame = -1;

function loop(nowMs: number): void {
  scheduled = false;
  frame++;
  for (const render of renderers) render(nowMs);
  if (renderers.size === 0) return;
  scheduled = true;
  if (performance.now() - lastNewsMs < IDLE_AFTER_MS) requestAnimationFrame(loop);
  else
    idleTimer = setTimeout(() => {
      idleTimer = undefined;
      requestAnimationFrame(loop);
    }, IDLE_FRAME_MS);
}

/** Adds a renderer; returns the function that removes it. */
export function onFrame(render: Renderer): () => void {
  renderers.add(render);
  wake();
  return () => renderers.delete(render);
}

/**
 * Something may have changed what the views show (a message from the worker, the user's input):
 * the loop runs every frame again, from the next one.
 */
export function wake(): void {
  lastNewsMs = performance.now();
  if (idleTimer !== undefined) {
    clearTimeout(idleTimer);
    idleTimer = undefined;
    scheduled = false;
  }
  if (!scheduled && renderers.size > 0) {
    scheduled = true;
    requestAnimationFrame(loop);
  }
}

/**
 * The charts that redraw a few times a second (the graphs, the remotes' chart) take turns: the
 * first to ask in an animation frame redraws, another waits for the next frame, 16 ms later,
 * rather than adding its cost to the same one. Returns whether this one may redraw now.
 */
export function chartTurn(): boolean {
  if (chartFrame === frame) return false;
  chartFrame = frame;
  return true;
}
