/**
 * The built-in drive scenarios, made for the receiver the user chose (its system, remote and
 * channel count): each channel swept and stepped, dropouts short of a hold, of a failsafe and
 * long, the fade counter moving and wrapping, a system byte that lies, empty slots, X-Plus,
 * VTX frames, damaged frames and noise between frames, a switch from 22 to 11 ms, a rebind to
 * another format. Sticks rest at centre and the throttle low unless a step moves them.
 */
import { CHANNEL_NAMES, SYSTEM_DSM2_22MS_1024, SYSTEM_DSMX_11MS_2048, SYSTEM_DSMX_22MS_2048, systemInfo } from '../decoder/spec.js';
import type { ChannelMotion, Scenario } from '../simulator/scenario.js';
import type { DriveScenario, DriveStep } from './scenario.js';

/** The receiver a built-in scenario is made for. */
export interface DriveReceiver {
  /** §8.3 system byte of the protocol in use (0x01, 0x12, 0xA2, 0xB2). */
  system: number;
  remote: 'internal' | 'external';
  /** Ordinary channels 1–12. */
  channels: number;
}

const S = 1_000_000;
/** Throttle (channel 0) rests low, every other channel at centre. */
const REST: readonly ChannelMotion[] = Array.from({ length: 20 }, (_, id) => ({ kind: 'fixed', percent: id === 0 ? -100 : 0 }) as const);

/** `base`'s receiver with sticks at rest except `moves`, no random loss or fades (a scenario adds what it checks). */
function receiver(base: DriveReceiver, over: Partial<Scenario> = {}, moves: Record<number, ChannelMotion> = {}): Scenario {
  const motion: Record<number, ChannelMotion> = { ...REST, ...moves };
  return { system: base.system, remote: base.remote, channels: base.channels, fades: { lossRate: 0, randomRate: 0 }, ...over, motion };
}

function step(note: string, seconds: number, rx?: Scenario): DriveStep {
  return rx === undefined ? { note, durationUs: seconds * S } : { note, durationUs: seconds * S, receiver: rx };
}

/** The user's own sticks (sliders, keys, a gamepad: `DrivePlayer.setChannel`) over a receiver at rest, for up to an hour. */
export function manualScenario(base: DriveReceiver): DriveScenario {
  if (systemInfo(base.system) === undefined) throw new TypeError(`system must be 0x01, 0x12, 0xA2 or 0xB2, got ${base.system}`);
  return {
    name: 'manual',
    title: 'The sticks as the page sets them: sliders, keys or a gamepad.',
    steps: [step('Sticks from the page', 3600, receiver(base))],
  };
}

