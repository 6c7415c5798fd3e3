/**
 * The doctor's findings (src/report, fed by the worker): what is wrong with the setup and what
 * to change, worst first, each with its evidence, how sure it is, what to do and the flight
 * stack's settings. A finding appears once its evidence suffices and goes when it no longer
 * holds; in replay, the findings at the replay position. "Copy settings" puts the chosen flight
 * stack's CLI lines on the clipboard. `TopFinding` is the worst one in one line, for under the
 * link state. Findings about ports that are gone (unplugged) are listed apart, as what was seen
 * before the loss, never as the link now.
 */
import { computed, signal } from '@preact/signals';
import { useState } from 'preact/hooks';
import type { DoctorFinding } from '../../../report/doctor-types.js';
import type { FlightStack } from '../../../report/doctor-stacks.js';
import { diagnosis, drive, replayReading, send, sources } from '../../store.js';
import { plural } from '../../../report/report-text.js';
import { splitFindings, withDriveLoop } from './current.js';
import './style.css';

const STACKS: readonly FlightStack[] = ['Betaflight', 'iNav', 'ArduPilot', 'PX4'];
const STACK_KEY = 'satscope.stack';
const SEVERITY = { problem: 'Problem', warning: 'Warning', info: 'Info' } as const;

function savedStack(): FlightStack {
  try {
    const v = typeof localStorage === 'undefined' ? null : localStorage.getItem(STACK_KEY);
    return STACKS.find((s) => s === v) ?? 'Betaflight';
  } catch {
    return 'Betaflight';
  }
}

/** The flight stack whose settings are copied (remembered). */
const stack = signal<FlightStack>(savedStack());
/** What the last copy did, for the status line. */
const copied = signal('');

const keyOf = (f: DoctorFinding): string => `${f.code}:${f.ports.join(',')}`;

/** Ports whose adapter is gone: what the doctor last said of them is not the link now. */
const lostPorts = computed(() => sources.value.filter((s) => s.kind === 'serial' && s.state === 'lost').map((s) => s.id));
/** The findings about the link now, and those about ports lost since. */
const split = computed(() => {
  // The drive's loopback reads what the adapter sent: its gaps are frames not sent, not a weak link.
  const d = drive.value;
  const loop = d === null || d.source === null ? null : { source: d.source, skipped: d.timing.skipped, driving: d.state === 'driving' };
  return splitFindings(withDriveLoop(diagnosis.value?.findings ?? [], loop), lostPorts.value);
});
/** "remote A", "remotes A and B": the lost ports' labels. */
const lostNames = computed(() => {
  const labels = sources.value.filter((s) => lostPorts.value.includes(s.id)).map((s) => s.label);
  return labels.length === 1 ? `remote ${labels[0]}` : `remotes ${labels.slice(0, -1).join(', ')} and ${labels.at(-1)}`;
});

/** The lines to paste for `which`: from the worst finding that has some for it. */
function settingsFor(findings: readonly DoctorFinding[], which: FlightStack): { lines: string[]; from: DoctorFinding } | null {
  for (const f of findings) {
    const s = f.settings.find((x) => x.stack === which && x.lines.length > 0);
    if (s !== undefined) return { lines: s.lines, from: f };
  }
  return null;
}

async function copy(text: string): Promise<boolean> {
  try {
    await navigator.clipboard.writeText(text);
    return true;
  } catch {
    return false;
  }
}

export function TopFinding() {
  const top = split.value.current[0];
  if (top === undefined) return null;
  return (
    <a class={`top-finding sev-${top.severity}`} href="#diagnosis" title={top.title} data-testid="top-finding">
      <span class="mark" aria-hidden="true">
        {top.severity === 'problem' ? '!' : top.severity === 'warning' ? '⚠' : 'i'}
      </span>
      <span class="text">{top.title}</span>
    </a>
  );
}

