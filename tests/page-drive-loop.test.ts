/** The drive's loopback in the doctor's findings (src/app/components/Diagnosis/current.ts): frames not sent, not a weak link. */
import { describe, expect, it } from 'vitest';
import { withDriveLoop } from '../src/app/components/Diagnosis/current.js';
import type { DoctorFinding } from '../src/report/doctor-types.js';

const finding = (
  code: DoctorFinding['code'],
  port: number,
  title: string,
  severity: DoctorFinding['severity'] = 'warning',
): DoctorFinding => ({
  code,
  ports: [port],
  severity,
  confidence: 'likely',
  title,
  evidence: [{ text: '3 holds (frames stopped, last values held), the last at 0:12.', timeUs: 12e6 }],
  todo: ['Move the satellite away from carbon and metal.'],
  settings: [],
  confirm: null,
  sinceUs: 0,
});

describe("the drive's loopback in the findings", () => {
  it('says frames the writer skipped were not sent, on the loopback port only, and ranks it below real problems', () => {
    const findings = [
      finding('weak-link', 3, 'A: the link is weak: frames lost'),
      finding('weak-link', 4, 'B: the link is weak: frames lost'),
      finding('rebind', 3, 'A: the receiver changed mode mid-session (a rebind?)'),
    ];
    const out = withDriveLoop(findings, { source: 3, skipped: 316, driving: true });
    const loop = out.find((f) => f.ports[0] === 3 && f.code === 'weak-link');
    expect(loop?.title).toBe('A: frames the drive did not send (its writer skipped 316 frames), not a weak link');
    expect(loop?.severity).toBe('info');
    expect(loop?.evidence[0]?.text).toMatch(/drive's own loopback/);
    expect(loop?.evidence[1]?.text).toMatch(/3 holds/);
    expect(loop?.todo.join(' ')).not.toMatch(/carbon/);
    // Another port's weak link is a weak link; and info comes after warnings.
    expect(out.map((f) => f.title)).toEqual([
      'B: the link is weak: frames lost',
      'A: the receiver changed mode mid-session (a rebind?)',
      'A: frames the drive did not send (its writer skipped 316 frames), not a weak link',
    ]);
    const stopped = withDriveLoop([finding('weak-link', 3, 'A: the link is weak: failsafe', 'problem')], {
      source: 3,
      skipped: 0,
      driving: false,
    });
    expect(stopped[0]?.title).toBe('A: the drive stopped sending, not a weak link');
    expect(withDriveLoop(findings, null)).toEqual(findings);
  });
});
