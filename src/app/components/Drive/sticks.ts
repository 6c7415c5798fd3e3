/**
 * Sticks from the keyboard and a gamepad, for Drive's manual mode: what each source says a
 * channel should be, in % of travel (−100 … 100), with no DOM in here (the panel polls the
 * keyboard's held keys and `navigator.getGamepads()` on requestAnimationFrame and sends the
 * values through the held-sticks path; the worker's player bounds the throttle by the ceiling
 * whatever the source, and the page shows it bounded).
 *
 * Channel ids are the receiver's (spec §8.5): 0 throttle, 1 aileron, 2 elevator, 3 rudder.
 */

/** The keyboard's sticks, mode 2: W/S throttle, A/D rudder (left stick); arrows elevator and aileron (right stick). */
export const KEY_MAP: readonly { key: string; label: string; id: number; direction: 1 | -1 }[] = [
  { key: 'w', label: 'W', id: 0, direction: 1 },
  { key: 's', label: 'S', id: 0, direction: -1 },
  { key: 'd', label: 'D', id: 3, direction: 1 },
  { key: 'a', label: 'A', id: 3, direction: -1 },
  { key: 'ArrowRight', label: '→', id: 1, direction: 1 },
  { key: 'ArrowLeft', label: '←', id: 1, direction: -1 },
  { key: 'ArrowUp', label: '↑', id: 2, direction: 1 },
  { key: 'ArrowDown', label: '↓', id: 2, direction: -1 },
];

/** How fast a held key moves its stick, % of travel per second (the whole travel in 1 s). */
export const KEY_RATE_PERCENT_PER_S = 200;

/** The key a KeyboardEvent names in `KEY_MAP` terms (letters either case), or null when it moves no stick. */
export function stickKey(key: string): string | null {
  const k = key.length === 1 ? key.toLowerCase() : key;
  return KEY_MAP.some((m) => m.key === k) ? k : null;
}

/**
 * The keyboard's sticks after `dtMs` with `down` held: a held key moves its stick at
 * `KEY_RATE_PERCENT_PER_S`; a stick whose keys are up springs back to centre at that rate,
 * except the throttle (channel 0), which stays where it was left, as on a transmitter.
 */
export function keyboardStep(now: Record<number, number>, down: ReadonlySet<string>, dtMs: number): Record<number, number> {
  const next: Record<number, number> = { ...now };
  const step = (KEY_RATE_PERCENT_PER_S * Math.max(0, Math.min(dtMs, 100))) / 1000;
  for (const id of [0, 1, 2, 3]) {
    let push = 0;
    for (const m of KEY_MAP) if (m.id === id && down.has(m.key)) push += m.direction;
    const v = next[id] ?? (id === 0 ? -100 : 0);
    if (push !== 0) next[id] = clamp(v + push * step);
    else if (id !== 0 && v !== 0) next[id] = Math.abs(v) <= step ? 0 : v - Math.sign(v) * step;
    else next[id] = v;
  }
  return next;
}

/** Where a channel takes a gamepad's input: an axis or a button, inverted or not. */
export interface GamepadSource {
  kind: 'axis' | 'button';
  index: number;
  invert: boolean;
}

/** A gamepad mapping: a source per channel id (none: the channel is not the gamepad's), each axis's centre, and the deadband. */
export interface GamepadMapping {
  channels: Record<number, GamepadSource>;
  /** Each axis's value at rest (−1 … 1), as "Set centre" read it; an axis not here rests at 0. */
  centres: Record<number, number>;
  /** Around the centre, this much of an axis's travel (0 … 0.5) reads as the centre. */
  deadband: number;
}

/**
 * A standard-mapping gamepad (https://w3c.github.io/gamepad/#remapping), mode 2: the left stick
 * throttle (up: more) and rudder, the right stick aileron and elevator (up: more). The Gamepad
 * API's Y axes grow downwards, hence inverted. A transmitter in joystick mode often puts its
 * channels on axes 0–3 in its own order: set them in the mapping.
 */
export const DEFAULT_MAPPING: GamepadMapping = {
  channels: {
    0: { kind: 'axis', index: 1, invert: true },
    1: { kind: 'axis', index: 2, invert: false },
    2: { kind: 'axis', index: 3, invert: true },
    3: { kind: 'axis', index: 0, invert: false },
  },
  centres: {},
  deadband: 0.05,
};

