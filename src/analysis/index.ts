/**
 * The doctor: findings about a satellite setup from what the wire shows. Every public name of
 * src/analysis is exported here.
 */
export {
  Doctor, NOTHING_AFTER_US, NOTHING_CERTAIN_US, LINE_WINDOW_BINS,
  type Confidence, type ConfirmProbe, type DoctorCode, type DoctorFinding, type DoctorOptions, type DoctorPortSource,
  type Evidence, type Severity,
} from './doctor.js';
export { doctorCapture, type DoctorCaptureOptions, type DoctorReport, type DoctorTimelineEntry } from './doctor-capture.js';
export {
  ArduPilotGuess, ARDUPILOT_GUESS_FRAMES, bindPulses, channelSetText, foreignSettings, PROTOCOL_SETTINGS, satelliteSettings,
  type FlightStack, type ForeignProtocol, type GuessTally, type StackSetting, type StreamFacts,
} from './doctor-stacks.js';
export { classifyLine, PacketScanner, PACKET_KINDS, type LineCounts, type LineVerdict, type PacketKind } from './doctor-line.js';
