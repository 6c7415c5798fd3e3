/** Drive's sticks from the keyboard and a gamepad (src/app/components/Drive/sticks.ts): what each says a channel should be. */
import { describe, expect, it } from 'vitest';
import {
  axisPercent,
  changed,
  DEFAULT_MAPPING,
  type GamepadMapping,
  gamepadChannels,
  keyboardStep,
  loadMapping,
  MAPPING_KEY,
  saveMapping,
  stickKey,
} from '../src/app/components/Drive/sticks.js';

const pad = (axes: number[], pressed: number[] = []) => ({
  axes,
  buttons: Array.from({ length: 16 }, (_, i) => ({ value: pressed.includes(i) ? 1 : 0, pressed: pressed.includes(i) })),
});

describe('keyboard sticks', () => {
  it('moves a stick while its key is held, springs the others back to centre, and leaves the throttle where it is', () => {
    expect(stickKey('W')).toBe('w');
    expect(stickKey('ArrowUp')).toBe('ArrowUp');
    expect(stickKey(' ')).toBeNull();
    expect(stickKey('Escape')).toBeNull();
    let s = keyboardStep({ 0: -100, 1: 0 }, new Set(['w', 'ArrowRight']), 100);
    s = keyboardStep(s, new Set(['w', 'ArrowRight']), 50);
    expect(s[0]).toBe(-70);
    expect(s[1]).toBe(30);
    // A frame late by seconds moves a stick no more than a tenth of a second's worth.
    expect(keyboardStep({ 2: 0 }, new Set(['ArrowUp']), 5000)[2]).toBe(20);
    // Let go: the aileron comes back, the throttle stays.
    s = keyboardStep(s, new Set(), 100);
    expect(s[0]).toBe(-70);
    expect(s[1]).toBe(10);
    s = keyboardStep(s, new Set(), 100);
    expect(s[1]).toBe(0);
    // Held long: the end of travel, never past.
    expect(keyboardStep({ 0: 90 }, new Set(['w']), 100)[0]).toBe(100);
    expect(keyboardStep({ 3: 0 }, new Set(['a']), 100)[3]).toBe(-20);
  });
});

describe('gamepad sticks', () => {
  it('maps axes by the standard layout: left stick throttle (up: more) and rudder, right stick aileron and elevator', () => {
    const v = gamepadChannels(pad([0.5, -1, -0.25, 1]), DEFAULT_MAPPING);
    expect(v).toEqual({ 0: 100, 1: -21, 2: -100, 3: 47 });
  });

  it('reads a deadband around the centre as the centre, and a centre away from 0 as the centre', () => {
    expect(axisPercent(0.04, 0, 0.05)).toBe(0);
    expect(axisPercent(1, 0, 0.05)).toBe(100);
    expect(axisPercent(-1, 0, 0.05)).toBe(-100);
    // A transmitter whose stick rests at 0.1: 0.1 is the centre, each end still the end.
    expect(axisPercent(0.1, 0.1, 0)).toBe(0);
    expect(axisPercent(1, 0.1, 0)).toBe(100);
    expect(axisPercent(-1, 0.1, 0)).toBe(-100);
    expect(axisPercent(-0.45, 0.1, 0)).toBe(-50);
    expect(axisPercent(Number.NaN, 0, 0)).toBe(0);
  });

  it('takes buttons as one end or the other, inverted where set, and leaves out what the pad lacks', () => {
    const m: GamepadMapping = {
      channels: {
        4: { kind: 'button', index: 0, invert: false },
        5: { kind: 'button', index: 1, invert: true },
        6: { kind: 'axis', index: 9, invert: false },
      },
      centres: {},
      deadband: 0,
    };
    expect(gamepadChannels(pad([0, 0], [0]), m)).toEqual({ 4: 100, 5: 100 });
    expect(gamepadChannels(pad([0, 0], [1]), m)).toEqual({ 4: -100, 5: -100 });
  });

  it('keeps the mapping in storage, and reads the default where what is kept is no mapping', () => {
    const kept = new Map<string, string>();
    const storage = { getItem: (k: string) => kept.get(k) ?? null, setItem: (k: string, v: string) => void kept.set(k, v) };
    expect(loadMapping(storage)).toEqual(DEFAULT_MAPPING);
    const m: GamepadMapping = { channels: { 0: { kind: 'axis', index: 2, invert: true } }, centres: { 2: -0.1 }, deadband: 0.1 };
    saveMapping(storage, m);
    expect(loadMapping(storage)).toEqual(m);
    kept.set(MAPPING_KEY, '{"channels": {"0": {"kind": "wheel", "index": 1}, "1": {"kind": "axis", "index": 1}}, "deadband": 3}');
    expect(loadMapping(storage)).toEqual({ channels: { 1: { kind: 'axis', index: 1, invert: false } }, centres: {}, deadband: 0.05 });
    kept.set(MAPPING_KEY, 'not json');
    expect(loadMapping(storage)).toEqual(DEFAULT_MAPPING);
    expect(loadMapping(undefined)).toEqual(DEFAULT_MAPPING);
  });

  it('sends only the channels whose whole-% value changed', () => {
    expect(changed({ 0: -100, 1: 10 }, { 0: -100.2, 1: 12, 2: 0 })).toEqual([
      [1, 12],
      [2, 0],
    ]);
  });
});
