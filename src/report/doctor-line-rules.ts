/**
 * The doctor's rules about the line itself: nothing arrives, or what arrives is not a satellite
 * (another protocol, an inverted line, another speed, noise, an overrun), over the last 3 s.
 */
import { classifyLine, PACKET_KINDS, type LineVerdict, type PacketKind } from './doctor-line.js';
import { foreignSettings, PROTOCOL_SETTINGS, type ForeignProtocol } from './doctor-stacks.js';
import {
  dur,
  LINE_WINDOW_BINS,
  lineWindow,
  M_BREAKS,
  M_BYTES,
  M_CHAR_ERRORS,
  M_FF,
  M_FRAME_BYTES,
  M_OVERRUNS,
  M_PACKETS,
  M_TEXT,
  M_ZERO,
  NOTHING_AFTER_US,
  NOTHING_CERTAIN_US,
  UNKNOWN_AFTER_US,
  type PortState,
} from './doctor-state.js';
import type { AddFinding, Confidence, ConfirmProbe, Evidence, RuleContext } from './doctor-types.js';
import { formatDuration, noFramesHint, plural } from './report-text.js';
import { absencesUntil } from './absences.js';

export const NOTHING_TODO = [
  'Transmitter off, or the satellite not bound to this transmitter and model memory (most common). Satellite LED off: it has power but no link. Turn the transmitter on with the right model; if the LED stays off, bind again.',
  'The satellite is in bind mode. LED blinking fast: bind it now (transmitter in bind), or power-cycle it without bind pulses to leave bind mode.',
  "DATA does not reach the adapter. LED solid (linked) but nothing arrives: grey wire (DATA) to the adapter's RX, not TX; check the connector is not reversed.",
  "No common ground. LED solid, DATA on RX, still nothing: connect black (GND) to the adapter's GND.",
  'No power. LED never lights, not even for a moment at power-up: 3.3 V on orange (pin 1), GND on black; never 5 V on a satellite.',
];

const UART_115200 = '115200 8N1';

/** How each protocol's packets are recognised, and the line setting its bytes are sent at. */
const PACKET_SHAPES: Readonly<Record<PacketKind, { what: string; setting: string }>> = {
  ibus: { what: '32-byte packets starting 0x20 0x40 with valid checksums', setting: UART_115200 },
  srxl2: { what: 'packets starting 0xA6 with valid CRCs', setting: UART_115200 },
  'srxl-v1': { what: '18-byte packets starting 0xA5 with valid CRCs', setting: UART_115200 },
  crsf: { what: 'packets starting 0xC8 (or 0xEE, 0xEA) with a length and a valid CRC-8', setting: '420000 8N1' },
  sbus: { what: '25-byte packets from 0x0F to 0x00, one after another', setting: '100000 8E2, inverted' },
  fport: { what: 'frames between 0x7E flags with valid checksums', setting: '115200 8N1, inverted' },
  ghst: { what: 'packets starting with a Ghost address (0x80–0x8A), a length and a valid CRC-8', setting: '420000 8N1' },
};

export function nothingFindings(p: PortState, now: number, add: AddFinding): void {
  if (!Number.isFinite(p.openUs) || p.activity > 0) return;
  const silent = now - p.openUs;
  if (silent < NOTHING_AFTER_US) return;
  add({
    code: 'nothing-arrives',
    ports: [p.port],
    severity: 'problem',
    confidence: silent >= NOTHING_CERTAIN_US ? 'certain' : 'likely',
    title: `${p.label}: nothing arrives`,
    evidence: [
      {
        text: `No byte and no line error in ${dur(silent)} since the port opened at ${p.baudRate} baud; a satellite with a link sends a frame every 11 or 22 ms, and nothing at all without one (spec §7.1).`,
        timeUs: p.openUs,
      },
    ],
    todo: NOTHING_TODO,
    settings: [],
    confirm: null,
    sinceUs: p.openUs + NOTHING_AFTER_US,
  });
}

/**
 * The port's adapter went away ("device lost", live or recorded) and, until its data came
 * back, nothing could be seen: said with the report's figures (`absences.ts`), and what makes
 * an adapter drop off USB when nobody unplugged it.
 */
