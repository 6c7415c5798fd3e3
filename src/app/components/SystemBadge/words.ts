/** How the system badge names where the resolution came from: one wording, for the badge and for the tests that read it. */
import type { ResolutionReason } from '../../../decoder/types.js';

/** The words after the resolution on its chip (' inferred', ' set by you'…), or '' when the system byte says it. */
export function resolutionSource(reason: ResolutionReason): string {
  switch (reason) {
    case 'channel-ids':
    case 'system-byte-contradicted':
      return ' inferred';
    case 'override':
      return ' set by you';
    case 'internal-remote':
      return ' from the internal remote';
    case 'system-byte':
    case 'unknown':
      return '';
  }
}
