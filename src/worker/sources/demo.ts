/**
 * The demo source: the library's simulator running the demo scenario (sticks moving, fades, an
 * X-Plus pass, a VTX burst, a dropout into failsafe) in real time, delivered in 16 ms batches
 * the way a USB adapter delivers bytes.
 */
import { Simulator, demoScenario } from '../../simulator/index.js';

const CHUNK_MS = 16;

export class DemoSource {
  readonly #sim: Simulator;
  readonly #offsetUs: number;
  #timer: ReturnType<typeof setInterval> | undefined;

  /**
   * @param nowUs the worker's clock in µs
   * @param onData called with each batch of bytes and its arrival time on the worker's clock
   */
  constructor(
    readonly nowUs: () => number,
    readonly onData: (bytes: Uint8Array, timeUs: number) => void,
  ) {
    this.#sim = new Simulator(demoScenario());
    // Simulator time 0 is now.
    this.#offsetUs = nowUs() - this.#sim.scenario.timing.startUs;
  }

  start(): void {
    this.#timer = setInterval(() => {
      const now = this.nowUs();
      const chunk = this.#sim.generate(now - this.#offsetUs);
      if (chunk.bytes.length > 0) this.onData(chunk.bytes, now);
    }, CHUNK_MS);
  }

  stop(): void {
    clearInterval(this.#timer);
    this.#timer = undefined;
  }
}
