import type { ByteFile } from './byte-file.js';
import type { StreamedCapture } from './capture-windows.js';

export function streamCsv(_file: ByteFile): StreamedCapture | null {
  return null;
}
