/**
 * A live chart's axes, grid and labels drawn once on a canvas of their own, and drawn again only
 * when they change; each redraw of the chart copies that canvas in, then draws its series.
 *
 * uPlot draws everything into one canvas on every redraw: the live graphs redraw ten times a
 * second, and each time every tick label and the axis title were drawn again with fillText (the
 * costliest script of a redraw: 10–15 ms of the animation frame that redrew the four charts, in
 * the traces of the page's long tasks), though they had not changed. They rarely do: the x ticks
 * are counted back from the window's end ("now", −10 s…) and stay put while the data slides past
 * them (axes.ts), and the y range changes only when the data's top crosses a round number. So
 * the chart draws its series only, over a copy of a second uPlot with the same axes and no
 * series, legend or cursor, kept off the page and redrawn when what its axes show changes: the
 * plot's size, the y range or the x span. (Off the page rather than a layer under the chart's
 * canvas: a canvas more per chart made every frame's compositing dearer.)
 */
import uPlot from 'uplot';

/**
 * What a chart's axes show, as a key: the same key, the same picture. The x axis is labelled by
 * time before the window's end, so only the window's span counts, not where it is; rounded, so
 * that a span computed from a sliding end (end − (end − 60)) is the same span on every frame.
 */
export function axesKey(size: { width: number; height: number }, x: uPlot.Scale, y: uPlot.Scale): string {
  const span = (x.max ?? Number.NaN) - (x.min ?? Number.NaN);
  return `${size.width}x${size.height}|${span.toPrecision(9)}|${y.min}|${y.max}`;
}

/** Calls `draw` when the key differs from the last one drawn; says whether it did. */
export class Redrawn {
  #key: string | undefined;
  /** How many times it drew. */
  draws = 0;

  update(key: string, draw: () => void): boolean {
    if (key === this.#key) return false;
    this.#key = key;
    this.draws++;
    draw();
    return true;
  }
}

/**
 * A uPlot chart whose axes are drawn apart, only when they change. `options()` gives the chart's
 * options (it is called twice: uPlot keeps and changes the objects it is given, so the two charts
 * must not share them). Its x scale is the graphs' time window (`time: false`); the axes' chart
 * draws its y axis over the chart's y range and its x axis over the same span, ending at the
 * span, which the time axis labels as time before the end (agoAxis).
 */
export function layeredChart(options: () => uPlot.Options, data: uPlot.AlignedData, target: HTMLElement): uPlot {
  const own = options();
  const base = options();
  let yMin = 0;
  let yMax = 1;
  let span = 1;
  const layer = new uPlot(
    {
      ...base,
      legend: { show: false },
      cursor: { show: false },
      series: [{}, { show: false }],
      scales: {
        x: { time: false, range: () => [0, span] },
        y: { range: () => [yMin, yMax] },
      },
      hooks: {},
    },
    [
      [0, 1],
      [null, null],
    ],
    // No target: placed under the chart's canvas once the chart exists.
  );
  const redrawn = new Redrawn();
  const chart = new uPlot(
    {
      ...own,
      // The series only: axes, grid and labels are the layer's, copied in first.
      drawOrder: ['series' as uPlot.DrawOrderKey],
      hooks: {
        ...own.hooks,
        drawClear: [
          ...(own.hooks?.drawClear ?? []),
          (u) => {
            const x = u.scales.x;
            const y = u.scales.y;
            // No range (no data yet, a new source): the axes stay as they were last drawn.
            const ranged =
              x !== undefined && y !== undefined && [x.min, x.max, y.min, y.max].every((v) => typeof v === 'number' && Number.isFinite(v));
            if (ranged) {
              redrawn.update(axesKey(u, x, y), () => {
                span = (x.max ?? 1) - (x.min ?? 0);
                yMin = y.min ?? 0;
                yMax = y.max ?? 1;
                // batch() draws at once, not in a microtask: the copy below takes the new axes.
                layer.batch(() => {
                  if (layer.width !== u.width || layer.height !== u.height) layer.setSize({ width: u.width, height: u.height });
                  layer.setScale('x', { min: 0, max: span });
                  layer.setScale('y', { min: yMin, max: yMax });
                });
              });
            }
            if (redrawn.draws > 0) u.ctx.drawImage(layer.ctx.canvas, 0, 0);
          },
        ],
        destroy: [...(own.hooks?.destroy ?? []), () => layer.destroy()],
      },
    },
    data,
    target,
  );
  return chart;
}