function Finding({ f, open, onToggle }: { f: DoctorFinding; open: boolean; onToggle: (open: boolean) => void }) {
  const d = diagnosis.value;
  const port = f.ports[0];
  const probe = f.confirm;
  const canProbe = probe !== null && port !== undefined && d?.probeable.includes(port) === true;
  const probing = d?.probing ?? null;
  return (
    <li class={`finding sev-${f.severity}`} data-code={f.code}>
      <details open={open} onToggle={(e) => onToggle((e.currentTarget as HTMLDetailsElement).open)}>
        <summary>
          <span class="sev">{SEVERITY[f.severity]}</span>
          <span class="title">{f.title}</span>
          <span class="conf">{f.confidence}</span>
        </summary>
        <div class="body">
          {f.evidence.length > 0 ? (
            <>
              <h3>Evidence</h3>
              <ul class="evidence">
                {f.evidence.map((e, i) => (
                  <li key={i}>{e.text}</li>
                ))}
              </ul>
            </>
          ) : null}
          {f.todo.length > 0 ? (
            <>
              <h3>What to do</h3>
              <ol class="todo">
                {f.todo.map((t, i) => (
                  <li key={i}>{t}</li>
                ))}
              </ol>
            </>
          ) : null}
          {f.settings.length > 0 ? (
            <>
              <h3>Flight controller</h3>
              <div class="stacks">
                {f.settings.map((s) => (
                  <div class="stack" key={s.stack}>
                    <h4>{s.stack}</h4>
                    {s.lines.length > 0 ? <pre>{s.lines.join('\n')}</pre> : null}
                    <p>{s.note}</p>
                  </div>
                ))}
              </div>
            </>
          ) : null}
          {f.confirm !== null ? (
            <div class="confirm">
              {canProbe ? (
                <button type="button" disabled={probing !== null} onClick={() => send({ type: 'diagnosis-confirm', source: port, probe })}>
                  {probing !== null && probing.source === port
                    ? `Listening at ${probing.baudRate} baud…`
                    : `Listen at ${f.confirm.baudRate} baud for ${f.confirm.listenUs / 1e6} s`}
                </button>
              ) : null}
              <p class="muted">
                {f.confirm.note}
                {canProbe ? ' Then reading returns to 115200.' : ''}
              </p>
            </div>
          ) : null}
        </div>
      </details>
    </li>
  );
}

export function DiagnosisPanel() {
  const d = diagnosis.value;
  const { current: findings, before } = split.value;
  // Which findings the user opened or closed. The worst starts open when it is a problem (then
  // there is little else to look at); warnings and advice stay one line each, so on a phone
  // the channel bars are not pushed far down.
  const [toggled, setToggled] = useState<Record<string, boolean>>({});
  const opened = (f: DoctorFinding, i: number): boolean => toggled[keyOf(f)] ?? (i === 0 && f.severity === 'problem');
  const which = stack.value;
  const paste = settingsFor(findings, which);
  const item = (f: DoctorFinding, i: number) => {
    const key = keyOf(f);
    return (
      <Finding
        key={key}
        f={f}
        open={opened(f, i)}
        onToggle={(open) => {
          if (opened(f, i) !== open) setToggled({ ...toggled, [key]: open });
        }}
      />
    );
  };
  const empty = replayReading.value
    ? 'Reading the capture: findings appear once it plays.'
    : d === null || (d.mode === 'live' && sources.value.length === 0)
      ? 'Connect a receiver: findings appear here as the evidence comes in.'
      : d.mode === 'replay'
        ? 'Nothing wrong found at this point of the capture.'
        : 'Nothing wrong found so far.';
  const onCopy = async () => {
    if (paste === null) return;
    const ok = await copy(`${paste.lines.join('\n')}\n`);
    copied.value = ok
      ? `Copied ${plural(paste.lines.length, `${which} line`)} (${paste.from.title}).`
      : 'The browser did not allow copying: select the lines below instead.';
  };
  return (
    <section class="diagnosis" aria-labelledby="diagnosis-title">
      <div class="head">
        <h2 id="diagnosis-title">Diagnosis</h2>
        <div class="copy">
          <label>
            <span class="sr-only">Flight stack</span>
            <select
              value={which}
              onChange={(e) => {
                const v = (e.currentTarget as HTMLSelectElement).value as FlightStack;
                stack.value = v;
                copied.value = '';
                try {
                  localStorage.setItem(STACK_KEY, v);
                } catch {
                  /* private mode: not remembered */
                }
              }}
            >
              {STACKS.map((s) => (
                <option key={s} value={s}>
                  {s}
                </option>
              ))}
            </select>
          </label>
          <button
            type="button"
            disabled={paste === null}
            onClick={() => void onCopy()}
            title={paste === null ? `No ${which} settings to copy for these findings` : `Copies: ${paste.lines.join('; ')}`}
          >
            Copy settings
          </button>
        </div>
      </div>
      <p class="copied" role="status">
        {copied.value}
      </p>
      {findings.length === 0 ? (
        <p class="none" data-testid="diagnosis-none">
          {before.length === 0
            ? empty
            : sources.value.every((s) => lostPorts.value.includes(s.id))
              ? 'No port is read now: nothing can be said about the link.'
              : 'Nothing wrong found on the ports still read.'}
        </p>
      ) : (
        <ul class="findings" data-testid="findings">
          {findings.map(item)}
        </ul>
      )}
      {before.length > 0 ? (
        <div class="before" data-testid="findings-before">
          <h3>Before {lostNames.value}'s adapter was lost: not the link now</h3>
          <ul class="findings">{before.map((f, i) => item(f, i + findings.length))}</ul>
        </div>
      ) : null}
    </section>
  );
}
