/**
 * UTF-8 for capture metadata, events and CSV text, through the platform's TextEncoder and
 * TextDecoder (every browser and Node has them; types/text-encoding.d.ts declares them for the
 * library's ES2022-only build). Malformed input becomes U+FFFD, as WHATWG decoding does.
 */
const encoder = new TextEncoder();
const decoder = new TextDecoder();
const strict = new TextDecoder('utf-8', { fatal: true });

export function utf8Encode(text: string): Uint8Array {
  return encoder.encode(text);
}

export function utf8Decode(bytes: Uint8Array, start = 0, end = bytes.length): string {
  return decoder.decode(bytes.subarray(start, end));
}

/** Whether bytes [start, end) are well-formed UTF-8; with `allowCutTail`, a sequence cut short at the end is fine. */
export function isUtf8(bytes: Uint8Array, start = 0, end = bytes.length, allowCutTail = false): boolean {
  try {
    strict.decode(bytes.subarray(start, end), { stream: allowCutTail });
    return true;
  } catch {
    return false;
  } finally {
    // A streaming decode keeps the cut tail: flush it so the next call starts clean.
    if (allowCutTail) {
      try {
        strict.decode();
      } catch {
        // the cut tail it held is what the caller allowed
      }
    }
  }
}
