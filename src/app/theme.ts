/**
 * Light and dark. The page follows the system's prefers-color-scheme until the user picks one
 * with the toggle; the pick is remembered (localStorage). CSS reads the theme from
 * `<html data-theme>`; the canvas charts, which cannot read CSS custom properties cheaply, take
 * their colours from `chartColors()` and are rebuilt when `theme` changes.
 */
import { computed, signal } from '@preact/signals';
import { type DataColors, DATA_COLORS } from '../report/palette.js';

export type Theme = 'light' | 'dark';

const KEY = 'satscope-theme';
const media = typeof matchMedia === 'function' ? matchMedia('(prefers-color-scheme: dark)') : null;

function stored(): Theme | null {
  try {
    if (typeof localStorage === 'undefined') return null;
    const v = localStorage.getItem(KEY);
    return v === 'light' || v === 'dark' ? v : null;
  } catch {
    return null; // storage blocked: follow the system
  }
}

/** The user's pick, or null: follow the system. */
export const themeChoice = signal<Theme | null>(stored());
const systemDark = signal(media?.matches ?? true);
media?.addEventListener('change', (e) => {
  systemDark.value = e.matches;
});

/** The theme on screen. */
export const theme = computed<Theme>(() => themeChoice.value ?? (systemDark.value ? 'dark' : 'light'));

function apply(t: Theme): void {
  document.documentElement.dataset.theme = t;
}
// (Outside a page, e.g. a test importing the chart helpers, there is nothing to apply it to.)
if (typeof document !== 'undefined') theme.subscribe(apply);

export function setTheme(choice: Theme | null): void {
  themeChoice.value = choice;
  try {
    if (choice === null) localStorage.removeItem(KEY);
    else localStorage.setItem(KEY, choice);
  } catch {
    // Not remembered, but still applied.
  }
}

/** The graphs' colours: the data's (palette.ts, shared with the report) and the chart's own. */
export interface ChartColors extends DataColors {
  axis: string;
  grid: string;
  cursor: string;
  remotes: string[];
  /** The channel traces, one a lane (cycled); the glitch marks over them are the palette's. */
  traces: string[];
  /** The shade of every other lane of the traces. */
  lane: string;
}

const DARK: ChartColors = {
  ...DATA_COLORS.dark,
  axis: '#8a97a8',
  grid: '#1e2835',
  cursor: '#8a97a8',
  remotes: ['#4fd1a5', '#f0b429', '#7cc4ff', '#ff8fab', '#c3a6ff'],
  traces: ['#7cc4ff', '#4fd1a5', '#f0b429', '#c3a6ff'],
  lane: 'rgba(140,160,190,0.07)',
};

const LIGHT: ChartColors = {
  ...DATA_COLORS.light,
  axis: '#4f5b6b',
  grid: '#e3e8ee',
  cursor: '#4f5b6b',
  remotes: ['#0a7d5a', '#b7791f', '#1f6fd1', '#c2185b', '#7048e8'],
  traces: ['#1f6fd1', '#0a7d5a', '#a0660f', '#7048e8'],
  lane: 'rgba(60,80,110,0.05)',
};

export function chartColors(t: Theme = theme.value): ChartColors {
  return t === 'dark' ? DARK : LIGHT;
}