export function adapterAwayFinding(p: PortState, now: number, ctx: RuleContext, add: AddFinding): void {
  const a = absencesUntil(p.away, now);
  if (a.count === 0 || !ctx.timed) return;
  add({
    code: 'adapter-away',
    ports: [p.port],
    severity: 'warning',
    confidence: 'certain',
    title: `${p.label}: the USB adapter went away ${plural(a.count, 'time')}`,
    evidence: [
      {
        text: `The adapter was lost ${plural(a.count, 'time')} (${formatDuration(a.totalUs)} in all, the first at ${ctx.at(a.firstUs)}) until its data came back. No hold or failsafe is counted for that time, since the link could not be seen (frames the receiver's own counter says it lost then still count).`,
        timeUs: a.firstUs,
      },
    ],
    todo: [
      'If nobody unplugged it: the USB cable or connector (loose, or long), or a hub that cuts power; plug the adapter straight into the computer.',
      "An adapter that resets when the satellite draws current: if the satellite is powered from the adapter's 3.3 V pin, power it from a 3.3 V regulator of its own (grounds common).",
      'The computer suspending USB: keep it from sleeping while you record.',
    ],
    settings: [],
    confirm: null,
    sinceUs: a.firstUs,
  });
}

export function lineVerdict(p: PortState, now: number, ctx: RuleContext): LineVerdict {
  const { fromS, toS } = lineWindow(now);
  const windowStart = Math.max(fromS * 1e6, Number.isFinite(p.firstActivityUs) ? p.firstActivityUs : fromS * 1e6);
  const seconds = Math.max(
    0,
    (Math.min(now, Number.isFinite(p.lastActivityUs) ? Math.max(p.lastActivityUs, windowStart) : now) - windowStart) / 1e6,
  );
  const packets = { ibus: 0, 'srxl-v1': 0, srxl2: 0, crsf: 0, sbus: 0, fport: 0, ghst: 0 } as Record<PacketKind, number>;
  PACKET_KINDS.forEach((k, i) => {
    packets[k] = p.bins.sum(M_PACKETS + i, fromS, toS);
  });
  return classifyLine({
    seconds: Math.max(seconds, 0.5),
    bytes: p.bins.sum(M_BYTES, fromS, toS),
    frameBytes: p.bins.sum(M_FRAME_BYTES, fromS, toS),
    characterErrors: p.bins.sum(M_CHAR_ERRORS, fromS, toS),
    breaks: p.bins.sum(M_BREAKS, fromS, toS),
    packets,
    burstPeriodUs: ctx.precise ? p.burst.periodUs(fromS * 1e6) : NaN,
  });
}

/**
 * The line window in words, never longer than what the port has shown: the last 3 s, or the
 * time since its first byte; untimed (a raw file), the file or its last bytes.
 */
export function windowText(p: PortState, now: number, ctx: RuleContext): string {
  const { fromS, toS } = lineWindow(now);
  if (!ctx.timed) {
    const bytes = p.bins.sum(M_BYTES, fromS, toS);
    return bytes >= p.bytes ? 'in the file' : `in the file's last ${plural(bytes, 'byte')}`;
  }
  const since = now - p.firstActivityUs;
  return since < LINE_WINDOW_BINS * 1e6 ? `in ${formatDuration(since)}` : `in the last ${LINE_WINDOW_BINS} s`;
}

