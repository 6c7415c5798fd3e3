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

/** The drive's own loopback (the adapter's TX wired to its RX): its source, the frames its writer skipped, and whether it still sends. */
export interface DriveLoop {
  source: number;
  skipped: number;
  driving: boolean;
}

const SEVERITY_RANK = { problem: 0, warning: 1, info: 2 } as const;

/**
 * The doctor's findings with the drive's loopback said for what it is: a gap in what the adapter
 * reads back is a frame the drive did not send (its writer skipped it, a scenario's silence, or
 * the drive stopped), not a weak link. The doctor cannot know that (it reads the port as any
 * receiver's); the page does. Worst first still.
 */
export function withDriveLoop(findings: readonly DoctorFinding[], loop: DriveLoop | null): DoctorFinding[] {
  if (loop === null) return [...findings];
  const out = findings.map((f): DoctorFinding => {
    if (f.code !== 'weak-link' || f.ports.length !== 1 || f.ports[0] !== loop.source) return f;
    const label = f.title.split(': the link is weak')[0] ?? f.title;
    const skipped = `${loop.skipped} frame${loop.skipped === 1 ? '' : 's'}`;
    return {
      ...f,
      severity: 'info',
      confidence: 'certain',
      title: loop.driving
        ? `${label}: frames the drive did not send (its writer skipped ${skipped}), not a weak link`
        : `${label}: the drive stopped sending, not a weak link`,
      evidence: [
        {
          text: `This port is the drive's own loopback: it reads back what the adapter sent. The writer skipped ${skipped} (a timer that woke late sends the newest frame, never a backlog); a scenario's silences and the stop send nothing.`,
          timeUs: null,
        },
        ...f.evidence,
      ],
      todo: [
        'Nothing to change on a radio link: a gap here is a frame not sent. Fewer skipped frames: a less loaded machine, the tab in front.',
      ],
    };
  });
  return out.sort((a, b) => SEVERITY_RANK[a.severity] - SEVERITY_RANK[b.severity]);
}
