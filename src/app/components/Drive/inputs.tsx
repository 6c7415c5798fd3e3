/**
 * The keyboard and a gamepad as Drive's sticks: polled on requestAnimationFrame, each change sent
 * as a held stick (the same path as the sliders). The keyboard's map is shown; the gamepad's is
 * the user's (which axis or button drives which channel, inverted or not, its centre and a
 * deadband) and the page keeps it (localStorage). The throttle ceiling bounds them as it does the
 * sliders (the worker's player applies it to whatever holds channel 0).
 */
import { useEffect, useRef, useState } from 'preact/hooks';
import { CHANNEL_NAMES } from '../../../decoder/spec.js';
import {
  changed,
  DEFAULT_MAPPING,
  type GamepadMapping,
  type GamepadSource,
  gamepadChannels,
  KEY_MAP,
  keyboardStep,
  loadMapping,
  type PadState,
  saveMapping,
  stickKey,
} from './sticks.js';

/** How often the gamepad's live values are shown (the sticks themselves go every animation frame), ms. */
const SHOW_EVERY_MS = 100;

const storage = (): Storage | undefined => (typeof localStorage === 'undefined' ? undefined : localStorage);

/** The first gamepad the browser lists (null: none, or the browser has none yet: a pad shows once a button is pressed). */
function firstPad(): Gamepad | null {
  if (typeof navigator === 'undefined' || typeof navigator.getGamepads !== 'function') return null;
  for (const p of navigator.getGamepads()) if (p !== null && p.connected !== false) return p;
  return null;
}

/** Whether a key press belongs to the element focused (typing in a field, choosing in a list), not the sticks. */
function typing(target: EventTarget | null): boolean {
  const el = target as HTMLElement | null;
  if (el === null || typeof el.closest !== 'function') return false;
  return el.closest('input:not([type="checkbox"]):not([type="range"]), select, textarea, [contenteditable="true"]') !== null;
}

