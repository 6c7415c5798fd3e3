/**
 * How long a test lets one run of the CLI take before stopping it (spawnSync's `timeout`). A test
 * blocked in spawnSync cannot reach its own timeout: a CLI that hangs would hang the whole run.
 * Stopped, it exits with no status, and the test fails there instead.
 */
export const CLI_TIMEOUT_MS = 60_000;
