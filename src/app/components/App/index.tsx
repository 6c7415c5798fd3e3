/**
 * The page: sources and recorder on top, replay controls when replaying, then the link state
 * and system beside the channel bars, X-Plus when it arrives, and the graphs. With nothing to
 * show (no receiver, no demo, no capture), what to wire and how to start instead.
 */
import { computed, signal } from '@preact/signals';
import { useEffect, useState } from 'preact/hooks';
import { lazy } from '../../lazy.js';
import { openCapture } from '../../open-file.js';
import { diagnosis, replayName, replaySpanUs, sources, status, xplusSeen } from '../../store.js';
import { ChannelBars } from '../ChannelBars/index.js';
import { Counters } from '../Counters/index.js';
import { DiagnosisPanel } from '../Diagnosis/index.js';
import { EmptyState } from '../EmptyState/index.js';
import { Fold } from '../Fold/index.js';
import { Graphs, WINDOWS } from '../Graphs/index.js';
import { LinkPanel } from '../LinkPanel/index.js';
import { Notices } from '../Notices/index.js';
import { Remotes } from '../Remotes/index.js';
import { ReplayBar } from '../ReplayBar/index.js';
import { SystemBadge } from '../SystemBadge/index.js';
import { Toolbar } from '../Toolbar/index.js';
import { Traces } from '../Traces/index.js';
import './style.css';

const BindPanel = lazy(() => import('../Bind/index.js').then((m) => m.BindPanel));
const DrivePanel = lazy(() => import('../Drive/index.js').then((m) => m.DrivePanel));
const InspectorPanel = lazy(() => import('../InspectorPanel/index.js').then((m) => m.InspectorPanel));

const NORMAL = [0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11];
const XPLUS = [12, 13, 14, 15, 16, 17, 18, 19];
/** The graphs' (and the episode timeline's) window, µs. */
const windowUs = signal(60e6);
/** The channel panel's title names the remote shown when there are several (a signal bound to the text). */
const channelsTitle = computed(() => (sources.value.length > 1 ? `Channels — remote ${status.value.label}` : 'Channels'));
/** What the folded diagnosis says on a phone: how many findings (nothing before the doctor spoke). */
const findingsHint = computed(() => {
  const n = diagnosis.value?.findings.length;
  return n === undefined ? undefined : n === 1 ? '1 finding' : `${n} findings`;
});
/** Whether the bind panel is open. */
export const binding = signal(false);
/** Whether the drive panel is open. */
export const driving = signal(false);

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
  const empty = sources.value.length === 0 && replayName.value === null;
  // A capture shorter than the graphs' window would be a sliver at its right edge: fit it.
  const name = replayName.value;
  const span = replaySpanUs.value;
  useEffect(() => {
    if (name === null || span <= 0) return;
    windowUs.value = WINDOWS.find(([us]) => us >= span)?.[0] ?? windowUs.value;
  }, [name, span > 0]);
  return (
    <>
      <Toolbar
        granted={granted}
        onBind={() => {
          binding.value = !binding.value;
        }}
        onDrive={() => {
          driving.value = !driving.value;
        }}
      />
      {binding.value ? (
        <BindPanel
          granted={granted}
          onClose={() => {
            binding.value = false;
          }}
        />
      ) : null}
      {driving.value ? (
        <DrivePanel
          granted={granted}
          onClose={() => {
            driving.value = false;
          }}
        />
      ) : null}
      <ReplayBar />
      <Notices />
      {empty ? (
        <main class="start">
          <EmptyState
            onBind={() => {
              binding.value = true;
            }}
          />
        </main>
      ) : (
        <main class="grid">
          {/* On a phone both columns dissolve into one, ordered by what matters first, the rest folded (style.css). */}
          <aside class="side">
            <div class="panel p-link">
              <LinkPanel windowUs={windowUs} />
            </div>
            <Fold name="system" title="System">
              <h2>System</h2>
              <SystemBadge />
            </Fold>
            <Fold name="counters" title="Counters">
              <h2>Counters</h2>
              <Counters />
            </Fold>
          </aside>
          <div class="main">
            <Fold name="diagnosis" title="Diagnosis" hint={findingsHint.value} anchor="diagnosis">
              <div id="diagnosis">
                <DiagnosisPanel />
              </div>
            </Fold>
            {sources.value.length > 1 ? (
              <Fold name="remotes" title="Remotes side by side" hint={`${sources.value.length} remotes`}>
                <Remotes windowUs={windowUs} />
              </Fold>
            ) : null}
            <div class="panel p-channels">
              <h2>{channelsTitle}</h2>
              <ChannelBars ids={NORMAL} label="Channels 0–11" />
            </div>
            {xplusSeen.value ? (
              <div class="panel p-xplus">
                <h2>X-Plus</h2>
                <ChannelBars ids={XPLUS} label="X-Plus channels" />
              </div>
            ) : null}
            <Fold name="graphs" title="Link over time">
              <Graphs windowUs={windowUs} />
            </Fold>
            <Fold name="traces" title="Channels over time">
              <Traces windowUs={windowUs} />
            </Fold>
            <div class="panel p-inspector">
              <InspectorPanel />
            </div>
          </div>
        </main>
      )}
      {dragging ? (
        <div class="drop" aria-hidden="true">
          Drop a capture (.sscap, raw .bin, Saleae CSV) to replay it
        </div>
      ) : null}
    </>
  );
}
