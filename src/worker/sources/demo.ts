/**
 * The demo source: the library's simulator in real time, delivered in 16 ms batches the way a
 * USB adapter delivers bytes. Two remotes, as a real installation has them (spec §7.3): A, the
 * internal one (sticks moving, fades, an X-Plus pass, a VTX burst, a dropout into failsafe),
 * and B, an external one mounted at 90° whose dropouts come at other times.
 *
 * The simulated receiver keeps its own time: every chunk is stamped with the simulated time its
 * last byte was sent, and the links are judged at the simulated time delivered so far. A timer
 * that fires late (a busy machine, a starved worker) delivers the chunks it owes, each at its own
 * time, so a late timer is never link loss; the demo's failsafes are the scenario's dropouts.
 */
import { Simulator } from '../../simulator/simulator.js';
import { demoScenario } from '../../simulator/presets.js';
import type { Scenario } from '../../simulator/scenario.js';
import type { Clock } from '../host.js';
import type { Driver } from '../registry.js';

const CHUNK_MS = 16;
const CHUNK_US = CHUNK_MS * 1000;
const SECOND = 1_000_000;
/**
 * The most simulated time a late timer catches up at once. A longer stall (a machine asleep)
 * pauses the simulation instead, and the links are told the frames stopped for a reason that is
 * not theirs: the simulated receiver never went silent, so counting the silence would be a
 * failsafe that never happened.
 */
const CATCH_UP_US = 10 * SECOND;

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
  /** Worker clock minus simulator clock: grows when a stall longer than CATCH_UP_US is skipped. */
  #offsetUs: number;
  /** The simulated time delivered so far, on the worker's clock: the links are judged here. */
  #deliveredUs: number;
  #timer: unknown;

  /**
   * @param clock the worker's clock
   * @param onData called with each remote's batch of bytes and its arrival time on the worker's clock, µs
   * @param onPause called when the simulation paused at `atUs` (a stall too long to catch up)
   */
  constructor(
    readonly clock: Clock,
    readonly onData: (remote: number, bytes: Uint8Array, timeUs: number) => void,
    readonly onPause: (atUs: number) => void = () => undefined,
  ) {
    const a = new Simulator(demoScenario());
    this.#sims = [a, new Simulator(externalDemo())];
    // Simulator time 0 is now.
    this.#deliveredUs = this.clockUs();
    this.#offsetUs = this.#deliveredUs - a.scenario.timing.startUs;
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

  /** Never past the simulated time delivered: a silence the timer caused is not the receiver's. */
  linkNowUs(): number {
    return this.#deliveredUs;
  }

  start(): void {
    if (this.#timer !== undefined) return;
    this.#timer = this.clock.every(CHUNK_MS, () => this.#deliver(this.clockUs()));
  }

  /** Sends what the remotes sent up to `nowUs`, a USB chunk at a time, each at its simulated time. */
  #deliver(nowUs: number): void {
    if (nowUs - this.#deliveredUs > CATCH_UP_US) {
      this.onPause(this.#deliveredUs);
      this.#offsetUs += nowUs - this.#deliveredUs - CATCH_UP_US;
      this.#deliveredUs = nowUs - CATCH_UP_US;
    }
    while (this.#deliveredUs < nowUs) {
      const at = Math.min(this.#deliveredUs + CHUNK_US, nowUs);
      this.#sims.forEach((sim, i) => {
        const chunk = sim.generate(at - this.#offsetUs);
        if (chunk.bytes.length > 0) this.onData(i, chunk.bytes, at);
      });
      this.#deliveredUs = at;
    }
  }

  async stop(): Promise<void> {
    this.clock.cancel(this.#timer);
    this.#timer = undefined;
  }

  /** A remote closed on its own: its bytes are dropped by the sink (the simulation goes on, as a receiver would). */
  async release(): Promise<void> {}
}
