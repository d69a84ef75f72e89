// MCGVLoader: a three.js loader for `.mcgv` animated meshes, in the style of three's own loaders
// (GLTFLoader, DRACOLoader). An ES module: the page maps 'three' with an import map.
//
//   const loader = new MCGVLoader();                    // finds mcgv_web.wasm beside this file
//   loader.load('clip.mcgv', (animation) => {
//     scene.add(new THREE.Mesh(animation.geometry, animation.materials ?? material));
//   }, onProgress, onError);
//   renderer.setAnimationLoop((ms) => animation.setTime(ms / 1000));
//
// The file streams in: `fetch`'s body reader feeds the decoder as bytes arrive. `onLoad` is called as
// soon as something can be drawn: a temporal-DCT (tdct) stream's whole clip, coarse, once its first
// band has arrived (it sharpens as later bands land: 'frames' events), a JPEG stream's frames one by
// one as their pictures arrive. A stream cut into temporal segments is drawn once complete. AV1
// pictures are decoded by the browser's WebCodecs where it can; HEVC and MPEG-4 streams, or AV1
// where WebCodecs cannot, end in an error naming the codec the browser is missing.
//
// The animation is an EventDispatcher: 'header' (geometry ready, no frame yet), 'frames' (new or
// sharper frames), 'progress' (bytes), 'done', 'error' ({ error }).

import {
  Box3,
  BufferAttribute,
  BufferGeometry,
  DynamicDrawUsage,
  EventDispatcher,
  Loader,
  MeshBasicMaterial,
  MeshStandardMaterial,
  Sphere,
  Vector3,
} from 'three';
import { MCGV, MCGVError } from './mcgv.js';

export { MCGVError };

export class MCGVLoader extends Loader {
  constructor(manager) {
    super(manager);
    this.wasmURL = new URL('./mcgv_web.wasm', import.meta.url);
    this.like = null;
    this.decoder = null;
    this.maxBands = -1;
  }

  /** Decodes no more than `n` temporal-DCT bands (a preview, as `decode --bands N`); -1: all. */
  setMaxBands(n) {
    this.maxBands = n;
    return this;
  }

  /** Where the WebAssembly decoder is (default: mcgv_web.wasm beside this module). */
  setWasmURL(url) {
    this.wasmURL = url;
    this.decoder = null;
    return this;
  }

  /** Materials to dress the mesh in, as `decode --like` does: a GLTFLoader result (or an object
   *  with `scene`) whose materials are matched to the stream's by name (else its first). */
  setLike(gltf) {
    this.like = gltf;
    return this;
  }

  /** The compiled decoder, once. */
  getDecoder() {
    this.decoder ??= MCGV.load(this.wasmURL);
    return this.decoder;
  }

  /** Streams `url`; `onLoad(animation)` once something can be drawn (see the file's header). */
  load(url, onLoad, onProgress, onError) {
    const animation = new MCGVAnimation(this);
    let loaded = false;
    const ready = () => {
      if (!loaded) {
        loaded = true;
        onLoad?.(animation);
      }
    };
    animation.addEventListener('frames', ready);
    animation.addEventListener('progress', (e) => onProgress?.(e.event));
    animation.addEventListener('error', (e) => {
      if (onError) onError(e.error);
      else console.error(e.error);
    });
    const resolved = this.manager.resolveURL(this.path ? this.path + url : url);
    this.manager.itemStart(resolved);
    animation
      .stream(resolved, this.requestHeader, this.withCredentials)
      .catch((error) => animation.fail(error))
      .finally(() => this.manager.itemEnd(resolved));
    return animation;
  }

  /** A whole stream already in memory (ArrayBuffer or Uint8Array): the decoded animation. */
  async parse(buffer) {
    const animation = new MCGVAnimation(this);
    await animation.start();
    animation.feed(buffer instanceof Uint8Array ? buffer : new Uint8Array(buffer));
    await animation.finish();
    if (animation.error) throw animation.error;
    return animation;
  }
}

