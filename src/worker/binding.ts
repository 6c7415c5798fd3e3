/**
 * The Bind command: the port is taken from whatever reads it, the bind runs (bind.ts), and the
 * port is read live at once with the satellite kept powered, so the user sees the bind take.
 */
import { runBind } from './bind.js';
import { type Host, notice } from './host.js';
import type { BindProgress, ToWorker } from './protocol.js';
import type { SourceRegistry } from './registry.js';
import { openProblem } from './sources/serial.js';
import { type SerialPorts, sameAdapter } from './sources/serial-ports.js';

export async function bind(
  message: Extract<ToWorker, { type: 'bind' }>,
  host: Host,
  registry: SourceRegistry,
  serial: SerialPorts,
  run: typeof runBind = runBind,
): Promise<void> {
  await registry.use(serial);
  const port = await serial.find(message.port);
  if (port === undefined) {
    notice(host, 'error', 'The port is not available', 'Plug the adapter in and choose it again.');
    return;
  }
  // The bind needs the port to itself: close it if it is being read (or was, before it was lost).
  for (const s of registry.list()) if (s.serial?.port === port || sameAdapter(s.identity, message.port)) await registry.remove(s.id);
  const report = (progress: BindProgress) => host.post({ type: 'bind', progress });
  let keepOn: SerialOutputSignals;
  try {
    keepOn = await run(port, message, report);
  } catch (error) {
    const problem = openProblem(error);
    report({ step: 'failed', text: `${problem.title}: ${problem.detail}`, atMs: 0, sincePowerOnMs: null });
    notice(host, 'error', `Bind failed: ${problem.title}`, problem.detail);
    return;
  }
  if (await serial.open(message.port, keepOn)) {
    report({
      step: 'live',
      text: 'reading at 115200: the satellite blinks until the transmitter binds, then frames appear',
      atMs: 0,
      sincePowerOnMs: null,
    });
  } else {
    report({
      step: 'failed',
      text: 'the pulses were sent, but the port could not be opened again at 115200',
      atMs: 0,
      sincePowerOnMs: null,
    });
  }
}
