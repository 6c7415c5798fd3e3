/**
 * USB-serial adapters: the one table of their USB IDs and names, and the baud rate each chip
 * really makes for a requested one. The page's port picker, every port's name, and the chips a
 * bind plans its pulses for all come from here.
 */

/**
 * Chips, and how their baud rate is made, as the Linux drivers compute it (the dividers are the
 * chip's, so other systems reach the same rates; their drivers may round a little differently):
 * - `ft232r`: FTDI FT232R/FT232BM/FT231X: 3 MHz / (n + k/8), n ≥ 2, k 0–7; the driver rounds
 *   the divisor 3 MHz / baud to the nearest eighth.
 * - `cp2102`: Silicon Labs CP2102/CP2103: only the rates of AN205 table 1 (the table lives in the
 *   chip); a request maps to the first entry whose range covers it (41667 → 51200!).
 * - `cp2102n`: CP2102N/CP2104/CP2105/CP2108: 24 MHz / n, any n (CP2102N shares the CP2102's
 *   USB ID, so a page cannot tell them apart).
 * - `ch340`: WCH CH340/CH341: 48 MHz / (2^(12−3·ps−fact) · div), ps 0–3, fact 0–1, div 2–255,
 *   the Linux driver's search.
 * - `pl2303`: Prolific PL2303HX(A)/HXD: the standard rates directly, others 12 MHz·32 /
 *   (mantissa · 4^exp), mantissa < 512 (truncating).
 * - `pl2303ta`: PL2303TA/TB: 12 MHz·32 / (mantissa · 2^exp), mantissa < 2048.
 * - `pl2303g`: PL2303G (HXN): the rate is passed to the chip as is; its divider is undocumented,
 *   modelled as exact.
 */
export type UsbSerialChip = 'ft232r' | 'cp2102' | 'cp2102n' | 'ch340' | 'pl2303' | 'pl2303ta' | 'pl2303g';

export const USB_SERIAL_CHIPS: readonly UsbSerialChip[] = ['ft232r', 'cp2102', 'cp2102n', 'ch340', 'pl2303', 'pl2303ta', 'pl2303g'];
/** The four families a user is likely to own; a plan for these works on any of them. */
export const DEFAULT_CHIPS: readonly UsbSerialChip[] = ['ft232r', 'cp2102', 'ch340', 'pl2303'];

/** Each chip as its maker names it, for people. */
export const CHIP_NAMES: Readonly<Record<UsbSerialChip, string>> = {
  ft232r: 'FTDI FT232R',
  cp2102: 'Silicon Labs CP2102',
  cp2102n: 'Silicon Labs CP2102N',
  ch340: 'WCH CH340',
  pl2303: 'Prolific PL2303HX',
  pl2303ta: 'Prolific PL2303TA',
  pl2303g: 'Prolific PL2303G',
};

// ---------------------------------------------------------------------------------------------
// USB IDs

/** What WebSerial's `port.getInfo()` tells of a port; both absent for a port that is not USB. */
export interface UsbIds {
  readonly usbVendorId?: number | undefined;
  readonly usbProductId?: number | undefined;
}

export interface UsbSerialVendor {
  readonly usbVendorId: number;
  /** Short name for a port list: "FTDI (0403:6001)". */
  readonly name: string;
  /** The chips this vendor's product may be, or undefined when it is not a chip modelled here. */
  readonly chips: (usbProductId: number | undefined) => readonly UsbSerialChip[] | undefined;
}

/** PL2303G (HXN) product IDs: 0x23A3, 0x23B3, … 0x23F3 (the Linux driver's list). */
const isPl2303g = (pid: number | undefined) => pid !== undefined && pid >= 0x23a3 && pid <= 0x23f3 && (pid & 0xf) === 3;