/** A decoded (or decoding) animation: a BufferGeometry whose positions follow `setFrame`/`setTime`. */
export class MCGVAnimation extends EventDispatcher {
  constructor(loader) {
    super();
    this.loader = loader;
    this.geometry = new BufferGeometry();
    this.materials = null;
    this.info = null;
    this.frames = null; // frames × 3 × vertices
    this.ready = null; // per frame: 1 once decoded
    this.bytesReceived = 0;
    this.bytesTotal = 0;
    this.bandsDecoded = 0;
    this.framesDecoded = 0;
    this.decodeMsPerFrame = 0;
    this.firstFrameBytes = 0; // bytes received when a frame could first be drawn (the first frame)
    this.firstFrameChunkStart = 0; // … and where the chunk that brought them started
    this.chunkStart = 0; // where the chunk being fed starts in the stream
    this.firstClipBytes = 0; // … when every frame could (a tdct stream's first band)
    this.previewed = false;
    this.previewDressed = false;
    this.done = false;
    this.error = null;
    this.current = -1;
    this.stream_ = null;
    this.nextOpenAt = 0;
    this.openedBytes = 0; // bytes the open stream holds (an open stream sees no later bytes)
    this.opened = false;
  }

  get frameCount() {
    return this.info?.frames ?? 0;
  }

  get fps() {
    return this.info?.fps > 0 ? this.info.fps : 30;
  }

  get duration() {
    return this.frameCount / this.fps;
  }

  /** Bytes of WebAssembly memory the decoder holds. */
  get decoderBytes() {
    return this.stream_?.dead === false ? this.stream_.memoryBytes : 0;
  }

  async start() {
    const mcgv = await this.loader.getDecoder();
    this.stream_ = mcgv.stream();
  }

  /** Fetches `url` and feeds its body to the decoder as it arrives. */
  async stream(url, headers = {}, withCredentials = false) {
    await this.start();
    const response = await fetch(url, { headers, credentials: withCredentials ? 'include' : 'same-origin' });
    if (!response.ok) throw new MCGVError(`${url}: HTTP ${response.status} ${response.statusText}`);
    this.bytesTotal = Number(response.headers.get('content-length')) || 0;
    const reader = response.body.getReader();
    for (;;) {
      const { done, value } = await reader.read();
      if (done) break;
      this.feed(value);
      if (this.error) {
        reader.cancel().catch(() => {});
        return;
      }
    }
    await this.finish();
  }

  /** Appends bytes that arrived and draws what they allow. */
  feed(bytes) {
    if (this.error) return;
    try {
      this.stream_.append(bytes);
      this.chunkStart = this.bytesReceived;
      this.bytesReceived += bytes.length;
      this.dispatchEvent({ type: 'progress', event: { loaded: this.bytesReceived, total: this.bytesTotal, lengthComputable: this.bytesTotal > 0 } });
      this.advance(false);
    } catch (error) {
      this.fail(error);
    }
  }

  /** The last bytes have arrived: decodes everything, or fails with the stream's error. */
  async finish() {
    if (this.error) return;
    this.done = true;
    try {
      this.advance(true);
      if (this.needsPictures()) await this.decodePictures();
      this.dispatchEvent({ type: 'done' });
    } catch (error) {
      this.fail(error);
    }
  }

  fail(error) {
    if (this.error) return;
    this.error = error instanceof Error ? error : new MCGVError(String(error));
    this.dispatchEvent({ type: 'error', error: this.error });
  }