export function StickSources({
  channels,
  driving,
  held,
  ceiling,
  onHold,
}: {
  channels: number;
  driving: boolean;
  /** The sticks held now (% by channel id), read each frame. */
  held: { current: Record<number, number> };
  ceiling: number;
  /** A channel held at `percent` from the next frame on; null gives it back to the scenario. */
  onHold(id: number, percent: number | null): void;
}) {
  const [keyboard, setKeyboard] = useState(false);
  const [gamepad, setGamepad] = useState(false);
  const [mapping, setMapping] = useState<GamepadMapping>(() => loadMapping(storage()));
  const [pad, setPad] = useState<{ id: string; axes: number; buttons: number; values: Record<number, number> } | null>(null);
  const down = useRef(new Set<string>());
  const live = useRef({ mapping, onHold, driving });
  live.current = { mapping, onHold, driving };

  const remap = (m: GamepadMapping) => {
    setMapping(m);
    saveMapping(storage(), m);
  };

  // The keys held, while the keyboard is a stick source and a drive runs (Escape and Space stay the stop).
  useEffect(() => {
    if (!keyboard || !driving) return;
    const keyDown = (e: KeyboardEvent) => {
      const k = stickKey(e.key);
      if (k === null || typing(e.target) || e.ctrlKey || e.metaKey || e.altKey) return;
      e.preventDefault();
      down.current.add(k);
    };
    const keyUp = (e: KeyboardEvent) => {
      const k = stickKey(e.key);
      if (k !== null) down.current.delete(k);
    };
    const blur = () => down.current.clear();
    document.addEventListener('keydown', keyDown);
    document.addEventListener('keyup', keyUp);
    window.addEventListener('blur', blur);
    return () => {
      document.removeEventListener('keydown', keyDown);
      document.removeEventListener('keyup', keyUp);
      window.removeEventListener('blur', blur);
      down.current.clear();
    };
  }, [keyboard, driving]);

  // One loop for both: each animation frame, what the keys and the gamepad say, sent where it changed.
  useEffect(() => {
    if (!keyboard && !gamepad) return;
    let raf = 0;
    let last = performance.now();
    let shown = 0;
    /** The keyboard's sticks, and which of them the keys have moved (the others stay the scenario's). */
    let keys: Record<number, number> = {};
    const touched = new Set<number>();
    /** The channels the gamepad holds: given back to the scenario (sticks at rest, throttle low) if the pad goes. */
    let padHeld: number[] = [];
    const tick = (t: number) => {
      const dt = t - last;
      last = t;
      const { mapping: m, onHold: hold, driving: on } = live.current;
      const want: Record<number, number> = {};
      if (keyboard && on) {
        for (const k of down.current) for (const e of KEY_MAP) if (e.key === k && !touched.has(e.id)) touched.add(e.id);
        if (touched.size > 0) {
          const from: Record<number, number> = {};
          for (const id of touched) from[id] = keys[id] ?? held.current[id] ?? (id === 0 ? -100 : 0);
          keys = keyboardStep(from, down.current, dt);
          for (const id of touched) want[id] = keys[id] as number;
        }
      }
      if (gamepad) {
        const p = firstPad();
        if (p !== null) {
          const state: PadState = { axes: p.axes, buttons: p.buttons };
          const values = gamepadChannels(state, m);
          Object.assign(want, values);
          padHeld = Object.keys(values).map(Number);
          if (t - shown >= SHOW_EVERY_MS) {
            shown = t;
            setPad({ id: p.id, axes: p.axes.length, buttons: p.buttons.length, values });
          }
        } else {
          // Unplugged (or its transmitter off) mid-drive: its channels are not left where it last had them.
          for (const id of padHeld) hold(id, null);
          padHeld = [];
          if (t - shown >= SHOW_EVERY_MS) {
            shown = t;
            setPad(null);
          }
        }
      }
      for (const [id, v] of changed(held.current, want)) hold(id, Math.round(v));
      raf = requestAnimationFrame(tick);
    };
    raf = requestAnimationFrame(tick);
    return () => cancelAnimationFrame(raf);
  }, [keyboard, gamepad, held]);

  const setSource = (id: number, value: string, invert: boolean) => {
    const next = { ...mapping.channels };
    if (value === '') delete next[id];
    else {
      const [kind, index] = value.split(':');
      next[id] = { kind: kind === 'button' ? 'button' : 'axis', index: Number(index), invert };
    }
    remap({ ...mapping, channels: next });
  };
  const axes = Math.max(pad?.axes ?? 0, 4);
  const buttons = Math.max(pad?.buttons ?? 0, 16);
  const sourceValue = (s: GamepadSource | undefined) => (s === undefined ? '' : `${s.kind}:${s.index}`);
  const keyNames = (id: number) =>
    KEY_MAP.filter((k) => k.id === id)
      .map((k) => k.label)
      .join(' / ');
  return (
    <div class="drive-inputs">
      <fieldset class="drive-keys">
        <legend>
          <label>
            <input type="checkbox" checked={keyboard} onChange={(e) => setKeyboard((e.currentTarget as HTMLInputElement).checked)} />
            Keyboard sticks
          </label>
        </legend>
        <table class="drive-keymap" aria-label="Keyboard sticks">
          <tbody>
            {[0, 3, 2, 1].map((id) => (
              <tr key={id}>
                <th>
                  <kbd>{keyNames(id)}</kbd>
                </th>
                <td>
                  {CHANNEL_NAMES[id]}
                  {id === 0 ? ' (stays where you leave it)' : ' (back to centre when let go)'}
                </td>
              </tr>
            ))}
          </tbody>
        </table>
        <p class="drive-note">
          While a drive runs and the focus is not in a field. <kbd>Esc</kbd> or <kbd>Space</kbd> stops.
        </p>
      </fieldset>
      <fieldset class="drive-pad">
        <legend>
          <label>
            <input type="checkbox" checked={gamepad} onChange={(e) => setGamepad((e.currentTarget as HTMLInputElement).checked)} />
            Gamepad or transmitter (joystick mode)
          </label>
        </legend>
        <p class="drive-note" data-testid="drive-pad-state">
          {!gamepad
            ? 'Its mapping is kept in this browser.'
            : pad === null
              ? 'No gamepad yet: plug it in and press a button on it (browsers show one only once it is used).'
              : `${pad.id}: ${pad.axes} axes, ${pad.buttons} buttons.`}
        </p>
        <div class="table-scroll" tabIndex={0} role="region" aria-label="Gamepad mapping">
          <table class="drive-padmap">
            <thead>
              <tr>
                <th>Channel</th>
                <th>From</th>
                <th>Inverted</th>
                <th>Now</th>
              </tr>
            </thead>
            <tbody>
              {Array.from({ length: channels }, (_, id) => {
                const s = mapping.channels[id];
                const now = pad?.values[id];
                return (
                  <tr key={id}>
                    <th>{CHANNEL_NAMES[id]}</th>
                    <td>
                      <select
                        aria-label={`${CHANNEL_NAMES[id]} from`}
                        value={sourceValue(s)}
                        onChange={(e) => setSource(id, (e.currentTarget as HTMLSelectElement).value, s?.invert ?? false)}
                      >
                        <option value="">—</option>
                        {Array.from({ length: axes }, (_, i) => (
                          <option key={`a${i}`} value={`axis:${i}`}>
                            axis {i}
                          </option>
                        ))}
                        {Array.from({ length: buttons }, (_, i) => (
                          <option key={`b${i}`} value={`button:${i}`}>
                            button {i}
                          </option>
                        ))}
                      </select>
                    </td>
                    <td>
                      <input
                        type="checkbox"
                        aria-label={`${CHANNEL_NAMES[id]} inverted`}
                        checked={s?.invert ?? false}
                        disabled={s === undefined}
                        onChange={(e) => setSource(id, sourceValue(s), (e.currentTarget as HTMLInputElement).checked)}
                      />
                    </td>
                    <td class="num">{now === undefined ? '' : `${id === 0 ? Math.min(now, ceiling) : now} %`}</td>
                  </tr>
                );
              })}
            </tbody>
          </table>
        </div>
        <div class="drive-go">
          <label>
            Deadband
            <input
              type="number"
              min={0}
              max={50}
              value={Math.round(mapping.deadband * 100)}
              onChange={(e) => {
                const v = Number((e.currentTarget as HTMLInputElement).value);
                if (Number.isFinite(v)) remap({ ...mapping, deadband: Math.max(0, Math.min(50, v)) / 100 });
              }}
            />
            %
          </label>
          <button
            type="button"
            disabled={pad === null}
            title="Let the sticks rest, then read where each axis rests as its centre"
            onClick={() => {
              const p = firstPad();
              if (p !== null) remap({ ...mapping, centres: Object.fromEntries(p.axes.map((v, i) => [i, v])) });
            }}
          >
            Set centre
          </button>
          <button type="button" class="link" onClick={() => remap(DEFAULT_MAPPING)}>
            Default mapping
          </button>
        </div>
      </fieldset>
    </div>
  );
}
