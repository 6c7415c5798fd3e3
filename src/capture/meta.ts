/**
 * Capture metadata checking, shared by the writer (which throws) and the reader (which drops).
 */
import type { CaptureMeta, CapturePortInfo, MetaScalar } from './model.js';

const KNOWN_STRING_FIELDS = ['createdAt', 'source', 'note'] as const;
const KNOWN_NUMBER_FIELDS = ['baudRate', 'usbVendorId', 'usbProductId'] as const;

function isScalar(v: unknown): v is MetaScalar {
  return v === null || typeof v === 'string' || typeof v === 'boolean' || (typeof v === 'number' && Number.isFinite(v));
}

export function isPlainObject(v: unknown): v is Record<string, unknown> {
  return typeof v === 'object' && v !== null && !Array.isArray(v);
}

/** Why `value` cannot be field `key` (at `path`), or undefined when it can. */
function fieldProblem(key: string, value: unknown, path: string): string | undefined {
  if (key === '__proto__') return `${path} is not an allowed key`;
  if ((KNOWN_STRING_FIELDS as readonly string[]).includes(key) || key === 'name') {
    return typeof value === 'string' ? undefined : `${path} must be a string`;
  }
  if ((KNOWN_NUMBER_FIELDS as readonly string[]).includes(key)) {
    return typeof value === 'number' && Number.isFinite(value) ? undefined : `${path} must be a finite number`;
  }
  return isScalar(value) ? undefined : `${path} must be a string, a finite number, a boolean or null`;
}

/**
 * A clean copy of `value` as `CaptureMeta`: fields of the wrong type are left out and described
 * in `problems`. Undefined values are left out silently (JSON has no undefined).
 */
export function cleanMeta(value: unknown, problems: string[]): CaptureMeta {
  const out: CaptureMeta = {};
  if (!isPlainObject(value)) {
    problems.push('meta must be a plain object');
    return out;
  }
  for (const key of Object.keys(value)) {
    const v = value[key];
    if (v === undefined) continue;
    if (key === 'ports') {
      if (!Array.isArray(v)) {
        problems.push('meta.ports must be an array');
        continue;
      }
      const ports: CapturePortInfo[] = [];
      v.forEach((entry: unknown, i: number) => {
        const port: CapturePortInfo = {};
        if (!isPlainObject(entry)) {
          problems.push(`meta.ports[${i}] must be an object`);
        } else {
          for (const k of Object.keys(entry)) {
            const pv = entry[k];
            if (pv === undefined) continue;
            const problem = fieldProblem(k, pv, `meta.ports[${i}].${k}`);
            if (problem) problems.push(problem);
            else port[k] = pv as MetaScalar;
          }
        }
        // Keep the entry even when emptied, so entry i still describes port i.
        ports.push(port);
      });
      out.ports = ports;
      continue;
    }
    const problem = fieldProblem(key, v, `meta.${key}`);
    if (problem) problems.push(problem);
    else out[key] = v as MetaScalar;
  }
  return out;
}