/** USB vendors of the USB-serial chips and boards people wire to a satellite. */
export const USB_SERIAL_VENDORS: readonly UsbSerialVendor[] = [
  { usbVendorId: 0x0403, name: 'FTDI', chips: () => ['ft232r'] }, // FT232R/FT231X
  { usbVendorId: 0x10c4, name: 'CP210x', chips: () => ['cp2102', 'cp2102n'] }, // Silicon Labs
  { usbVendorId: 0x1a86, name: 'CH340', chips: () => ['ch340'] }, // WCH CH340/CH341
  { usbVendorId: 0x067b, name: 'PL2303', chips: (pid) => (isPl2303g(pid) ? ['pl2303g'] : ['pl2303', 'pl2303ta']) }, // Prolific
  { usbVendorId: 0x2341, name: 'Arduino', chips: () => undefined },
  { usbVendorId: 0x239a, name: 'Adafruit', chips: () => undefined },
  { usbVendorId: 0x0483, name: 'STM32', chips: () => undefined }, // flight controllers in passthrough
];

const vendor = (usbVendorId: number | undefined) => USB_SERIAL_VENDORS.find((v) => v.usbVendorId === usbVendorId);

/** A port's name for people, from its USB IDs: "FTDI (0403:6001)", or "Serial port". */
export function portName(info: UsbIds): string {
  const { usbVendorId, usbProductId } = info;
  if (usbVendorId === undefined) return 'Serial port';
  const hex = (v: number) => v.toString(16).padStart(4, '0');
  return `${vendor(usbVendorId)?.name ?? 'USB serial'} (${hex(usbVendorId)}:${hex(usbProductId ?? 0)})`;
}

/**
 * The chips a port with these USB IDs may be, and whether the IDs told: unknown IDs (or none)
 * give every chip in DEFAULT_CHIPS with `known` false, so a plan stays one that works anywhere.
 */
export function adapterChips(info: UsbIds): { readonly chips: readonly UsbSerialChip[]; readonly known: boolean } {
  const chips = vendor(info.usbVendorId)?.chips(info.usbProductId);
  return chips === undefined ? { chips: DEFAULT_CHIPS, known: false } : { chips, known: true };
}

/** The chips a WebSerial port may be, from `port.getInfo()`; DEFAULT_CHIPS for unknown IDs. */
export function chipsForUsbId(usbVendorId?: number, usbProductId?: number): readonly UsbSerialChip[] {
  return adapterChips({ usbVendorId, usbProductId }).chips;
}

// ---------------------------------------------------------------------------------------------
// Baud rates

/** AN205 table 1: [rate, highest request that maps to it]. */
const CP2102_TABLE: readonly (readonly [number, number])[] = [
  [300, 300],
  [600, 600],
  [1200, 1200],
  [1800, 1800],
  [2400, 2400],
  [4000, 4000],
  [4800, 4803],
  [7200, 7207],
  [9600, 9612],
  [14400, 14428],
  [16000, 16062],
  [19200, 19250],
  [28800, 28912],
  [38400, 38601],
  [51200, 51558],
  [56000, 56280],
  [57600, 58053],
  [64000, 64111],
  [76800, 77608],
  [115200, 117028],
  [128000, 129347],
  [153600, 156868],
  [230400, 237832],
  [250000, 254234],
  [256000, 273066],
  [460800, 491520],
  [500000, 567138],
  [576000, 670254],
  [921600, Infinity],
];
/** Rates a PL2303 sets directly. */
const PL2303_DIRECT: readonly number[] = [
  75, 150, 300, 600, 1200, 1800, 2400, 3600, 4800, 7200, 9600, 14400, 19200, 28800, 38400, 57600, 115200, 230400, 460800, 614400, 921600,
  1228800, 2457600, 3000000, 6000000,
];

/**
 * Every rate a fixed-table chip makes exactly (the CP2102's table, then the PL2303's direct
 * rates), so a planner can try them. Not exported from the package.
 */
export function tableRates(): number[] {
  return [...CP2102_TABLE.map(([rate]) => rate), ...PL2303_DIRECT];
}

