/**
 * The adapter a bind runs on: the one table of USB IDs (src/bind/chips.ts) names the port and
 * picks its chips, and the Bind panel previews exactly the bind the worker then runs on it.
 */
import { describe, expect, it } from 'vitest';
import { bindPreview } from '../src/app/components/Bind/preview.js';
import { adapterChips, DEFAULT_CHIPS, portName, type UsbIds } from '../src/bind/index.js';
import { runBind } from '../src/worker/bind.js';

/** A SerialPort with these USB IDs that records what a driver does to it. */
function fakePort(usb: UsbIds) {
  const calls: { open: SerialOptions[]; signals: SerialOutputSignals[]; written: number[]; closes: number } = {
    open: [],
    signals: [],
    written: [],
    closes: 0,
  };
  let writable: WritableStream<Uint8Array> | null = null;
  const port = {
    getInfo: () => ({ ...usb }),
    async open(options: SerialOptions) {
      calls.open.push(options);
      writable = new WritableStream<Uint8Array>({ write: (chunk) => void calls.written.push(...chunk) });
    },
    async setSignals(signals: SerialOutputSignals) {
      calls.signals.push(signals);
    },
    get writable() {
      return writable;
    },
    async close() {
      calls.closes++;
      writable = null;
    },
  };
  return { port: port as unknown as SerialPort, calls };
}

const ADAPTERS: { label: string; usb: UsbIds }[] = [
  { label: 'FTDI FT232R', usb: { usbVendorId: 0x0403, usbProductId: 0x6001 } },
  { label: 'CP2102 or CP2102N', usb: { usbVendorId: 0x10c4, usbProductId: 0xea60 } },
  { label: 'CH340', usb: { usbVendorId: 0x1a86, usbProductId: 0x7523 } },
  { label: 'PL2303HX or TA', usb: { usbVendorId: 0x067b, usbProductId: 0x2303 } },
  { label: 'PL2303G', usb: { usbVendorId: 0x067b, usbProductId: 0x23a3 } },
  { label: 'an Arduino (chip not modelled)', usb: { usbVendorId: 0x2341, usbProductId: 0x0043 } },
  { label: 'a port without USB IDs (a pty, a native UART)', usb: {} },
];

describe('the USB-serial adapter table', () => {
  it('names ports as before: vendor and IDs, or "Serial port" without IDs', () => {
    expect(portName({ usbVendorId: 0x0403, usbProductId: 0x6001 })).toBe('FTDI (0403:6001)');
    expect(portName({ usbVendorId: 0x10c4, usbProductId: 0xea60 })).toBe('CP210x (10c4:ea60)');
    expect(portName({ usbVendorId: 0x1a86, usbProductId: 0x7523 })).toBe('CH340 (1a86:7523)');
    expect(portName({ usbVendorId: 0x067b, usbProductId: 0x2303 })).toBe('PL2303 (067b:2303)');
    expect(portName({ usbVendorId: 0x0483, usbProductId: 0x5740 })).toBe('STM32 (0483:5740)');
    expect(portName({ usbVendorId: 0x1234 })).toBe('USB serial (1234:0000)');
    expect(portName({})).toBe('Serial port');
  });

  it('says whether the USB IDs named the chips, and stands in the default chips when not', () => {
    expect(adapterChips({ usbVendorId: 0x0403, usbProductId: 0x6001 })).toEqual({ chips: ['ft232r'], known: true });
    expect(adapterChips({ usbVendorId: 0x067b, usbProductId: 0x23a3 })).toEqual({ chips: ['pl2303g'], known: true });
    expect(adapterChips({ usbVendorId: 0x2341, usbProductId: 0x0043 })).toEqual({ chips: DEFAULT_CHIPS, known: false });
    expect(adapterChips({})).toEqual({ chips: DEFAULT_CHIPS, known: false });
  });
});

describe('the Bind panel preview', () => {
  it('is the plan the worker runs on the same adapter: same rate, same bytes, same power signals', async () => {
    const runs = await Promise.all(
      ADAPTERS.map(async ({ label, usb }) => {
        const { port, calls } = fakePort(usb);
        await runBind(port, { pulses: 9, powerLine: 'rts', polarity: 'asserted' }, () => {});
        return { label, usb, calls };
      }),
    );
    for (const { label, usb, calls } of runs) {
      const preview = bindPreview(9, usb, 'rts', 'asserted');
      const shown = preview.steps.flatMap((s) => ('signals' in s && s.action !== 'reopen' ? [s.signals] : []));
      expect([calls.open[0]?.baudRate, calls.open[0]?.stopBits], label).toEqual([preview.plan.baudRate, preview.plan.stopBits]);
      expect(calls.written, label).toEqual(Array.from(preview.plan.bytes));
      expect(calls.signals, label).toEqual(shown);
      expect(calls.closes, label).toBe(1); // closed for the reopen at 115200
    }
  });

  it('differs from the default-chips plan where the chip allows better, so showing the default would be false', () => {
    const ftdi = bindPreview(9, { usbVendorId: 0x0403, usbProductId: 0x6001 }, 'rts', 'asserted');
    const unknown = bindPreview(9, {}, 'rts', 'asserted');
    expect(ftdi.plan.baudRate).toBe(41667); // exact 120 µs phases
    expect(unknown.plan.baudRate).toBe(38400); // what every common chip can make
    expect(ftdi.chipsKnown).toBe(true);
    expect(ftdi.adapter).toContain('FTDI FT232R');
  });

  it('says when it falls back to the common chips: unknown adapter, or no port chosen yet', () => {
    const unknown = bindPreview(9, { usbVendorId: 0x2341, usbProductId: 0x0043 }, 'rts', 'asserted');
    expect(unknown.chipsKnown).toBe(false);
    expect(unknown.adapter).toMatch(/does not know this adapter's chip/);
    const none = bindPreview(9, null, 'rts', 'asserted');
    expect(none.chipsKnown).toBe(false);
    expect(none.adapter).toMatch(/No port chosen yet/);
    expect(none.plan).toEqual(bindPreview(9, {}, 'rts', 'asserted').plan);
    for (const p of [unknown, none]) expect(p.adapter).not.toMatch(/setSignals|requestToSend|baud/);
  });
});
