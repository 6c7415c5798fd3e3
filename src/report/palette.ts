/**
 * What each measured quantity is drawn in, wherever SatScope draws it: the page's graphs (light
 * and dark) and the printed health report (light). Fades amber, lost frames and failsafes red,
 * RSSI blue, the frame period green: a colour means the same thing on every surface.
 */
export interface DataColors {
  readonly fades: string;
  readonly rssi: string;
  /** RSSI's lowest in each column (the report), a tint of `rssi`. */
  readonly rssiMin: string;
  readonly period: string;
  readonly lost: string;
  /** A failsafe's band behind a graph, and its edge. */
  readonly failsafeBand: string;
  readonly failsafeEdge: string;
  readonly glitch: string;
}

export const DATA_COLORS: { readonly light: DataColors; readonly dark: DataColors } = {
  light: {
    fades: '#b7791f',
    rssi: '#1f6fd1',
    rssiMin: '#a9c6ec',
    period: '#0a7d5a',
    lost: '#d1343a',
    failsafeBand: 'rgba(209,52,58,0.16)',
    failsafeEdge: '#d1343a',
    glitch: '#d1343a',
  },
  dark: {
    fades: '#f0b429',
    rssi: '#7cc4ff',
    rssiMin: '#3d6a91',
    period: '#4fd1a5',
    lost: '#ff6b6b',
    failsafeBand: 'rgba(255,60,60,0.25)',
    failsafeEdge: '#ff6b6b',
    glitch: '#ff4d4f',
  },
};