  /** Opens, reopens and decodes as far as the bytes so far allow. */
  advance(last) {
    const s = this.stream_;
    if (!this.opened) {
      if (!last && this.bytesReceived < this.nextOpenAt) return;
      if (!this.previewed && !last) this.preview();
      try {
        this.info = s.open({ partial: !last, maxBands: this.loader.maxBands });
      } catch (error) {
        if (last || error.panic) throw error;
        // Not enough yet: try again when a little more has come.
        this.nextOpenAt = this.bytesReceived + Math.max(1024, this.bytesReceived >> 4);
        return;
      }
      this.opened = true;
      this.openedBytes = this.bytesReceived;
      this.nextOpenAt = this.nextPictureOpen();
      if (!this.previewed || !this.previewDressed) this.build();
      if (this.needsPictures()) return;
      this.decodeWhatArrived(last);
      return;
    }
    if (this.needsPictures()) return;
    const segmented = this.info.segments.length > 1;
    if (this.info.codec === 'tdct' || segmented) {
      // Reopen for more bands (or the whole of a segmented stream) at the next milestone.
      const wanted = this.loader.maxBands >= 0 ? this.loader.maxBands : Infinity;
      const complete = this.info.bands && this.bandsDecoded >= Math.min(wanted, this.info.bands.total) && !segmented;
      if (complete || (!last && this.bytesReceived < this.nextOpenAt)) return;
      this.info = s.open({ partial: !last, maxBands: this.loader.maxBands });
      this.decodeWhatArrived(last);
    } else {
      // The open stream holds the bytes of when it opened: frames whose pictures came later are
      // reached by reopening on the bytes so far, at growing milestones and at the end.
      if (this.bytesReceived > this.openedBytes && (last || this.bytesReceived >= this.nextOpenAt)) {
        this.info = s.open({ partial: !last, maxBands: this.loader.maxBands });
        this.openedBytes = this.bytesReceived;
        this.nextOpenAt = this.nextPictureOpen();
      }
      this.decodeWhatArrived(last);
    }
  }

  /** When to reopen a stream of pictures decoded here: a quarter more bytes (64 KiB at least), so
   *  the copies a reopening makes add up to a few times the file, not its square. */
  nextPictureOpen() {
    return this.bytesReceived + Math.max(65536, this.bytesReceived >> 2);
  }

  /** Draws the first frame from the stream's first parts (the whole clip needs the predictor's
   *  and the first band's bytes); its texture coordinates follow when they have arrived. */
  preview() {
    let first;
    try {
      first = this.stream_.firstFrame();
    } catch (error) {
      if (error.panic) throw error;
      return;
    }
    this.info = first.info;
    this.build();
    this.previewed = true;
    this.previewDressed = first.info.attributesKnown;
    this.geometry.attributes.position.array.set(first.positions);
    this.geometry.attributes.position.needsUpdate = true;
    this.geometry.computeVertexNormals();
    const v = first.info.vertices;
    const min = [Infinity, Infinity, Infinity];
    const max = [-Infinity, -Infinity, -Infinity];
    for (let i = 0; i < 3 * v; i++) {
      min[i % 3] = Math.min(min[i % 3], first.positions[i]);
      max[i % 3] = Math.max(max[i % 3], first.positions[i]);
    }
    this.geometry.boundingBox = new Box3(new Vector3(...min), new Vector3(...max));
    this.geometry.boundingSphere = this.geometry.boundingBox.getBoundingSphere(new Sphere());
    this.firstFrameBytes = this.bytesReceived;
    this.firstFrameChunkStart = this.chunkStart;
    this.dispatchEvent({ type: 'frames', preview: true });
  }

  /** Decodes the frames the open stream gives now. */
  decodeWhatArrived(last) {
    const info = this.info;
    const segmented = info.segments.length > 1;
    if (info.codec === 'tdct' || segmented) {
      if (segmented && !last) return; // a segmented stream opens once whole
      const bands = info.bands ? info.bands.decoded : 0;
      if (info.bands && bands === 0) {
        this.scheduleBands();
        return;
      }
      const t0 = performance.now();
      this.stream_.decodeAll(this.frames);
      this.decodeMsPerFrame = (performance.now() - t0) / info.frames;
      this.ready.fill(1);
      this.framesDecoded = info.frames;
      this.bandsDecoded = bands;
      this.scheduleBands();
      this.shown();
    } else {
      // A picture codec decoded here (JPEG): each frame whose picture has arrived, in order.
      let added = 0;
      let ms = 0;
      for (let f = this.framesDecoded; f < info.frames; f++) {
        const t0 = performance.now();
        try {
          this.stream_.decodeFrame(f, this.frames.subarray(3 * info.vertices * f, 3 * info.vertices * (f + 1)));
        } catch (error) {
          if (last || error.panic) throw error;
          break;
        }
        ms += performance.now() - t0;
        this.ready[f] = 1;
        this.framesDecoded = f + 1;
        added++;
      }
      if (added) {
        this.decodeMsPerFrame = ms / added;
        this.shown();
      }
    }
  }

