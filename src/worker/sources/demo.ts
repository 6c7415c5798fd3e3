/**
 * The demo source: the library's simulator in real time, delivered in 16 ms batches the way a
 * USB adapter delivers bytes. Two remotes, as a real installation has them (spec §7.3): A, the
 * internal one (sticks moving, fades, an X-Plus pass, a VTX burst, a dropout into failsafe),
 * and B, an external one mounted at 90° whose dropouts come at other times.
 */
import { Simulator, demoScenario, type Scenario } from '../../simulator/index.js';

const CHUNK_MS = 16;
const SECOND = 1_000_000;

/** Remote B: the same transmitter and sticks, an external remote with its own fades and dropouts. */
function externalDemo(): Scenario {
  const a = demoScenario();
  return {
    ...a,
    name: 'demo-b',
    remote: 'external',
    xplus: a.xplus,
    vtx: undefined,
    fades: { start: 40, lossRate: 0.008, randomRate: 0.003 },
    dropouts: [
      { atUs: 12 * SECOND, durationUs: 0.4 * SECOND },
      { atUs: 33 * SECOND, durationUs: 1.3 * SECOND },
    ],
  };
}

export class DemoSource {
  readonly #sims: Simulator[];
  readonly #offsetUs: number;
  #timer: ReturnType<typeof setInterval> | undefined;

  /**
   * @param nowUs the worker's clock in µs
   * @param onData called with each remote's batch of bytes and its arrival time on the worker's clock
   */
  constructor(
    readonly nowUs: () => number,
    readonly onData: (remote: number, bytes: Uint8Array, timeUs: number) => void,
  ) {
    this.#sims = [new Simulator(demoScenario()), new Simulator(externalDemo())];
    // Simulator time 0 is now.
    this.#offsetUs = nowUs() - (this.#sims[0] as Simulator).scenario.timing.startUs;
  }

  /** How many remotes the demo has. */
  get remotes(): number {
    return this.#sims.length;
  }

  start(): void {
    this.#timer = setInterval(() => {
      const now = this.nowUs();
      this.#sims.forEach((sim, i) => {
        const chunk = sim.generate(now - this.#offsetUs);
        if (chunk.bytes.length > 0) this.onData(i, chunk.bytes, now);
      });
    }, CHUNK_MS);
  }

  stop(): void {
    clearInterval(this.#timer);
    this.#timer = undefined;
  }
}
