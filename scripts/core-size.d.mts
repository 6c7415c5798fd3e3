/** Each package entry bundled alone, minified and gzipped: sizes in bytes and the minified code. */
export function entrySizes(): Promise<
  Record<'satscope' | 'satscope/capture' | 'satscope/report' | 'satscope/drive', { min: number; gzip: number; text: string }>
>;
