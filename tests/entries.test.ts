/**
 * The package's entries stay apart in a bundle: importing the core (`satscope`) pulls in neither
 * the capture importers nor the report's HTML nor the doctor nor Drive.
 */
import { describe, expect, it } from 'vitest';
import { entrySizes } from '../scripts/core-size.mjs';

describe('package entries in a bundle', () => {
  it('keeps capture files, the report and the doctor out of a bundle that imports the core', async () => {
    const sizes = await entrySizes();
    const core = sizes.satscope.text;
    expect(core).toContain('push() after end()');
    expect(core).not.toMatch(/Saleae|Link health report|serialrx_provider|\.sscap/);
    expect(sizes['satscope/report'].text).toContain('Link health report');
    // Drive stays out of the core and carries neither the health report nor the doctor.
    expect(core).not.toMatch(/Drive report|MAVLink/);
    expect(sizes['satscope/drive'].text).toContain('Drive report');
    expect(sizes['satscope/drive'].text).not.toMatch(/Link health report|Saleae/);
    // The figure the README quotes, with room for small changes (14.1 kB since the decoder's
    // slots are read written out, not looped: 1.4x the decoding speed for 0.3 kB; 14.9 kB since
    // the link monitor's checkpoints share settled episodes, episode-log.ts: 0.5 kB for
    // checkpoints that no longer grow with every episode before them; 15.4 kB since the link
    // monitor tells receiver restarts and delivery stalls from loss: 0.4 kB; 16.3 kB since a lock
    // needs evidence of a channel, forced options never pick the alignment and an ambiguous
    // header is said and re-read: 0.9 kB; 16.9 kB since a silence is dated by the frame that
    // ends it and judged by the counter over the burst after it: 0.5 kB; 17.0 kB since an
    // acquisition pass that finds no start is not scored again: 0.1 kB, 3.5x on noise; 17.7 kB
    // since a system byte's period is refuted by the frames' timing and a stream's end counts
    // what its last deliveries vouch for: 0.3 kB; 18.9 kB since an external remote's frames that
    // read as well a few bytes off are said unproven, weighed frame by frame and re-read on the
    // first header that moves as no count does: 1.0 kB, the least that tells a count from a
    // held stick, where before a reading a word off was shown as certain).
    expect(sizes.satscope.gzip).toBeLessThan(19 * 1024);
  }, 60_000);
});
