/**
 * The demo source: the library's simulator in real time, delivered in 16 ms batches the way a
 * USB adapter delivers bytes. Two remotes, as a real installation has them (spec §7.3): A, the
 * internal one (sticks moving, fades, an X-Plus pass, a VTX burst, a dropout into failsafe),
 * and B, an external one mounted at 90° whose dropouts come at other times.
 */
import { Simulator, demoScenario, type Scenario } from '../../simulator/index.js';
import type { Clock } from '../host.js';
import type { Driver } from '../registry.js';

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

export class DemoSource implements Driver {
  readonly kind = 'demo';
  readonly #sims: Simulator[];
  readonly #offsetUs: number;
  #timer: unknown;

  /**
   * @param clock the worker's clock
   * @param onData called with each remote's batch of bytes and its arrival time on the worker's clock, µs
   */
  constructor(
    readonly clock: Clock,
    readonly onData: (remote: number, bytes: Uint8Array, timeUs: number) => void,
  ) {
    const a = new Simulator(demoScenario());
    this.#sims = [a, new Simulator(externalDemo())];
    // Simulator time 0 is now.
    this.#offsetUs = this.clockUs() - a.scenario.timing.startUs;
  }

  /** How many remotes the demo has. */
  get remotes(): number {
    return this.#sims.length;
  }

  clockUs(): number {
    return this.clock.now() * 1000;
  }

  clockRate(): number {
    return 1;
  }

  linkNowUs(): number {
    return this.clockUs();
  }

  start(): void {
    if (this.#timer !== undefined) return;
    this.#timer = this.clock.every(CHUNK_MS, () => {
      const now = this.clockUs();
      this.#sims.forEach((sim, i) => {
        const chunk = sim.generate(now - this.#offsetUs);
        if (chunk.bytes.length > 0) this.onData(i, chunk.bytes, now);
      });
    });
  }

  async stop(): Promise<void> {
    this.clock.cancel(this.#timer);
    this.#timer = undefined;
  }

  /** A remote closed on its own: its bytes are dropped by the sink (the simulation goes on, as a receiver would). */
  async release(): Promise<void> {}
}