  /** When to reopen a tdct stream: when the bands needed to double those decoded have arrived
   *  (their lengths are in the band index; the download's length places them), else when half as
   *  many bytes again have come. */
  scheduleBands() {
    const bands = this.info.bands;
    if (!bands || !this.bytesTotal) {
      this.nextOpenAt = Math.ceil(this.bytesReceived * 1.5);
      return;
    }
    const target = Math.min(bands.total, Math.max(bands.decoded + 1, 2 * bands.decoded));
    let after = 0;
    for (let k = target; k < bands.total; k++) after += bands.lengths[k];
    this.nextOpenAt = this.bytesTotal - after;
  }

  shown() {
    if (!this.firstFrameBytes) {
      this.firstFrameBytes = this.bytesReceived;
      this.firstFrameChunkStart = this.chunkStart;
    }
    if (!this.firstClipBytes) this.firstClipBytes = this.bytesReceived;
    this.updateBounds();
    const x = this.current < 0 ? 0 : this.current;
    this.current = -1;
    this.setFrame(x);
    this.dispatchEvent({ type: 'frames', bands: this.bandsDecoded });
  }

  /** The geometry of the open stream: index, UVs, material groups; positions to come. */
  build() {
    const s = this.stream_;
    const info = this.info;
    const v = info.vertices;
    this.frames = new Float32Array(3 * v * info.frames);
    this.ready = new Uint8Array(info.frames);
    let index = s.triangles();
    const materials = s.materials();
    const g = this.geometry;
    g.clearGroups();
    if (materials && info.materials.length > 1) {
      // One group per material: the triangles sorted by it.
      const order = [...materials.keys()].sort((a, b) => materials[a] - materials[b]);
      const sorted = new Uint32Array(index.length);
      order.forEach((t, i) => sorted.set(index.subarray(3 * t, 3 * t + 3), 3 * i));
      index = sorted;
      let start = 0;
      for (let i = 1; i <= order.length; i++) {
        if (i === order.length || materials[order[i]] !== materials[order[start]]) {
          g.addGroup(3 * start, 3 * (i - start), materials[order[start]]);
          start = i;
        }
      }
    }
    g.setIndex(new BufferAttribute(index, 1));
    const drawn = g.attributes.position?.array;
    const positions = new BufferAttribute(drawn?.length === 3 * v ? drawn : new Float32Array(3 * v), 3);
    positions.setUsage(DynamicDrawUsage);
    g.setAttribute('position', positions);
    const uv = s.texcoords(0);
    if (uv) g.setAttribute('uv', new BufferAttribute(uv, 2));
    this.materials = this.likeMaterials();
    this.dispatchEvent({ type: 'header', info });
  }

  /** The `like` glTF's materials for the stream's material names (its first for a name it lacks). */
  likeMaterials() {
    const gltf = this.loader.like;
    if (!gltf) return null;
    const found = [];
    (gltf.scene ?? gltf).traverse((o) => {
      if (!o.isMesh) return;
      for (const m of Array.isArray(o.material) ? o.material : [o.material]) if (!found.includes(m)) found.push(m);
    });
    if (!found.length) return null;
    const names = this.info.materials.length ? this.info.materials : [''];
    const list = names.map((n) => found.find((m) => m.name === n) ?? found[0]);
    return list.length === 1 ? list[0] : list;
  }

