/**
 * Grading a flight controller against what Drive sent, on a fake one that follows Betaflight's
 * documented rules (tests/fake-fc.ts): its channel order found from a sweep, its values against
 * §9's, the time a step takes to reach it, and when it reports the receiver lost and back.
 */
import { describe, expect, it } from 'vitest';
import { servoToMicros } from '../src/decoder/spec.js';
import { builtinScenarios } from '../src/drive/builtins.js';
import { type FcReading, gradeDrive } from '../src/drive/grade.js';
import { DrivePlayer, type DriveWrite } from '../src/drive/player.js';
import type { DriveScenario } from '../src/drive/scenario.js';
import { FakeFc, type FakeFcOptions } from './fake-fc.js';

/** Plays `name` into a fake flight controller, reading it every `pollUs` as MSP would. */
function drive(name: string, fc: FakeFcOptions, pollUs = 20_000): { sent: DriveWrite[]; readings: FcReading[] } {
  const scenario = builtinScenarios({ system: 0xb2, remote: 'internal', channels: 12 }).find((s) => s.name === name) as DriveScenario;
  const sent = new DrivePlayer(scenario).writesUntil(Number.POSITIVE_INFINITY);
  const flight = new FakeFc(fc);
  const readings: FcReading[] = [];
  let k = 0;
  const end = (sent.at(-1)?.atUs ?? 0) + 2_000_000;
  for (let t = 0; t < end; t += pollUs) {
    for (; k < sent.length && (sent[k] as DriveWrite).atUs <= t; k++)
      flight.write((sent[k] as DriveWrite).bytes, (sent[k] as DriveWrite).atUs);
    readings.push(flight.state(t));
  }
  return { sent, readings };
}

const check = (g: ReturnType<typeof gradeDrive>, id: string) => g.checks.find((c) => c.id === id);