/** `Math.round(a / b)` as C's DIV_ROUND_CLOSEST for positive integers. */
const divRoundClosest = (a: number, b: number) => Math.floor((a + Math.floor(b / 2)) / b);

function ch340Rate(requested: number): number {
  const clk = 48_000_000;
  const clkDiv = (ps: number, fact: number) => 2 ** (12 - 3 * ps - fact);
  const minRate = (ps: number) => Math.floor(clk / (clkDiv(ps, 1) * 512));
  const speed = Math.min(Math.max(requested, Math.ceil(clk / (clkDiv(0, 0) * 256))), clk / (clkDiv(3, 0) * 2));
  let fact = 1;
  let ps = 3;
  while (ps > 0 && !(speed > minRate(ps))) ps--;
  let cd = clkDiv(ps, fact);
  let div = Math.floor(clk / (cd * speed));
  if (div < 9 || div > 255) {
    div = Math.floor(div / 2);
    cd *= 2;
    fact = 0;
  }
  // Pick the next divisor when that rate is closer (the driver's ×16 integer comparison).
  if (Math.floor((16 * clk) / (cd * div)) - 16 * speed >= 16 * speed - Math.floor((16 * clk) / (cd * (div + 1)))) div++;
  if (fact === 1 && div % 2 === 0) {
    div /= 2;
    fact = 0;
  }
  return clk / (clkDiv(ps, fact) * div);
}

function pl2303Rate(requested: number, alt: boolean): number {
  if (!alt) {
    let nearest = PL2303_DIRECT[PL2303_DIRECT.length - 1]!;
    for (let i = 0; i < PL2303_DIRECT.length; i++) {
      const hi = PL2303_DIRECT[i]!;
      if (hi > requested) {
        const lo = i > 0 ? PL2303_DIRECT[i - 1]! : hi;
        nearest = i > 0 && hi - requested > requested - lo ? lo : hi;
        break;
      }
    }
    if (nearest === requested) return requested;
  } else if (PL2303_DIRECT.includes(requested)) {
    return requested;
  }
  const baseline = 12_000_000 * 32;
  let mantissa = Math.max(1, Math.floor(baseline / requested));
  let exponent = 0;
  const limit = alt ? 2048 : 512;
  const maxExp = alt ? 15 : 7;
  while (mantissa >= limit) {
    if (exponent < maxExp) {
      mantissa = Math.floor(mantissa / (alt ? 2 : 4));
      exponent++;
    } else {
      mantissa = limit - 1;
      break;
    }
  }
  return Math.floor(Math.floor(baseline / mantissa) / (alt ? 2 ** exponent : 4 ** exponent));
}

/** The baud rate `chip` really runs at when `requested` (an integer, as WebSerial takes) is set. */
export function chipBaudRate(chip: UsbSerialChip, requested: number): number {
  if (!Number.isInteger(requested) || requested <= 0) throw new RangeError(`baud rate must be a positive integer, not ${requested}`);
  switch (chip) {
    case 'ft232r': {
      // Divisor in eighths of 3 MHz, at most 2^17 − 1.
      const d3 = Math.min(Math.max(divRoundClosest(48_000_000, 2 * requested), 8), 0x1ffff);
      return 24_000_000 / d3;
    }
    case 'cp2102': {
      const b = Math.max(requested, 300);
      for (const [rate, high] of CP2102_TABLE) if (b <= high) return rate;
      return 921600;
    }
    case 'cp2102n': {
      const prescale = requested <= 365 ? 4 : 1;
      return 48_000_000 / (2 * prescale * divRoundClosest(48_000_000, 2 * prescale * requested));
    }
    case 'ch340':
      return ch340Rate(requested);
    case 'pl2303':
      return pl2303Rate(requested, false);
    case 'pl2303ta':
      return pl2303Rate(requested, true);
    case 'pl2303g':
      return requested;
  }
}
