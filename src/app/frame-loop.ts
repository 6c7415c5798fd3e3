/**
 * One requestAnimationFrame loop for every high-rate view. A renderer is called each frame and
 * decides itself whether anything it shows changed (data version, or a displayed age rolling over).
 */
export type Renderer = (nowMs: number) => void;

const renderers = new Set<Renderer>();
let running = false;

function loop(nowMs: number): void {
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
