/**
 * Which findings are about the link as it is now. A finding about ports whose adapters are all
 * gone (unplugged) describes a link that no longer exists: it is kept, as what was seen before
 * the loss, but never shown as current (nor as the worst finding under the link state).
 */
import type { DoctorFinding } from '../../../report/doctor-types.js';

export interface SplitFindings {
  /** About a port still read, or the whole session: worst first. */
  current: DoctorFinding[];
  /** About ports that are all lost: worst first. */
  before: DoctorFinding[];
}

export function splitFindings(findings: readonly DoctorFinding[], lostPorts: readonly number[]): SplitFindings {
  const current: DoctorFinding[] = [];
  const before: DoctorFinding[] = [];
  for (const f of findings) {
    const gone = f.ports.length > 0 && f.ports.every((p) => lostPorts.includes(p));
    (gone ? before : current).push(f);
  }
  return { current, before };
}
