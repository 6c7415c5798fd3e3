/**
 * Node can hang for ever as a process ends (nodejs/node#54918, open): on its way out the main
 * thread waits for V8's background tasks, while a background compile (TurboFan) that needs a
 * garbage collection waits for the main thread. `satscope decode FILE > /dev/full` hung so in
 * 4 of 600 runs, six at a time on two cores (Node 20.20; gdb: the main thread in
 * NodePlatform::DrainTasks, the compile thread in CollectionBarrier::AwaitCollectionBackground),
 * and once in the test suite. With TurboFan compiling on the thread that runs the code
 * (`--no-concurrent-recompilation`) no background task waits for the main thread: none of 600
 * runs hung, nor of 1200 through this file, and `info` and `report` on a day's capture took as
 * long. V8 reads the flag only as it starts: the command runs in a Node started with it.
 */
import { spawn } from 'node:child_process';
import { constants } from 'node:os';

/** The Node options the command runs with. */
export const COMMAND_NODE_FLAGS: readonly string[] = ['--no-concurrent-recompilation'];

/** Set in the environment of the Node started here: that one never starts another (whatever its options say). */
const STARTED_HERE = 'SATSCOPE_RELAUNCHED';

/** Whether the command must be started in another Node: this one was started without the command's options. */
export function mustRelaunch(): boolean {
  return process.env[STARTED_HERE] === undefined && !COMMAND_NODE_FLAGS.every((flag) => process.execArgv.includes(flag));
}

/** The signals that stop a command, passed on to the one started here. */
const PASSED_ON: NodeJS.Signals[] = ['SIGINT', 'SIGTERM', 'SIGHUP'];

/**
 * Runs `script` with `args` in a Node started with the command's options and this one's, on
 * this process's standard streams, passing on the signals that stop a command. Resolves to its
 * exit code; when a signal ended it, this process ends by the same signal.
 */
export function relaunch(script: string, args: readonly string[]): Promise<number> {
  return new Promise((resolve) => {
    const child = spawn(process.execPath, [...COMMAND_NODE_FLAGS, ...process.execArgv, script, ...args], {
      stdio: 'inherit',
      env: { ...process.env, [STARTED_HERE]: '1' },
    });
    const passOn = (signal: NodeJS.Signals): void => {
      child.kill(signal);
    };
    for (const signal of PASSED_ON) process.on(signal, passOn);
    child.on('error', (error) => {
      process.stderr.write(`satscope: cannot start Node (${process.execPath}): ${error.message}\n`);
      resolve(2);
    });
    child.on('exit', (code, signal) => {
      for (const s of PASSED_ON) process.off(s, passOn);
      if (signal === null) {
        resolve(code ?? 1);
        return;
      }
      // Ended the same way: a shell or a test sees the signal, not an exit code.
      process.kill(process.pid, signal);
      resolve(128 + (constants.signals[signal] ?? 0));
    });
  });
}
