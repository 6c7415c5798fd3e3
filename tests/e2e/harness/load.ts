// Other work on the machine: child processes that spin at normal priority, one per core by
// default, so a test can show its figures hold while the CPUs are busy. The children end on
// stop(), and by themselves if this process dies (they spin for at most `maxMs`).
import { spawn, type ChildProcess } from 'node:child_process';
import { availableParallelism } from 'node:os';

export interface CpuLoad {
  /** Ends the spinning children; resolves once they have exited. Idempotent. */
  stop(): Promise<void>;
}

export function loadCpus(count = availableParallelism(), maxMs = 120_000): CpuLoad {
  const spin = `const end = Date.now() + ${maxMs}; let x = 0; while (Date.now() < end) x += Math.sqrt(x + 1);`;
  const children: ChildProcess[] = [];
  for (let i = 0; i < count; i++) children.push(spawn(process.execPath, ['-e', spin], { stdio: 'ignore' }));
  let stopped: Promise<void> | null = null;
  return {
    stop() {
      stopped ??= Promise.all(
        children.map(
          (c) =>
            new Promise<void>((resolve) => {
              if (c.exitCode !== null || c.signalCode !== null) return resolve();
              c.once('exit', () => resolve());
              c.kill('SIGKILL');
            }),
        ),
      ).then(() => undefined);
      return stopped;
    },
  };
}
