// mcgv.js: the mcgv-video decoder (WebAssembly, web/src/lib.rs) as an ES module, for browsers and
// Node. No bundler, no dependency. Every codec decision is the library's: this file moves bytes in
// and numbers out.
//
//   import { MCGV } from './mcgv.js';
//   const mcgv = await MCGV.load(new URL('./mcgv_web.wasm', import.meta.url));  // or the bytes
//   const stream = mcgv.stream();            // one WebAssembly instance per stream
//   stream.append(bytes);                    // all of them, or a download's chunks as they come
//   const info = stream.open({ partial: true });   // throws MCGVError until enough has arrived
//   const xyz = stream.decodeFrame(7, new Float32Array(3 * info.vertices));
//
// A stream's instance is its own, so a bug that traps (a panic inside the decoder) kills that
// stream only: the call throws an MCGVError with the panic's message and `stream.dead` is true.

/** An error of the decoder (a bad stream, a frame that has not arrived) or of its instance. */
export class MCGVError extends Error {
  constructor(message, { panic = false } = {}) {
    super(message);
    this.name = 'MCGVError';
    /** True when the decoder trapped (a bug): the stream's instance is gone. */
    this.panic = panic;
  }
}

/** The compiled decoder; `stream()` makes a stream with its own instance. */
export class MCGV {
  /** Compiles the decoder from a URL (fetched, streamed where the server sends application/wasm),
   *  a Response, or the module's bytes. */
  static async load(source) {
    let module;
    if (source instanceof WebAssembly.Module) module = source;
    else if (source instanceof ArrayBuffer || ArrayBuffer.isView(source)) module = await WebAssembly.compile(source);
    else {
      const response = source instanceof Response ? source : await fetch(source);
      if (!response.ok) throw new MCGVError(`${response.url}: HTTP ${response.status}`);
      module = await (WebAssembly.compileStreaming && /wasm/.test(response.headers.get('content-type') || '')
        ? WebAssembly.compileStreaming(response)
        : response.arrayBuffer().then((b) => WebAssembly.compile(b)));
    }
    return new MCGV(module);
  }

  constructor(module) {
    this.module = module;
  }

  /** A new, empty stream. */
  stream() {
    const instance = new WebAssembly.Instance(this.module, {});
    return new MCGVStream(instance.exports);
  }
}

const decoder = new TextDecoder();

/** One `.mcgv` stream: its bytes so far, opened by `open`, decoded frame by frame or whole. */
export class MCGVStream {
  constructor(exports) {
    this.x = exports;
    this.dead = false;
    this.info = null;
    this.first = null;
    this.call('mcgv_init');
    this.handle = this.call('mcgv_stream_new');
  }

  /** Runs an export; a trap (a panic) becomes an MCGVError and kills the stream. */
  call(name, ...args) {
    if (this.dead) throw new MCGVError('the decoder of this stream died after an earlier error', { panic: true });
    try {
      return this.x[name](...args);
    } catch (e) {
      if (!(e instanceof WebAssembly.RuntimeError)) throw e;
      this.dead = true;
      const message = this.errorMessage() || String(e);
      throw new MCGVError(`${message} (${e.message})`, { panic: true });
    }
  }

  errorMessage() {
    try {
      const ptr = this.x.mcgv_error_ptr();
      const len = this.x.mcgv_error_len();
      return ptr ? decoder.decode(new Uint8Array(this.x.memory.buffer, ptr, len)) : '';
    } catch {
      return '';
    }
  }

  /** The address a call returned, or the error it stored. */
  check(ptr) {
    if (!ptr) throw new MCGVError(this.errorMessage() || 'decoder error');
    return ptr;
  }

  /** Appends bytes (a Uint8Array or ArrayBuffer) to the stream. */
  append(bytes) {
    const data = bytes instanceof Uint8Array ? bytes : new Uint8Array(bytes);
    const ptr = this.check(this.call('mcgv_stream_append', this.handle, data.length));
    new Uint8Array(this.x.memory.buffer, ptr, data.length).set(data);
  }

  /** Bytes appended so far. */
  get byteLength() {
    return this.call('mcgv_stream_len', this.handle);
  }

  /** Opens (again) the bytes so far. `partial`: they are the start of a stream still arriving;
   *  `maxBands`: decode no more temporal-DCT bands than this; `maxPositions`: refuse a stream
   *  promising more vertices × frames (default 3·10⁷). Returns `info`: vertices, frames,
   *  triangles, fps, codec, uvSets, materials (names), segments ([start, end) frames), bands
   *  (total, decoded, lengths; of the open segment) or pictures (lattice, bitDepth), settings,
   *  truncated, fileLength. Throws an MCGVError when the bytes do not open. */
  open({ partial = false, maxBands = -1, maxPositions = 0 } = {}) {
    this.info = null;
    this.check(this.call('mcgv_open', this.handle, maxBands ?? -1, partial ? 1 : 0, maxPositions));
    this.info = this.readInfo();
    return this.info;
  }