  updateBounds() {
    const v = this.info.vertices;
    const min = [Infinity, Infinity, Infinity];
    const max = [-Infinity, -Infinity, -Infinity];
    for (let f = 0; f < this.info.frames; f++) {
      if (!this.ready[f]) continue;
      const frame = this.frames.subarray(3 * v * f, 3 * v * (f + 1));
      for (let i = 0; i < frame.length; i += 3) {
        for (let a = 0; a < 3; a++) {
          const x = frame[i + a];
          if (x < min[a]) min[a] = x;
          if (x > max[a]) max[a] = x;
        }
      }
    }
    if (!Number.isFinite(min[0])) return;
    const g = this.geometry;
    g.boundingBox = new Box3(new Vector3(...min), new Vector3(...max));
    g.boundingSphere = g.boundingBox.getBoundingSphere(new Sphere());
  }

  /** Draws frame `x` (a number of frames, fractional: interpolated between its two neighbours,
   *  wrapping at the end). A frame not decoded yet shows the nearest decoded one before it. */
  setFrame(x) {
    const n = this.frameCount;
    if (!n || !this.ready) return;
    x = ((x % n) + n) % n;
    if (x === this.current) return;
    let i = Math.floor(x);
    while (i > 0 && !this.ready[i]) i--;
    if (!this.ready[i]) return;
    const j = (i + 1) % n;
    const a = this.ready[j] && i === Math.floor(x) ? x - i : 0;
    const v3 = 3 * this.info.vertices;
    const out = this.geometry.attributes.position.array;
    const p = this.frames.subarray(v3 * i, v3 * (i + 1));
    if (a === 0) out.set(p);
    else {
      const q = this.frames.subarray(v3 * j, v3 * (j + 1));
      for (let k = 0; k < v3; k++) out[k] = p[k] + a * (q[k] - p[k]);
    }
    this.geometry.attributes.position.needsUpdate = true;
    this.geometry.computeVertexNormals();
    this.current = x;
  }

  /** Draws the animation at `seconds` (looping), at the stream's frame rate. */
  setTime(seconds) {
    this.setFrame(seconds * this.fps);
  }

  /** Positions of frame `f` as decoded (a view: frames × 3 × vertices), or null if not yet. */
  frame(f) {
    if (!this.ready?.[f]) return null;
    const v3 = 3 * this.info.vertices;
    return this.frames.subarray(v3 * f, v3 * (f + 1));
  }

  /** A picture codec this WebAssembly build does not decode (MPEG-4, HEVC, AV1). */
  needsPictures() {
    return this.info && this.info.pictures && this.info.codec !== 'jpeg';
  }

  /** Decodes the pictures of an AV1 (HEVC, MPEG-4) stream with WebCodecs, then the frames. */
  async decodePictures() {
    const t0 = performance.now();
    await decodeWithWebCodecs(this.stream_, this.info, (f, samples, width, height) => {
      const v3 = 3 * this.info.vertices;
      this.stream_.decodeFrameFromPicture(f, samples, width, height, this.frames.subarray(v3 * f, v3 * (f + 1)));
      this.ready[f] = 1;
      this.framesDecoded++;
    });
    this.decodeMsPerFrame = (performance.now() - t0) / this.info.frames;
    this.shown();
  }

  /** Unlit, textured or not, as the glTF test render draws (geometry and UVs, not normals). */
  static unlit(material) {
    if (!material) return new MeshBasicMaterial({ color: 0xb0b0b0 });
    return new MeshBasicMaterial({ map: material.map, color: material.color, side: material.side, transparent: material.transparent, alphaTest: material.alphaTest });
  }

  /** A default lit material for streams without one. */
  static defaultMaterial() {
    return new MeshStandardMaterial({ color: 0xc8b8a0, roughness: 0.7, metalness: 0 });
  }

  dispose() {
    this.geometry.dispose();
    this.stream_?.free();
  }
}

/** What to do about pictures deeper than WebCodecs takes (Chromium decodes 10-bit AV1, not 12-bit). */
function deepHint(info) {
  return info.pictures?.bitDepth > 10 ? '; `mcgv-video encode --bit-depth 10` makes pictures it can' : '';
}

