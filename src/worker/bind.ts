/**
 * Runs a bind (spec §7.2) on a serial port: the steps of `bindTimeline` — open at the pulse
 * rate, power the satellite off through RTS or DTR, power it on, write the pulses ~60 ms later,
 * then close and reopen at 115200 with the power line asserted again at once — each at its time.
 * The worker then reads the port as usual, so the user sees the bind take.
 */
import { bindForAdapter, type BindStep, type PowerLine, type PowerPolarity } from '../bind/index.js';
import type { BindProgress } from './protocol.js';

const sleepUntil = (ms: number) => new Promise<void>((resolve) => setTimeout(resolve, Math.max(0, ms - performance.now())));

/**
 * Binds through `port` (closed on entry). Resolves with the setSignals argument that keeps the
 * satellite powered, for the live reopen; reports each step as it happens.
 * @throws the port's own error when a step fails (the port is closed again first).
 */
export async function runBind(
  port: SerialPort,
  options: { pulses: number; powerLine: PowerLine; polarity: PowerPolarity },
  report: (progress: BindProgress) => void,
): Promise<SerialOutputSignals> {
  // The plan for this port's chip, made by the same call the Bind panel previews it with.
  const { plan, steps } = bindForAdapter(options.pulses, port.getInfo(), { powerLine: options.powerLine, polarity: options.polarity });
  const start = performance.now();
  let powerOffAt = NaN;
  let powerOnAt = NaN;
  let keepOn: SerialOutputSignals = {};
  const done = (step: BindStep, text: string) => {
    const now = performance.now();
    report({
      step: step.action,
      text,
      atMs: Math.round(now - start),
      sincePowerOnMs: Number.isNaN(powerOnAt) ? null : Math.round((now - powerOnAt) * 10) / 10,
    });
  };
  try {
    for (const step of steps) {
      // Each step is timed from when the one it depends on really happened, not from the plan's
      // start: power-on from power-off (the satellite must be off long enough to reset), the
      // pulses and the reopen from power-on (they must land in the bind window).
      const offMs = -(steps.find((s) => s.action === 'power-off')?.sincePowerOnMs ?? 0);
      const due =
        step.action === 'power-on'
          ? powerOffAt + offMs
          : step.action === 'write' || step.action === 'reopen'
            ? powerOnAt + step.sincePowerOnMs
            : start + step.atMs;
      await sleepUntil(due);
      switch (step.action) {
        case 'open':
          await port.open({ baudRate: step.baudRate, dataBits: 8, stopBits: step.stopBits, parity: 'none', flowControl: 'none' });
          done(step, `opened at ${step.baudRate} baud`);
          break;
        case 'power-off':
          await port.setSignals(step.signals);
          powerOffAt = performance.now();
          done(step, 'satellite off');
          break;
        case 'power-on':
          await port.setSignals(step.signals);
          powerOnAt = performance.now();
          keepOn = step.signals;
          done(step, 'satellite on (t0)');
          break;
        case 'write': {
          const writer = (port.writable as WritableStream<Uint8Array>).getWriter();
          try {
            await writer.write(step.bytes);
            await writer.close(); // resolves once the bytes are out: drained
          } finally {
            writer.releaseLock();
          }
          done(step, `${options.pulses} pulses sent (${step.bytes.length} bytes at ${plan.baudRate} baud)`);
          break;
        }
        case 'reopen':
          await port.close();
          done(step, 'closing to reopen at 115200');
          return step.signals;
      }
    }
    return keepOn;
  } catch (error) {
    try {
      await port.close();
    } catch {
      // Not open, or already gone.
    }
    throw error;
  }
}