/** What a gamepad gives (the part of the Gamepad API read here). */
export interface PadState {
  axes: readonly number[];
  buttons: readonly { value: number; pressed: boolean }[];
}

const clamp = (v: number) => Math.max(-100, Math.min(100, v));

/** An axis's value (−1 … 1) as % of travel: from its centre to each end is the whole half of travel, the deadband around the centre reads 0. */
export function axisPercent(raw: number, centre: number, deadband: number): number {
  if (!Number.isFinite(raw)) return 0;
  const c = Math.max(-0.9, Math.min(0.9, Number.isFinite(centre) ? centre : 0));
  const d = Math.max(0, Math.min(0.5, deadband));
  const v = raw >= c ? (raw - c) / (1 - c) : (raw - c) / (1 + c);
  const a = Math.abs(v);
  if (a <= d) return 0;
  return clamp((Math.sign(v) * (Math.min(1, a) - d) * 100) / (1 - d));
}

/** What the gamepad says of each mapped channel, % of travel (integers, as the sliders give); a source the pad lacks is left out. */
export function gamepadChannels(pad: PadState, mapping: GamepadMapping): Record<number, number> {
  const out: Record<number, number> = {};
  for (const [key, src] of Object.entries(mapping.channels)) {
    let v: number | undefined;
    if (src.kind === 'axis') {
      const raw = pad.axes[src.index];
      if (raw !== undefined) v = axisPercent(raw, mapping.centres[src.index] ?? 0, mapping.deadband);
    } else {
      const b = pad.buttons[src.index];
      // An analog button (a trigger) is its value along the travel; a plain one is an end or the other.
      if (b !== undefined) v = clamp((Number.isFinite(b.value) ? b.value : b.pressed ? 1 : 0) * 200 - 100);
    }
    if (v !== undefined) out[Number(key)] = Math.round(src.invert ? -v : v) + 0;
  }
  return out;
}

/** Where the page keeps the gamepad mapping. */
export const MAPPING_KEY = 'satscope.drive.gamepad';

/** The mapping kept in `storage` (the default where none is kept, or what is kept is not a mapping). */
export function loadMapping(storage: Pick<Storage, 'getItem'> | undefined): GamepadMapping {
  try {
    const text = storage?.getItem(MAPPING_KEY);
    if (text === null || text === undefined) return DEFAULT_MAPPING;
    const m = JSON.parse(text) as Partial<GamepadMapping>;
    const channels: Record<number, GamepadSource> = {};
    for (const [k, s] of Object.entries(m.channels ?? {})) {
      const id = Number(k);
      if (!Number.isInteger(id) || id < 0 || id > 11) continue;
      if ((s.kind !== 'axis' && s.kind !== 'button') || !Number.isInteger(s.index) || s.index < 0) continue;
      channels[id] = { kind: s.kind, index: s.index, invert: s.invert === true };
    }
    const centres: Record<number, number> = {};
    for (const [k, c] of Object.entries(m.centres ?? {})) if (Number.isFinite(c) && Math.abs(c) <= 1) centres[Number(k)] = c;
    const deadband = typeof m.deadband === 'number' && m.deadband >= 0 && m.deadband <= 0.5 ? m.deadband : DEFAULT_MAPPING.deadband;
    return { channels, centres, deadband };
  } catch {
    return DEFAULT_MAPPING;
  }
}

/** Keeps `mapping` in `storage` (a full or refused storage keeps nothing). */
export function saveMapping(storage: Pick<Storage, 'setItem'> | undefined, mapping: GamepadMapping): void {
  try {
    storage?.setItem(MAPPING_KEY, JSON.stringify(mapping));
  } catch {
    // Private mode or full: the mapping lasts the session.
  }
}

/** The changes from `before` to `after` (channels whose whole-% value differs), to send as held sticks. */
export function changed(before: Record<number, number>, after: Record<number, number>): [number, number][] {
  const out: [number, number][] = [];
  for (const [k, v] of Object.entries(after)) if (Math.round(before[Number(k)] ?? Number.NaN) !== Math.round(v)) out.push([Number(k), v]);
  return out;
}