export function lineFindings(p: PortState, v: LineVerdict, now: number, ctx: RuleContext, add: AddFinding): void {
  const { fromS, toS } = lineWindow(now);
  const overruns = p.bins.sum(M_OVERRUNS, fromS, toS);
  if (overruns > 0) {
    add({
      code: 'overrun',
      ports: [p.port],
      severity: 'info',
      confidence: 'certain',
      title: `${p.label}: bytes were lost before they reached SatScope`,
      evidence: [{ text: `${plural(overruns, 'buffer overrun')} reported by the port ${windowText(p, now, ctx)}.`, timeUs: null }],
      todo: [
        "Close other programs that read the port; use a shorter USB cable or another USB port; gaps in the data around these times are not the satellite's.",
      ],
      settings: [],
      confirm: null,
    });
  }
  if (v.kind === 'satellite') {
    p.confirmed = null;
    return;
  }
  if (p.baudRate !== 115_200) return; // probing: judged when the port returns to 115200
  const window = windowText(p, now, ctx);
  const foreign = (
    protocol: ForeignProtocol,
    confidence: Confidence,
    evidence: Evidence[],
    extra: string[] = [],
    confirm: ConfirmProbe | null = null,
  ): void => {
    const name = PROTOCOL_SETTINGS[protocol].name;
    const c = p.confirmed?.protocol === protocol ? 'certain' : confidence;
    const ev =
      p.confirmed?.protocol === protocol
        ? [
            ...evidence,
            {
              text: `Confirmed: ${plural(p.confirmed.packets, `valid ${name} packet`)} when listening at ${p.confirmed.baudRate} baud.`,
              timeUs: p.confirmed.timeUs,
            },
          ]
        : evidence;
    add({
      code: protocol,
      ports: [p.port],
      severity: 'problem',
      confidence: c,
      title: `${p.label}: this is ${name}, not a Spektrum satellite`,
      evidence: ev,
      todo: [
        `Set the flight controller's serial receiver to ${name} (settings below), or connect a Spektrum satellite if that is what you meant to use.`,
        ...extra,
      ],
      settings: foreignSettings(protocol),
      confirm: c === 'certain' ? null : confirm,
    });
  };
  switch (v.kind) {
    case 'too-little':
      return;
    case 'packets': {
      const bytes = p.bins.sum(M_BYTES, fromS, toS);
      const { what, setting } = PACKET_SHAPES[v.protocol];
      const shape =
        v.protocol === 'srxl2' && p.scanner.lastSrxl2Type === 0xcd
          ? `${what} (channel data, 0xA6 0xCD)`
          : v.protocol === 'srxl2' && p.scanner.lastSrxl2Type === 0x21
            ? `${what} (handshakes, 0xA6 0x21)`
            : what;
      const extra =
        v.protocol === 'srxl2'
          ? [
              "SRXL2 (e.g. an SPM4651T) is a two-way, single-wire protocol: on the flight controller it goes to a UART's TX pin in half-duplex (Betaflight and iNav set that up for SRXL2).",
            ]
          : v.protocol === 'srxl-v1'
            ? ["SRXL v1 comes from a full Spektrum receiver's SRXL port, not from a satellite."]
            : [];
      foreign(
        v.protocol,
        v.count >= 10 ? 'certain' : 'likely',
        [
          {
            text: `${plural(v.count, 'packet')} ${window}: ${shape}, in ${plural(bytes, 'byte')}${setting === UART_115200 ? ' at 115200 8N1' : `, as read at its own setting (${setting})`}; no Spektrum satellite frames.`,
            timeUs: null,
          },
        ],
        extra,
      );
      return;
    }
    case 'inverted-satellite':
    case 'idle-low': {
      const period =
        v.kind === 'inverted-satellite'
          ? ` one every ${(v.periodUs / 1000).toFixed(1)} ms${v.confident ? ", a satellite's frame period" : ''}`
          : '';
      add({
        code: 'inverted-line',
        ports: [p.port],
        severity: 'problem',
        confidence: v.kind === 'inverted-satellite' ? (v.confident ? 'likely' : 'possible') : 'possible',
        title:
          v.kind === 'inverted-satellite'
            ? `${p.label}: the line is inverted: a satellite seen through an inverter`
            : `${p.label}: the line idles low (inverted)`,
        evidence: [
          {
            text: `${plural(Math.round(v.breaksPerSecond * 10) / 10, 'break condition')} a second (the line held low between packets),${period}; about ${v.bytesPerBreak.toFixed(1)} bytes between breaks, most of them with framing errors. A satellite's line idles high.`,
            timeUs: null,
          },
        ],
        todo: [
          'Connect DATA to an input without an inverter: on many F4 flight controllers the "SBUS" pad or a UART with an SBUS inverter inverts; use another UART\'s RX, or the pad marked for Spektrum/DSM.',
          'If the UART has a switchable inverter, turn it off: Betaflight and iNav `set serialrx_inverted = ON` undoes the inverter for a Spektrum provider (only where the hardware allows it).',
          'On this adapter: a plain 3.3 V USB-serial adapter\'s RX, not an "SBUS" or inverted input.',
        ],
        settings: [],
        confirm: null,
      });
      return;
    }
    case 'sbus':
      foreign(
        'sbus',
        v.confident ? 'likely' : 'possible',
        [
          {
            text: `The line idles low with ${Math.round(v.breaksPerSecond * 10) / 10} breaks a second (one packet every ${(v.periodUs / 1000).toFixed(1)} ms) and about ${v.bytesPerBreak.toFixed(1)} bytes between them: the shape of SBUS's 25-byte packets at 100000 baud 8E2, inverted.`,
            timeUs: null,
          },
        ],
        [
          "SBUS needs an inverted input (the flight controller's SBUS pad); on a flight controller without one, use an SBUS inverter or the receiver's non-inverted output.",
        ],
        {
          baudRate: 100_000,
          parity: 'even',
          stopBits: 2,
          listenUs: 1_000_000,
          note: 'Only through an adapter that inverts its RX (e.g. an FT232R with RXD inverted in its EEPROM): WebSerial cannot invert.',
        },
      );
      return;
    case 'crsf':
      foreign(
        'crsf',
        'likely',
        [
          {
            text: `Framing errors on most characters and bursts every ${(v.periodUs / 1000).toFixed(2)} ms (${Math.round(1e6 / v.periodUs)} Hz, a CRSF packet rate): a faster signal with normal polarity.`,
            timeUs: null,
          },
        ],
        [],
        {
          baudRate: 420_000,
          parity: 'none',
          stopBits: 1,
          listenUs: 500_000,
          note: 'Listen at 420000 8N1 to find CRSF sync bytes (0xC8) and checksums, then return to 115200.',
        },
      );
      return;
    case 'other-speed':
      if (p.confirmed?.protocol === 'crsf') {
        foreign('crsf', 'certain', [
          { text: `${Math.round(v.errorRatio * 100)} % of characters had framing errors at 115200.`, timeUs: null },
        ]);
        return;
      }
      add({
        code: 'wrong-speed',
        ports: [p.port],
        severity: 'problem',
        confidence: 'possible',
        title: `${p.label}: a signal at another speed, not a satellite at 115200`,
        evidence: [
          {
            text: `${Math.round(v.errorRatio * 100)} % of characters had framing errors ${window}, and no breaks: the line idles high like a UART, but its bits are not 115200 baud.`,
            timeUs: null,
          },
        ],
        todo: [
          'CRSF (Crossfire, ExpressLRS) runs at 420000 baud: if that is the receiver, set the flight controller to CRSF (Betaflight/iNav `set serialrx_provider = CRSF`).',
          'A satellite sends at 115200 only; anything else on this wire is another device, or noise from a loose ground.',
        ],
        settings: [],
        confirm: {
          baudRate: 420_000,
          parity: 'none',
          stopBits: 1,
          listenUs: 500_000,
          note: 'Listen at 420000 8N1 for CRSF packets, then return to 115200.',
        },
      });
      return;
    case 'noise':
      add({
        code: 'noise',
        ports: [p.port],
        severity: 'problem',
        confidence: 'likely',
        title: `${p.label}: noise on the line, not data`,
        evidence: [
          {
            text: `${Math.round(v.breaksPerSecond)} break conditions a second at no steady rate and ${Math.round(v.errorRatio * 100)} % framing errors ${window}: levels that change at random, not characters.`,
            timeUs: null,
          },
        ],
        todo: [
          "Connect ground: black (GND) of the satellite to the adapter's GND. An input without a common ground picks up noise.",
          "Check that DATA (grey) is on the adapter's RX and the connector is seated; a floating RX pin reads noise.",
          'Keep the lead away from motor and ESC wiring.',
        ],
        settings: [],
        confirm: null,
      });
      return;
    case 'unknown-115200':
      // A satellite's first frames wait for the decoder's evidence: give it time to lock. Bytes
      // without any frame are `noSatelliteFinding`'s, which says so plainly.
      if (now - p.firstActivityUs < UNKNOWN_AFTER_US || p.source?.decoder.format.locked === true || emptyStream(p, now)) return;
      add({
        code: 'unknown-stream',
        ports: [p.port],
        severity: 'warning',
        confidence: 'possible',
        title: `${p.label}: clean bytes at 115200, but not Spektrum frames`,
        evidence: [
          {
            text: `${plural(v.bytes, 'byte')} ${window} without line errors, in no known RC packet (${KNOWN_PACKETS}).`,
            timeUs: null,
          },
        ],
        todo: [
          "This is another device at 115200 8N1 (a GPS, a telemetry radio, a flight controller's output?). Check which wire is on the adapter: a satellite's grey DATA wire.",
        ],
        settings: [],
        confirm: null,
      });
      return;
  }
}