/** WebCodecs' codec strings of the picture codecs (4:4:4 pictures). */
function codecString(info) {
  const depth = info.pictures.bitDepth;
  switch (info.codec) {
    case 'av1':
      // Profile 1 (High: 4:4:4) at 10 bits, profile 2 (Professional) at 12; level 6.0 main tier.
      return depth === 12 ? 'av01.2.16M.12.0.000' : 'av01.1.16M.10.0.000';
    case 'hevc':
      return depth === 12 ? 'hvc1.4.10.L153.B0' : 'hvc1.4.10.L153.B0';
    case 'mpeg4':
      return 'mp4v.20.9';
    default:
      return info.codec;
  }
}

/** Decodes every picture of `stream` with WebCodecs and hands each (x | y | z side by side, 16-bit
 *  samples) to `onPicture(f, samples, width, height)`, in frame order. */
export async function decodeWithWebCodecs(stream, info, onPicture) {
  const codec = codecString(info);
  if (typeof VideoDecoder === 'undefined') {
    throw new MCGVError(`this browser has no WebCodecs VideoDecoder: it cannot decode ${info.codec} pictures`);
  }
  const [w, h] = info.pictures.lattice;
  const config = { codec, codedWidth: w, codedHeight: h, hardwareAcceleration: 'prefer-software' };
  const support = await VideoDecoder.isConfigSupported(config).catch(() => ({ supported: false }));
  if (!support.supported) {
    throw new MCGVError(`this browser cannot decode ${info.codec} pictures: WebCodecs has no decoder for ${codec}`);
  }
  let failure = null;
  const pending = new Map();
  const decoder = new VideoDecoder({
    output: (frame) => pending.set(frame.timestamp, frame),
    error: (e) => {
      failure = e;
    },
  });
  decoder.configure(config);
  const frames = info.frames;
  const what = `${info.pictures.bitDepth}-bit ${info.codec}`;
  for (let f = 0; f < frames; f++) {
    const { data, key } = stream.codedPicture(f);
    try {
      decoder.decode(new EncodedVideoChunk({ type: key ? 'key' : 'delta', timestamp: f, data }));
    } catch (e) {
      // Chromium 156 says so of 12-bit AV1 (profile 2), whose configuration it claims to support.
      decoder.close();
      throw new MCGVError(`this browser cannot decode ${what} pictures: WebCodecs refused frame ${f} (${e.message})${deepHint(info)}`);
    }
  }
  await decoder.flush().catch((e) => {
    failure ??= e;
  });
  decoder.close();
  try {
    if (failure) throw new MCGVError(`this browser cannot decode ${what} pictures: WebCodecs failed (${failure.message ?? failure})${deepHint(info)}`);
    for (let f = 0; f < frames; f++) {
      const frame = pending.get(f);
      if (!frame) throw new MCGVError(`WebCodecs gave no picture for frame ${f}`);
      onPicture(f, await pictureSamples(frame, w, h, info), 3 * w, h);
    }
  } finally {
    for (const frame of pending.values()) frame.close();
  }
}

/** The x | y | z samples of a decoded 4:4:4 picture: its Y, U and V planes side by side. */
async function pictureSamples(frame, w, h, info) {
  const format = frame.format;
  if (!/^I444P1[02]$/.test(format ?? '')) {
    throw new MCGVError(
      `WebCodecs gave ${info.codec} pictures as ${format ?? 'an opaque format'}, not the 4:4:4 ` +
        `${info.pictures.bitDepth}-bit samples the stream holds`,
    );
  }
  const buffer = new Uint8Array(frame.allocationSize());
  const layout = await frame.copyTo(buffer);
  const view = new DataView(buffer.buffer);
  const out = new Uint16Array(3 * w * h);
  for (let p = 0; p < 3; p++) {
    const { offset, stride } = layout[p];
    for (let y = 0; y < h; y++) {
      for (let x = 0; x < w; x++) out[y * 3 * w + p * w + x] = view.getUint16(offset + y * stride + 2 * x, true);
    }
  }
  return out;
}
