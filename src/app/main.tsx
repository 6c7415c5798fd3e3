/**
 * Entry: starts the worker, renders the page, offers ports the origin was granted before, and
 * starts the demo receiver when there are none, so a newcomer sees everything at once.
 */
import { render } from 'preact';
// First: sets <html data-theme> before anything is drawn.
import './theme.js';
import { App } from './components/App/index.js';
import { serialUnavailable } from './serial.js';
import { send, startWorker } from './store.js';
import { startBenchHooks } from './bench.js';
import { wake } from './frame-loop.js';

async function main(): Promise<void> {
  const worker = startWorker();
  // The user's input may change what the views show: they draw every frame again at once.
  for (const type of ['pointerdown', 'pointermove', 'keydown', 'wheel', 'input', 'resize'])
    window.addEventListener(type, wake, { passive: true, capture: true });
  const granted = serialUnavailable() === null ? await navigator.serial.getPorts() : [];
  render(<App granted={granted} />, document.getElementById('app') as HTMLElement);
  const params = new URLSearchParams(location.search);
  if (params.has('bench')) startBenchHooks(worker);
  if (granted.length === 0 && params.get('demo') !== '0') send({ type: 'demo-start' });
  if ('serviceWorker' in navigator && import.meta.env.PROD) {
    navigator.serviceWorker.register('./sw.js').catch(() => undefined);
  }
}

void main();
