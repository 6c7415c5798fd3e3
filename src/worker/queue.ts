/**
 * The worker's one line of work: commands from the page and reconnect attempts run one after
 * another, each to its end, since opening a port while another command closes it would race.
 */
export class TaskQueue {
  #tail: Promise<void> = Promise.resolve();

  /** @param onError told of a task that failed; the queue goes on with the next one */
  constructor(readonly onError: (error: unknown) => void) {}

  /** Runs `task` after everything queued before it. */
  enqueue(task: () => Promise<void> | void): void {
    this.#tail = this.#tail.then(task).catch((error: unknown) => this.onError(error));
  }

  /** Resolves once everything queued so far has run (for tests and shutdown). */
  idle(): Promise<void> {
    return this.#tail;
  }
}
