/**
 * What a recorded capture event tells the doctor: the words the worker's recorder writes
 * ("port opened", "device lost", "line error: FramingError"…) read back as the calls live use
 * makes. The live worker, `doctorCapture` and the report's one pass all go through here, so a
 * recording says what was seen.
 */
import type { Doctor } from './doctor.js';

/** A capture event's text names a WebSerial read error, e.g. "line error: FramingError". */
const LINE_ERROR = /\b(FramingError|ParityError|BreakError|BufferOverrunError)\b/;
/** "port opened", "device reconnected", optionally "… at 420000 baud". */
const OPENED = /\b(port opened|device reconnected)\b/i;
const CLOSED = /\b(device lost|port closed)\b/i;
const BAUD = /\b(\d{4,7})\s*baud\b/i;

/**
 * Feeds one recorded event to a doctor: "port opened" / "device reconnected" (optionally
 * "… at 420000 baud") opens the port, "device lost" / "port closed" closes it, and a text that
 * names a WebSerial read error ("line error: FramingError") is that error. Other texts are
 * ignored.
 */
export function doctorEvent(doctor: Doctor, port: number, text: string, timeUs: number): void {
  const error = LINE_ERROR.exec(text);
  if (error?.[1] !== undefined) doctor.lineError(port, error[1], timeUs);
  else if (OPENED.test(text)) {
    const baud = BAUD.exec(text);
    doctor.open(port, timeUs, baud !== null ? { baudRate: Number(baud[1]) } : {});
  } else if (CLOSED.test(text)) doctor.close(port);
}
