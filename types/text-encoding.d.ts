// TextEncoder and TextDecoder (WHATWG Encoding), declared for code compiled against ES2022
// alone (the library: no DOM, no Node types). Every browser and Node since 11 has them.
declare class TextEncoder {
  readonly encoding: 'utf-8';
  encode(input?: string): Uint8Array;
}
declare class TextDecoder {
  constructor(label?: string, options?: { fatal?: boolean; ignoreBOM?: boolean });
  readonly encoding: string;
  readonly fatal: boolean;
  decode(input?: Uint8Array, options?: { stream?: boolean }): string;
}