describe('grading a flight controller', () => {
  it('finds the channel order from a sweep: right with map TAER1234, wrong with the default AETR1234', () => {
    const right = gradeDrive(...(Object.values(drive('sweep', { resolution: 2048, map: 'TAER1234' })) as [DriveWrite[], FcReading[]]));
    expect(check(right, 'channel-map')?.verdict).toBe('pass');
    expect([...right.map].slice(0, 4)).toEqual([
      [0, 1],
      [1, 2],
      [2, 3],
      [3, 0],
    ]);
    const wrong = gradeDrive(...(Object.values(drive('sweep', { resolution: 2048, map: 'AETR1234' })) as [DriveWrite[], FcReading[]]));
    expect(check(wrong, 'channel-map')).toMatchObject({ verdict: 'fail' });
    expect(check(wrong, 'channel-map')?.found).toMatch(/channel 1 follows Throttle, not Aileron/);
  });

  it("measures Betaflight's scale against §9's: some 57 µs off at full stick", () => {
    const g = gradeDrive(...(Object.values(drive('sweep', { resolution: 2048 })) as [DriveWrite[], FcReading[]]));
    const values = check(g, 'values');
    expect(values?.verdict).toBe('fail');
    const worst = Number(/(-?\d+) µs at the most/.exec(values?.found ?? '')?.[1]);
    expect(Math.abs(worst)).toBeGreaterThan(50);
    expect(Math.abs(worst)).toBeLessThan(62);
  });

  it('times steps to the poll, and the receiver lost and back across the dropouts', () => {
    const steps = gradeDrive(...(Object.values(drive('steps', { resolution: 2048 })) as [DriveWrite[], FcReading[]]));
    const lag = check(steps, 'latency');
    expect(lag?.verdict).toBe('pass');
    const median = Number(/: ([\d.]+) ms median/.exec(lag?.found ?? '')?.[1]);
    expect(median).toBeGreaterThan(0);
    expect(median).toBeLessThanOrEqual(40);
    const drops = gradeDrive(...(Object.values(drive('dropouts', { resolution: 2048 })) as [DriveWrite[], FcReading[]]));
    const fs = check(drops, 'failsafe');
    expect(fs?.verdict).toBe('pass');
    // 1.2 s and 5 s silences: lost after about Betaflight's 100 ms (to the 20 ms poll).
    const after = [...(fs?.found ?? '').matchAll(/lost after (\d+) ms/g)].map((m) => Number(m[1]));
    expect(after.length).toBeGreaterThanOrEqual(2);
    for (const a of after) expect(a).toBeGreaterThanOrEqual(100);
    for (const a of after) expect(a).toBeLessThanOrEqual(130);
  });

  it('passes a flight controller that reads exactly by §9 however late it reads, and fails one too slow or stuck', () => {
    // A flight controller that converts by §9 exactly, `lagUs` behind, read every 20 ms.
    const exact = (name: string, lagUs: number, loss: (t: number, sentNow: boolean) => boolean | null = (_, on) => !on) => {
      const scenario = builtinScenarios({ system: 0xb2, remote: 'internal', channels: 12 }).find((x) => x.name === name) as DriveScenario;
      const sent = new DrivePlayer(scenario).writesUntil(Number.POSITIVE_INFINITY);
      const frames = sent.filter((w) => w.frame !== null);
      const readings: FcReading[] = [];
      const last = new Map<number, number>();
      let k = 0;
      for (let t = 0; t < (sent.at(-1)?.atUs ?? 0) + 2e6; t += 20_000) {
        for (; k < frames.length && (frames[k] as DriveWrite).atUs <= t - lagUs; k++) {
          const f = (frames[k] as DriveWrite).frame;
          for (const c of f?.channels ?? []) last.set(c.id, servoToMicros(c.pos, f?.resolution ?? 2048));
        }
        const on = k > 0 && t - lagUs - ((frames[k - 1] as DriveWrite).atUs ?? 0) < 100_000;
        readings.push({ atUs: t, channels: [1, 2, 3, 0].map((id) => last.get(id) ?? 1500), rxLoss: loss(t, on) });
      }
      return gradeDrive(sent, readings);
    };
    for (const lag of [0, 50_000]) {
      const g = exact('steps', lag);
      expect(check(g, 'values')?.verdict, `${lag}`).toBe('pass');
      expect(check(g, 'latency')?.verdict, `${lag}`).toBe('pass');
    }
    expect(check(exact('steps', 100_000), 'latency')?.verdict).toBe('fail');
    // Stuck in RXLOSS after the first silence; or never live at all.
    expect(
      check(
        exact('dropouts', 0, (t, on) => t > 3.2e6 || !on),
        'failsafe',
      )?.verdict,
    ).toBe('fail');
    expect(
      check(
        exact('dropouts', 0, () => true),
        'failsafe',
      ),
    ).toMatchObject({ verdict: 'fail', found: expect.stringMatching(/never reported the receiver live/) });
    expect(check(exact('dropouts', 0), 'failsafe')?.verdict).toBe('pass');
    // Exact by §9 whatever the frames look like: it holds still through every built-in.
    for (const s of builtinScenarios({ system: 0xb2, remote: 'internal', channels: 12 }))
      expect(check(exact(s.name, 20_000), 'steady')?.verdict, s.name).not.toBe('fail');
  });

  it('fails a flight controller whose value jumps while nothing sent moves, and one that drops the receiver while frames come', () => {
    const scenario = builtinScenarios({ system: 0xb2, remote: 'internal', channels: 4 }).find((x) => x.name === 'fades') as DriveScenario;
    const player = new DrivePlayer(scenario);
    const sent = player.writesUntil(Number.POSITIVE_INFINITY);
    const end = sent.at(-1)?.atUs ?? 0;
    const readings = (glitchAtUs: number, lostAtUs: number): FcReading[] => {
      const out: FcReading[] = [];
      for (let t = 0; t < end; t += 20_000) {
        const roll = Math.abs(t - glitchAtUs) < 10_000 ? 1800 : 1500;
        out.push({ atUs: t, channels: [roll, 1500, 1500, 1101], rxLoss: t < 600_000 || Math.abs(t - lostAtUs) < 10_000 });
      }
      return out;
    };
    expect(check(gradeDrive(sent, readings(-1e9, -1e9), undefined, player.steps), 'steady')?.verdict).toBe('pass');
    const jump = check(gradeDrive(sent, readings(4e6, -1e9), undefined, player.steps), 'steady');
    expect(jump).toMatchObject({
      verdict: 'fail',
      found: expect.stringMatching(
        /^1 reading of a value never sent: its channel 1 read 1800 µs and 1500 µs for one value sent \(1×, first at 4\.0 s \(/,
      ),
    });
    const lost = check(gradeDrive(sent, readings(-1e9, 4e6), undefined, player.steps), 'steady');
    expect(lost).toMatchObject({
      verdict: 'fail',
      found: expect.stringMatching(
        /receiver reported lost 1 time while frames had come for a second with no gap over 50 ms, first at 4\.0 s/,
      ),
    });
  });

  it('says unknown where the flight controller tells nothing', () => {
    const { sent, readings } = drive('dropouts', { resolution: 2048 });
    const g = gradeDrive(
      sent,
      readings.map((r) => ({ ...r, rxLoss: null })),
    );
    expect(check(g, 'failsafe')?.verdict).toBe('unknown');
    expect(gradeDrive(sent, []).checks.map((c) => c.verdict)).toEqual(['unknown', 'unknown', 'unknown', 'unknown', 'unknown']);
  });
});
