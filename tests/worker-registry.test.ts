/** The worker's source registry in Node: ids, labels, the list the page sees, and sessions of one kind. */
import { describe, expect, it } from 'vitest';
import { Diagnosis } from '../src/worker/diagnosis.js';
import { type Driver, type Source, SourceRegistry } from '../src/worker/registry.js';
import { fakeHost } from './worker-fakes.js';

/** A driver that notes what it was asked. */
function fakeDriver(kind: Driver['kind'], log: string[]): Driver {
  return {
    kind,
    clockUs: () => 42,
    clockRate: () => 4,
    linkNowUs: (id) => 100 + id,
    stop: async (sources: readonly Source[]) => {
      log.push(`${kind} stop ${sources.map((s) => s.id).join(',')}`);
    },
    release: async (s: Source) => {
      log.push(`${kind} release ${s.id}`);
    },
  };
}

function setup() {
  const fake = fakeHost();
  const log: string[] = [];
  const diagnosis = new Diagnosis(
    (m) => fake.host.post(m),
    () => 0,
    () => [],
    fake.clock,
  );
  const registry = new SourceRegistry(fake.host, diagnosis, {
    closing: async () => {
      log.push('closing');
    },
    empty: () => log.push('empty'),
  });
  return { ...fake, log, registry };
}

describe('the source registry', () => {
  it('gives each new source the lowest free id and its remote label, and the page a fresh decode for it', () => {
    const { registry, of } = setup();
    const ids = [0, 1, 2, 3, 4].map(() => registry.add('serial', registry.freeId(), 'port', 0));
    expect(ids.map((s) => [s.id, s.label])).toEqual([
      [0, 'A'],
      [1, 'B'],
      [2, 'R'],
      [3, 'L'],
      [4, 'R4'],
    ]);
    expect(of('reset').map((r) => r.source)).toEqual([0, 1, 2, 3, 4]);
    expect(ids[2]?.engine).not.toBe(ids[1]?.engine);
  });

  it('frees a removed source’s id for the next one, through its driver, and says when none is left', async () => {
    const { registry, log } = setup();
    await registry.use(fakeDriver('serial', log));
    registry.add('serial', registry.freeId(), 'a', 0);
    registry.add('serial', registry.freeId(), 'b', 0);
    await registry.remove(0);
    expect(log).toEqual(['serial release 0']);
    expect(registry.freeId()).toBe(0);
    await registry.remove(1);
    expect(log).toEqual(['serial release 0', 'serial release 1', 'empty']);
    await registry.remove(7); // not there: nothing happens
    expect(log).toHaveLength(3);
  });

  it('sends the list of sources only when something in it changed, with the driver’s clock rate', () => {
    const { registry, of } = setup();
    registry.send();
    expect(of('sources')).toHaveLength(1);
    const s = registry.add('demo', 0, 'Demo', 0);
    registry.send();
    registry.send();
    expect(of('sources')).toHaveLength(2);
    registry.setLabel(0, 'Left wing tip');
    registry.setState(s, 'reading');
    registry.send();
    const last = of('sources').at(-1)?.sources[0];
    expect(last).toMatchObject({ id: 0, label: 'Left win', state: 'reading', kind: 'demo', clockRate: 0 });
    expect(of('sources')).toHaveLength(4);
  });

  it('closes a session of another kind before a new one starts: the recording first, then the driver, then the page', async () => {
    const { registry, log, posts } = setup();
    const demo = fakeDriver('demo', log);
    await registry.use(demo);
    registry.add('demo', 0, 'a', 0);
    registry.add('demo', 1, 'b', 0);
    await registry.use(demo); // the same driver: nothing closes
    expect(log).toEqual([]);
    posts.length = 0;
    await registry.use(fakeDriver('serial', log));
    expect(log).toEqual(['empty', 'closing', 'demo stop 0,1']);
    expect(registry.size).toBe(0);
    expect(posts.map((p) => p.type)).toContain('reset');
    expect(registry.driver?.kind).toBe('serial');
  });

  it('takes the session clock and each link’s time from the driver', async () => {
    const { registry, clock } = setup();
    expect(registry.clockUs()).toBe(clock.now() * 1000);
    await registry.use(fakeDriver('replay', []));
    expect(registry.clockUs()).toBe(42);
    expect(registry.linkNowUs(3)).toBe(103);
  });
});