const KNOWN_PACKETS = 'Spektrum, SRXL, SRXL2, IBUS, SBUS, CRSF, FPort, GHST';

/**
 * Whether a port's bytes are judged to hold no Spektrum stream: bytes came, not one frame
 * decoded, and either the stream is over (`Doctor.ended`: a capture, however short) or a
 * satellite has had time to lock (`UNKNOWN_AFTER_US`).
 */
export function emptyStream(p: PortState, now: number): boolean {
  return p.frames === 0 && p.bytes > 0 && (p.ended || now - p.firstActivityUs >= UNKNOWN_AFTER_US);
}

/** File signatures a user may open by mistake, by their first bytes. */
const SIGNATURES: readonly { name: string; head: readonly number[] }[] = [
  { name: 'a PNG image', head: [0x89, 0x50, 0x4e, 0x47] },
  { name: 'a JPEG image', head: [0xff, 0xd8, 0xff] },
  { name: 'a GIF image', head: [0x47, 0x49, 0x46, 0x38] },
  { name: 'a PDF document', head: [0x25, 0x50, 0x44, 0x46] },
  { name: 'a ZIP archive', head: [0x50, 0x4b, 0x03, 0x04] },
  { name: 'a gzip archive', head: [0x1f, 0x8b] },
  { name: 'an ELF program', head: [0x7f, 0x45, 0x4c, 0x46] },
];