/** Every built-in scenario for `base`, in the order the page lists them. */
export function builtinScenarios(base: DriveReceiver): DriveScenario[] {
  const info = systemInfo(base.system);
  if (info === undefined) throw new TypeError(`system must be 0x01, 0x12, 0xA2 or 0xB2, got ${base.system}`);
  const ids = Array.from({ length: base.channels }, (_, id) => id);
  const fadeStart = base.remote === 'internal' ? 250 : 65_530;
  const other = info.resolution === 2048 ? SYSTEM_DSM2_22MS_1024 : SYSTEM_DSMX_11MS_2048;
  const internal: DriveReceiver = { ...base, remote: 'internal' };
  return [
    {
      name: 'sweep',
      title: 'Each channel swept over its whole stick range in turn: the order and scale the flight controller reads.',
      steps: [
        step('All sticks at rest', 2, receiver(base)),
        ...ids.map((id) =>
          step(
            `${CHANNEL_NAMES[id]} swept −100 % to +100 % and back`,
            4,
            receiver(base, {}, { [id]: { kind: 'sine', amplitude: 100, periodUs: 4 * S, phase: -Math.PI / 2 } }),
          ),
        ),
      ],
    },
    {
      name: 'steps',
      title: 'Each channel stepped from −100 % to +100 % and back: how long the flight controller takes to follow.',
      steps: ids.map((id) =>
        step(
          `${CHANNEL_NAMES[id]} stepped, 1 s a level`,
          3,
          receiver(base, {}, { [id]: { kind: 'steps', levels: [-100, 100, -100], holdUs: S } }),
        ),
      ),
    },
    {
      name: 'dropouts',
      title: 'The receiver goes silent for 100 ms, 1.2 s and 5 s: hold, failsafe and recovery.',
      steps: [
        step(
          'Dropouts of 100 ms at 3 s, 1.2 s at 6 s and 5 s at 10 s',
          17,
          receiver(base, {
            dropouts: [
              { atUs: 3 * S, durationUs: 0.1 * S },
              { atUs: 6 * S, durationUs: 1.2 * S },
              { atUs: 10 * S, durationUs: 5 * S },
            ],
          }),
        ),
      ],
    },
    {
      name: 'fades',
      title: 'The fade counter moves without frames lost, then frames are lost as it wraps.',
      steps: [
        step('Fades counted, every frame arrives', 5, receiver(base, { fades: { lossRate: 0, randomRate: 0.05 } })),
        step('Frames lost while the counter wraps', 5, receiver(base, { fades: { start: fadeStart, lossRate: 0.03, randomRate: 0 } })),
      ],
    },
    {
      name: 'lying-system-byte',
      title: 'An internal remote whose system byte says the other resolution than its data has.',
      steps: [
        step(
          '1024 data (DSM2 22 ms) under system byte 0xB2',
          5,
          receiver({ ...internal, system: SYSTEM_DSM2_22MS_1024 }, { systemByte: SYSTEM_DSMX_11MS_2048 }),
        ),
        step(
          '2048 data (DSMX 11 ms) under system byte 0x01',
          5,
          receiver({ ...internal, system: SYSTEM_DSMX_11MS_2048 }, { systemByte: SYSTEM_DSM2_22MS_1024 }),
        ),
      ],
    },
    {
      name: 'empty-slots',
      title: 'Frames with 0xFFFF slots (4 channels at 22 ms), then all 12 channels in frame pairs.',
      steps: [
        step('4 channels: three empty slots a frame', 5, receiver({ ...base, system: SYSTEM_DSMX_22MS_2048, channels: 4 })),
        step('12 channels in pairs of frames', 5, receiver({ ...base, system: SYSTEM_DSMX_22MS_2048, channels: 12 })),
      ],
    },
    {
      name: 'xplus',
      title: 'X-Plus channels 12–19 in the 7th slot, each at its own level.',
      steps: [
        step(
          'DSMX 11 ms, 12 channels and 8 X-Plus',
          6,
          receiver(
            { ...base, system: SYSTEM_DSMX_11MS_2048, channels: 12 },
            { xplus: 8 },
            Object.fromEntries(Array.from({ length: 8 }, (_, k) => [12 + k, { kind: 'fixed', percent: -100 + 25 * k } as const])),
          ),
        ),
      ],
    },
    {
      name: 'vtx',
      title: 'VTX control frames in bursts among the channel frames: the channels must not jump.',
      steps: [
        step(
          'A VTX burst every second',
          6,
          receiver(base, {
            vtx: {
              everyUs: S,
              settings: [
                { band: 1, channel: 3, power: 2, region: 0, pit: false },
                { band: 4, channel: 7, power: 1, region: 1, pit: true },
              ],
            },
          }),
        ),
      ],
    },
    {
      name: 'damage',
      title: 'Frames cut short and noise bytes between frames: each damaged frame dropped, none misread.',
      steps: [
        step(
          '5 % of frames truncated, noise after 20 %',
          10,
          receiver(base, { damage: { truncateRate: 0.05, noiseRate: 0.2, noiseMaxBytes: 6 } }),
        ),
      ],
    },
    {
      name: 'period-switch',
      title: 'The link switches from 22 ms to 11 ms frames without a break.',
      steps: [
        step('DSMX 22 ms', 5, receiver({ ...base, system: SYSTEM_DSMX_22MS_2048 })),
        step('DSMX 11 ms', 5, receiver({ ...base, system: SYSTEM_DSMX_11MS_2048 })),
      ],
    },
    {
      name: 'rebind',
      title: 'A rebind: the receiver goes silent, then comes back in the other resolution.',
      steps: [
        step('As bound', 5, receiver(base)),
        step('Silent while it rebinds', 1.5),
        step(
          `Back as ${systemInfo(other)?.name ?? ''}`,
          5,
          receiver({ ...base, system: other, channels: Math.min(base.channels, other === SYSTEM_DSM2_22MS_1024 ? 7 : 12) }),
        ),
      ],
    },
  ];
}
