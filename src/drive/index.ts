/**
 * satscope/drive: drive a flight controller as a Spektrum satellite and grade what it read.
 * Pure ECMAScript (no DOM, no Node, no timers): the caller owns the serial ports and the clock.
 *
 * - Scenarios: `builtinScenarios(receiver)` (sweep, steps, dropouts, fades, X-Plus, damage…),
 *   `manualScenario(receiver)` for live sticks, `parseDriveScenario(json)` for your own.
 * - Writing: a `DrivePlayer` plays a scenario as writes (the simulator's frames, the throttle
 *   bounded by a ceiling, `setChannel` for live sticks); a `WriteSchedule` says which write to make
 *   now so that each frame leaves whole after `MIN_SILENCE_US` of silence, the newest when late.
 * - The flight controller's reading: MSP for Betaflight and iNav (`encodeMsp`, `MspParser`,
 *   `readRc`, `readBetaflightStatus`, `readInavStatus`), MAVLink v2 for ArduPilot and PX4
 *   (`gcsHeartbeat`, `requestMessageInterval`, `MavlinkParser`, `readHeartbeat`,
 *   `readRcChannels`, `readRcReceiverHealth`).
 * - Grading: `gradeDrive(written, readings, order)` checks the channel order, the values against
 *   §9, a step's latency and the failsafe; `driveReportHtml` makes the self-contained report.
 *
 * ```ts
 * const player = new DrivePlayer(builtinScenarios(receiver)[0], { throttleCeilingPercent: -60 });
 * const schedule = new WriteSchedule(player);
 * // On a timer: for (let w = schedule.take(nowUs); w; w = schedule.take(nowUs)) port.write(w.bytes);
 * // then sleep until schedule.nextDueUs() (NaN: the scenario ended).
 * ```
 */
export { builtinScenarios, type DriveReceiver, manualScenario } from './builtins.js';
export { type DriveScenario, parseDriveScenario } from './scenario.js';
export { DrivePlayer, type DriveWrite } from './player.js';
export { type DriveTimingStats, MIN_SILENCE_US, WriteSchedule } from './schedule.js';
export { type DriveCheck, type DriveGrade, type FcReading, gradeDrive } from './grade.js';
export { type DriveReport, driveReportHtml } from './report.js';
export { encodeMsp, MSP, type MspMessage, MspParser, readBetaflightStatus, readInavStatus, readRc } from './msp.js';
export {
  gcsHeartbeat,
  MAVLINK,
  type MavlinkMessage,
  MavlinkParser,
  readHeartbeat,
  readRcChannels,
  readRcReceiverHealth,
  requestMessageInterval,
} from './mavlink.js';