/** What a port's bytes look like, in a sentence, when they hold no frame and no named protocol. */
function lookOf(p: PortState, fromS: number, toS: number, bytes: number): string {
  const head = p.head;
  const sig = SIGNATURES.find((s) => s.head.every((b, i) => head[i] === b));
  if (sig !== undefined)
    return `They begin like ${sig.name} (${sig.head.map((b) => b.toString(16).toUpperCase().padStart(2, '0')).join(' ')}), not a serial capture.`;
  const zero = p.bins.sum(M_ZERO, fromS, toS);
  const ff = p.bins.sum(M_FF, fromS, toS);
  const text = p.bins.sum(M_TEXT, fromS, toS);
  if (zero === bytes)
    return 'Every byte is 0x00: a line held low reads as zeros (DATA shorted to ground, an inverted line, or a receiver without power).';
  if (ff === bytes) return 'Every byte is 0xFF: an idle line read as data, or an input that floats high.';
  if (text >= 0.9 * bytes)
    return `${Math.round((text / bytes) * 100)} % of them are printable text: a GPS, a console or a log, not a receiver.`;
  return `They are in no known RC packet (${KNOWN_PACKETS}).`;
}

/**
 * What a port's bytes were once they have stopped: the protocol whose packets they held (at
 * least 3, the probe's bar), or null. The bins forget after 64 s; the port's count does not.
 */
function pastPackets(p: PortState): string | null {
  const kind = PACKET_KINDS.reduce<PacketKind | null>(
    (best, k) => (p.packetsEver[k] >= 3 && (best === null || p.packetsEver[k] > p.packetsEver[best]) ? k : best),
    null,
  );
  return kind === null
    ? null
    : `They were ${plural(p.packetsEver[kind], `${PROTOCOL_SETTINGS[kind].name} packet`)}, and the line has been silent since.`;
}

/**
 * Bytes that hold no Spektrum stream, said plainly (a problem: every surface then says no
 * satellite was found), with what they look like, unless a line finding already named them.
 */
export function noSatelliteFinding(p: PortState, v: LineVerdict, now: number, ctx: RuleContext, add: AddFinding): void {
  if (!emptyStream(p, now) || (v.kind !== 'too-little' && v.kind !== 'unknown-115200')) return;
  const { fromS, toS } = lineWindow(now);
  const windowBytes = p.bins.sum(M_BYTES, fromS, toS);
  const whole = windowBytes === p.bytes;
  const amount = whole ? plural(p.bytes, 'byte') : `${plural(p.bytes, 'byte')} (${plural(windowBytes, 'byte')} ${windowText(p, now, ctx)})`;
  const format = p.source?.decoder.format;
  if (format?.withheld === 'forced') {
    // Frames that an option set by hand does not fit: the setting is wrong, not the wiring.
    add({
      code: 'forced-option',
      ports: [p.port],
      severity: 'problem',
      confidence: 'certain',
      title: `${p.label}: the resolution set reads none of its frames`,
      evidence: [{ text: `${amount}: ${noFramesHint(format)}.`, timeUs: null }],
      todo: ['Set the resolution to Auto (satscope: leave out --resolution): the decoder finds the one the frames have.'],
      settings: [],
      confirm: null,
    });
    return;
  }
  add({
    code: 'no-satellite',
    ports: [p.port],
    severity: 'problem',
    confidence: 'certain',
    title: `${p.label}: no Spektrum satellite stream`,
    evidence: [
      { text: `${amount} and not one Spektrum frame in them (a satellite sends a 16-byte frame every 11 or 22 ms).`, timeUs: null },
      {
        text: windowBytes > 0 ? lookOf(p, fromS, toS, windowBytes) : (pastPackets(p) ?? lookOf(p, -Infinity, Infinity, p.bytes)),
        timeUs: null,
      },
    ],
    todo: [
      "If this should be a satellite: its grey DATA wire on the adapter's RX, black GND to GND, 3.3 V on orange, and a bound transmitter on (its LED solid).",
      'If this is a file: open a SatScope recording (.sscap), a raw dump of the DATA line (.bin) or a Saleae async-serial export (.csv) at 115200 8N1.',
    ],
    settings: [],
    confirm: null,
  });
}