  /** Reads the first frame of the bytes so far — the stream's first parts suffice — to draw
   *  while the rest arrives: { info, positions } (info: vertices, frames, triangles, fps, codec,
   *  uvSets, materials, hasMaterials, attributesKnown: false while the texture coordinates may
   *  still come). Until the stream opens, triangles(), texcoords() and materials() give its mesh.
   *  Throws an MCGVError while too few bytes have arrived. */
  firstFrame() {
    const ptr = this.check(this.call('mcgv_first_frame', this.handle));
    const len = this.call('mcgv_text_len', this.handle);
    const info = JSON.parse(decoder.decode(new Uint8Array(this.x.memory.buffer, ptr, len)));
    this.first = info;
    const p = this.check(this.call('mcgv_first_positions', this.handle));
    const positions = new Float32Array(this.x.memory.buffer, p, 3 * info.vertices).slice();
    return { info, positions };
  }

  /** The counts of the open stream, else of its first frame. */
  get mesh() {
    const m = this.info ?? this.first;
    if (!m) throw new MCGVError('the stream is not open');
    return m;
  }

  readInfo() {
    const ptr = this.check(this.call('mcgv_info', this.handle));
    const len = this.call('mcgv_text_len', this.handle);
    return JSON.parse(decoder.decode(new Uint8Array(this.x.memory.buffer, ptr, len)));
  }

  /** The triangles: 3 vertex indices each. */
  triangles() {
    const ptr = this.check(this.call('mcgv_triangles', this.handle));
    return new Uint32Array(this.x.memory.buffer, ptr, 3 * this.mesh.triangles).slice();
  }

  /** Texture coordinate set `set` (u, v per vertex), or null. */
  texcoords(set = 0) {
    if (set >= this.mesh.uvSets) return null;
    const ptr = this.check(this.call('mcgv_texcoords', this.handle, set));
    return new Float32Array(this.x.memory.buffer, ptr, 2 * this.mesh.vertices).slice();
  }

  /** Each triangle's material index (into info.materials), or null. */
  materials() {
    if (!this.mesh.hasMaterials) return null;
    const ptr = this.check(this.call('mcgv_materials', this.handle));
    return new Uint32Array(this.x.memory.buffer, ptr, this.mesh.triangles).slice();
  }

  /** Decodes frame `f` into `out` (a Float32Array of 3 × vertices: x, y, z per vertex). */
  decodeFrame(f, out = new Float32Array(3 * this.info.vertices)) {
    const ptr = this.check(this.call('mcgv_decode_frame', this.handle, f));
    out.set(new Float32Array(this.x.memory.buffer, ptr, 3 * this.info.vertices));
    return out;
  }

  /** Decodes every frame into `out` (frames × 3 × vertices floats). */
  decodeAll(out = new Float32Array(3 * this.info.vertices * this.info.frames)) {
    const ptr = this.check(this.call('mcgv_decode_all', this.handle));
    out.set(new Float32Array(this.x.memory.buffer, ptr, 3 * this.info.vertices * this.info.frames));
    return out;
  }

  /** Frame `f`'s coded picture (picture codecs): { data: Uint8Array, key: boolean }. */
  codedPicture(f) {
    const ptr = this.check(this.call('mcgv_coded_picture', this.handle, f));
    const len = this.call('mcgv_text_len', this.handle);
    const data = new Uint8Array(this.x.memory.buffer, ptr, len).slice();
    return { data, key: this.call('mcgv_coded_key', this.handle) === 1 };
  }

  /** Decodes frame `f` from its picture decoded outside (a Uint16Array of width × height samples,
   *  x | y | z side by side) into `out`. */
  decodeFrameFromPicture(f, samples, width, height, out = new Float32Array(3 * this.info.vertices)) {
    const dst = this.check(this.call('mcgv_picture_buffer', this.handle, width, height));
    new Uint16Array(this.x.memory.buffer, dst, width * height).set(samples);
    const ptr = this.check(this.call('mcgv_decode_frame_from_picture', this.handle, f, width, height));
    out.set(new Float32Array(this.x.memory.buffer, ptr, 3 * this.info.vertices));
    return out;
  }

  /** Bytes of WebAssembly memory the stream's instance holds. */
  get memoryBytes() {
    return this.x.memory.buffer.byteLength;
  }

  /** Frees the stream (its instance goes with the last reference). */
  free() {
    if (!this.dead) this.call('mcgv_stream_free', this.handle);
    this.dead = true;
  }
}
