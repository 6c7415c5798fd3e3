// The few WHATWG stream types the library's stream adapter uses. Browsers (lib.dom) and Node
// (@types/node) both declare the real ones; this file exists only so that tsconfig.decoder.json
// can check the library against ECMAScript alone.
interface TransformStreamDefaultController<O> {
  enqueue(chunk: O): void;
  error(reason?: unknown): void;
  terminate(): void;
}
interface Transformer<I, O> {
  transform?(chunk: I, controller: TransformStreamDefaultController<O>): void | PromiseLike<void>;
  flush?(controller: TransformStreamDefaultController<O>): void | PromiseLike<void>;
}
declare class ReadableStream<R = unknown> {
  pipeThrough<T>(pair: { readable: ReadableStream<T>; writable: WritableStream<R> }): ReadableStream<T>;
}
declare class WritableStream<W = unknown> {
  private readonly w?: W;
}
declare class TransformStream<I = unknown, O = unknown> {
  constructor(transformer?: Transformer<I, O>);
  readonly readable: ReadableStream<O>;
  readonly writable: WritableStream<I>;
}
