/**
 * The page: sources and recorder on top, replay controls when replaying, then the link state
 * and system beside the channel bars, X-Plus when it arrives, and the graphs.
 */
import { signal } from '@preact/signals';
import { useEffect, useState } from 'preact/hooks';
import { lazy } from '../../lazy.js';
import { openCapture } from '../../open-file.js';
import { sources, status, xplusSeen } from '../../store.js';
import { ChannelBars } from '../ChannelBars/index.js';
import { Counters } from '../Counters/index.js';
import { Graphs } from '../Graphs/index.js';
import { LinkPanel } from '../LinkPanel/index.js';
import { Notices } from '../Notices/index.js';
import { Remotes } from '../Remotes/index.js';
import { ReplayBar } from '../ReplayBar/index.js';
import { SystemBadge } from '../SystemBadge/index.js';
import { Toolbar } from '../Toolbar/index.js';
import './style.css';

const BindPanel = lazy(() => import('../Bind/index.js').then((m) => m.BindPanel));
const InspectorPanel = lazy(() => import('../InspectorPanel/index.js').then((m) => m.InspectorPanel));

const NORMAL = [0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11];
const XPLUS = [12, 13, 14, 15, 16, 17, 18, 19];
/** The graphs' (and the episode timeline's) window, µs. */
const windowUs = signal(60e6);
/** Whether the bind panel is open. */
export const binding = signal(false);

export function App({ granted }: { granted: SerialPort[] }) {
  const [dragging, setDragging] = useState(false);
  useEffect(() => {
    const over = (e: DragEvent) => {
      if (!e.dataTransfer?.types.includes('Files')) return;
      e.preventDefault();
      setDragging(true);
    };
    const leave = (e: DragEvent) => {
      if (e.relatedTarget === null) setDragging(false);
    };
    const drop = (e: DragEvent) => {
      e.preventDefault();
      setDragging(false);
      const file = e.dataTransfer?.files[0];
      if (file) void openCapture(file);
    };
    window.addEventListener('dragover', over);
    window.addEventListener('dragleave', leave);
    window.addEventListener('drop', drop);
    return () => {
      window.removeEventListener('dragover', over);
      window.removeEventListener('dragleave', leave);
      window.removeEventListener('drop', drop);
    };
  }, []);
  return (
    <>
      <Toolbar granted={granted} onBind={() => { binding.value = !binding.value; }} />
      {binding.value ? <BindPanel granted={granted} onClose={() => { binding.value = false; }} /> : null}
      <ReplayBar />
      <Notices />
      <main class="grid">
        <aside class="side">
          <div class="panel"><LinkPanel windowUs={windowUs} /></div>
          <div class="panel"><h2>System</h2><SystemBadge /></div>
          <div class="panel"><h2>Counters</h2><Counters /></div>
        </aside>
        <div class="main">
          {sources.value.length > 1 ? <div class="panel"><Remotes windowUs={windowUs} /></div> : null}
          <div class="panel"><h2>Channels{sources.value.length > 1 ? ` — remote ${status.value.label}` : ''}</h2><ChannelBars ids={NORMAL} label="Channels 0–11" /></div>
          {xplusSeen.value ? <div class="panel"><h2>X-Plus</h2><ChannelBars ids={XPLUS} label="X-Plus channels" /></div> : null}
          <div class="panel"><Graphs windowUs={windowUs} /></div>
          <div class="panel"><InspectorPanel /></div>
        </div>
      </main>
      {dragging ? <div class="drop" aria-hidden="true">Drop a capture (.sscap, raw .bin, Saleae CSV) to replay it</div> : null}
    </>
  );
}
