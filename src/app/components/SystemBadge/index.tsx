/**
 * What the link is: DSM2 or DSMX, 11 or 22 ms, 1024 or 2048, internal or external remote,
 * RSSI-capable, and whether the resolution was read from the system byte or inferred.
 */
import { computed } from '@preact/signals';
import { systemInfo } from '../../../decoder/spec.js';
import { nominalPeriodUs, status } from '../../store.js';
import { resolutionSource } from './words.js';
import './style.css';

function protocol(system: number | null, resolution: number | null, periodUs: number): string {
  const info = system === null ? undefined : systemInfo(system);
  if (info !== undefined) return `${info.protocol} ${info.periodMs} ms`;
  const ms = Number.isFinite(periodUs) ? `${Math.round(periodUs / 1000)} ms` : '';
  // Only DSM2 22 ms uses 1024; 11 ms and 2048 fit DSM2 and DSMX alike without a system byte.
  if (resolution === 1024) return 'DSM2 22 ms';
  return ms ? `DSM2/DSMX ${ms}` : 'DSM2/DSMX';
}

/** The protocol's name, a signal bound to its text: the measured period can name it before a system byte does. */
const protocolText = computed(() => {
  const { format } = status.value;
  return protocol(format.system, format.resolution, nominalPeriodUs.value);
});

export function SystemBadge() {
  const { format } = status.value;
  if (!format.locked && format.resolution === null) {
    return (
      <section class="badge waiting" aria-label="System">
        <span class="chip">Waiting for frames</span>
      </section>
    );
  }
  const source = resolutionSource(format.resolutionReason);
  const hex = format.system === null ? null : `0x${format.system.toString(16).toUpperCase().padStart(2, '0')}`;
  return (
    <section class="badge" aria-label="System" title={format.explanation}>
      <span class="chip strong" data-testid="protocol">
        {protocolText}
      </span>
      <span class="chip" data-testid="resolution">
        {format.resolution ?? '?'}
        {source === '' ? null : <em>{source}</em>}
      </span>
      <span class="chip" data-testid="remote">
        {format.remote === 'internal' ? 'Internal remote' : 'External remote'}
      </span>
      {hex !== null ? <span class="chip">system {hex}</span> : null}
      {format.headerMode === 'rssi' ? <span class="chip accent">RSSI (SPM4649T)</span> : null}
      {format.alignmentUnproven ? (
        <span class="chip accent" data-testid="alignment" title="Channel values and fades may be each other's until a stick moves">
          Frame start unproven: move a stick
        </span>
      ) : null}
      <p class="why">{format.explanation}</p>
    </section>
  );
}
