/**
 * Opening a capture file (button or drag-and-drop): the File goes to the worker, which reads it
 * (a .sscap a window at a time, whatever its size; what it must read whole, up to a limit).
 */
import { notify, send } from './store.js';

export async function openCapture(file: File): Promise<void> {
  if (file.size === 0) {
    notify('error', `Cannot open ${file.name}`, 'The file is empty.');
    return;
  }
  // Marks on the performance timeline (DevTools, bench:page) split opening a capture into the
  // page handing the file over, the worker reading it, and the page drawing its overview.
  performance.mark('satscope:capture-read');
  send({ type: 'replay-open', name: file.name, file });
}

/** The page's one file input (the toolbar's), which every "Open capture" button clicks. */
let input: HTMLInputElement | null = null;

export function setCaptureInput(el: HTMLInputElement | null): void {
  input = el;
}

/** Shows the browser's file chooser for a capture. */
export function chooseCapture(): void {
  input?.click();
}
