/**
 * One requestAnimationFrame loop for every high-rate view. A renderer is called each frame and
 * decides itself whether anything it shows changed (data version, or a displayed age rolling over).
 */
export type Renderer = (nowMs: number) => void;

const renderers = new Set<Renderer>();
let running = false;
/** Counts animation frames; the frame in which a chart last redrew. */
let frame = 0;
let chartFrame = -1;

function loop(nowMs: number): void {
  frame++;
  for (const render of renderers) render(nowMs);
  if (renderers.size > 0) requestAnimationFrame(loop);
  else running = false;
}

/** Adds a renderer; returns the function that removes it. */
export function onFrame(render: Renderer): () => void {
  renderers.add(render);
  if (!running) {
    running = true;
    requestAnimationFrame(loop);
  }
  return () => renderers.delete(render);
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
