// The player page (index.html): three.js draws the MCGVLoader's geometry; the panel shows the
// bytes received, the bands decoded and the decode time per frame. `window.mcgvPage` is what the
// tests (web/test/) read and drive.
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { MCGVLoader, MCGVAnimation } from '../MCGVLoader.js';

const q = new URLSearchParams(location.search);
const $ = (id) => document.getElementById(id);
let fixedFrame = q.has('frame') ? Number(q.get('frame')) : null;
const size = q.has('size') ? Number(q.get('size')) : 0;
if (q.get('ui') === '0') {
  $('panel').style.display = 'none';
  $('hint').style.display = 'none';
}

const renderer = new THREE.WebGLRenderer({ antialias: !size, preserveDrawingBuffer: true });
renderer.setClearColor(0x203040, 1);
renderer.setPixelRatio(size ? 1 : window.devicePixelRatio);
$('view').appendChild(renderer.domElement);
const scene = new THREE.Scene();
scene.add(new THREE.HemisphereLight(0xffffff, 0x444444, 2));
const sun = new THREE.DirectionalLight(0xffffff, 2);
sun.position.set(1, 2, 3);
scene.add(sun);
const camera = new THREE.PerspectiveCamera(30, 1, 0.01, 1000);
const controls = new OrbitControls(camera, renderer.domElement);

function resize() {
  const w = size || window.innerWidth;
  const h = size || window.innerHeight;
  renderer.setSize(w, h);
  camera.aspect = w / h;
  camera.updateProjectionMatrix();
}
window.addEventListener('resize', resize);
resize();

/** Frames the box (x0, y0, z0, x1, y1, z1) as the glTF test render does. */
function frame(box) {
  const [x0, y0, z0, x1, y1, z1] = box;
  const center = new THREE.Vector3((x0 + x1) / 2, (y0 + y1) / 2, (z0 + z1) / 2);
  const radius = Math.hypot(x1 - x0, y1 - y0, z1 - z0) / 2 || 1;
  camera.near = radius / 100;
  camera.far = radius * 100;
  const distance = radius / Math.sin(THREE.MathUtils.degToRad(15));
  camera.position.copy(center).add(new THREE.Vector3(1, 0.4, 1.6).normalize().multiplyScalar(distance));
  camera.lookAt(center);
  controls.target.copy(center);
  camera.updateProjectionMatrix();
  controls.update();
}

const state = {
  phase: 'idle', // idle, loading, playing, done, error
  error: null,
  bytesReceived: 0,
  bytesTotal: 0,
  firstFrameBytes: 0, // bytes received when the first frame was drawn
  firstFrameChunkStart: 0, // where the chunk that brought them started
  firstClipBytes: 0,
  firstBands: null,
  steps: [],
  bandsDecoded: 0,
  bandsTotal: 0,
  framesDecoded: 0,
  decodeMsPerFrame: 0,
  frame: 0,
  info: null,
};
let animation = null;
let mesh = null;
let playing = fixedFrame === null;
let clockStart = performance.now();
let framed = false;
let like = null;

function showError(error) {
  state.phase = 'error';
  state.error = String(error?.message ?? error);
  $('error').textContent = state.error;
  $('error').style.display = 'block';
  window.dispatchEvent(new CustomEvent('mcgv-error', { detail: state.error }));
}

function human(bytes) {
  return bytes < 1024 ? `${bytes} B` : bytes < 1048576 ? `${(bytes / 1024).toFixed(1)} KB` : `${(bytes / 1048576).toFixed(2)} MB`;
}

function updatePanel() {
  const a = animation;
  if (!a) return;
  Object.assign(state, {
    bytesReceived: a.bytesReceived,
    bytesTotal: a.bytesTotal,
    firstFrameBytes: a.firstFrameBytes,
    firstFrameChunkStart: a.firstFrameChunkStart,
    firstClipBytes: a.firstClipBytes,
    bandsDecoded: a.bandsDecoded,
    bandsTotal: a.info?.bands?.total ?? 0,
    framesDecoded: a.framesDecoded,
    decodeMsPerFrame: a.decodeMsPerFrame,
    info: a.info,
  });
  $('bytes').textContent = a.bytesTotal ? `${human(a.bytesReceived)} / ${human(a.bytesTotal)}` : human(a.bytesReceived);
  $('bands').textContent = a.info?.bands ? `${a.bandsDecoded} / ${a.info.bands.total}` : '–';
  $('decoded').textContent = a.info ? `${a.framesDecoded} / ${a.info.frames}` : '0';
  $('ms').textContent = a.decodeMsPerFrame ? a.decodeMsPerFrame.toFixed(2) : '–';
  $('codec').textContent = a.info ? a.info.codec : '–';
  const heap = performance.memory ? performance.memory.usedJSHeapSize : 0;
  $('memory').textContent = `${human(heap + a.decoderBytes)} (JS ${human(heap)}, decoder ${human(a.decoderBytes)})`;
  if (a.info) {
    $('slider').max = String(Math.max(0, a.info.frames - 1));
  }
}

/** Loads a stream (a URL, or a dropped file's bytes). */
function open(source, name) {
  if (animation) {
    scene.remove(mesh);
    animation.dispose();
  }
  $('error').style.display = 'none';
  $('hint').style.display = 'none';
  Object.assign(state, { phase: 'loading', error: null, firstFrameBytes: 0, firstFrameChunkStart: 0, firstClipBytes: 0, firstBands: null, steps: [] });
  framed = false;
  const loader = new MCGVLoader();
  if (like) loader.setLike(like);
  if (q.has('bands')) loader.setMaxBands(Number(q.get('bands')));
  const onFrames = (a) => {
    if (!mesh || mesh.geometry !== a.geometry) {
      let material = a.materials;
      if (q.get('unlit') === '1') material = Array.isArray(material) ? material.map(MCGVAnimation.unlit) : MCGVAnimation.unlit(material);
      material ??= MCGVAnimation.defaultMaterial();
      mesh = new THREE.Mesh(a.geometry, material);
      mesh.frustumCulled = false;
      scene.add(mesh);
    }
    if (!framed && a.geometry.boundingBox) {
      const b = a.geometry.boundingBox;
      frame(q.has('bbox') ? q.get('bbox').split(',').map(Number) : [b.min.x, b.min.y, b.min.z, b.max.x, b.max.y, b.max.z]);
      framed = true;
    }
    if (state.phase === 'loading' && a.framesDecoded) state.phase = 'playing';
    // What was drawn when: [bytes received, bands decoded, frames decoded].
    const step = [a.bytesReceived, a.bandsDecoded, a.framesDecoded];
    if (String(state.steps.at(-1)) !== String(step)) state.steps.push(step);
    // keep=K (tests): frame K as first drawn from bands, to compare with `decode --bands N`.
    if (q.has('keep') && !state.firstBands && a.bandsDecoded > 0) {
      const k = Number(q.get('keep'));
      state.firstBands = { bands: a.bandsDecoded, frame: k, positions: Array.from(a.frame(k)) };
    }
    updatePanel();
  };
  if (typeof source === 'string') {
    animation = loader.load(source, onFrames, () => updatePanel(), showError);
  } else {
    animation = new MCGVAnimation(loader);
    animation.addEventListener('error', (e) => showError(e.error));
    animation
      .start()
      .then(() => {
        animation.feed(new Uint8Array(source));
        return animation.finish();
      })
      .then(() => !animation.error && onFrames(animation));
  }
  animation.addEventListener('frames', () => onFrames(animation));
  animation.addEventListener('done', () => {
    if (!animation.error) state.phase = 'done';
    updatePanel();
  });
  document.title = `${name ?? source} — mcgv-video player`;
}

$('play').addEventListener('click', () => {
  playing = !playing;
  $('play').textContent = playing ? 'pause' : 'play';
  clockStart = performance.now() - (state.frame / (animation?.fps ?? 30)) * 1000;
});
$('slider').addEventListener('input', () => {
  playing = false;
  $('play').textContent = 'play';
  state.frame = Number($('slider').value);
});

window.addEventListener('dragover', (e) => {
  e.preventDefault();
  $('drop').style.display = 'flex';
});
window.addEventListener('dragleave', () => ($('drop').style.display = 'none'));
window.addEventListener('drop', async (e) => {
  e.preventDefault();
  $('drop').style.display = 'none';
  const file = e.dataTransfer.files[0];
  if (file) open(await file.arrayBuffer(), file.name);
});

function render() {
  if (animation?.info) {
    if (fixedFrame !== null) state.frame = fixedFrame;
    else if (playing) state.frame = (((performance.now() - clockStart) / 1000) * animation.fps) % animation.frameCount;
    animation.setFrame(state.frame);
    $('frame').textContent = `frame ${state.frame.toFixed(1)} / ${animation.frameCount}`;
    if (playing) $('slider').value = String(state.frame);
  }
  renderer.render(scene, camera);
}
renderer.setAnimationLoop(render);
setInterval(updatePanel, 250);

/** What the tests read and drive. */
window.mcgvPage = {
  state,
  get animation() {
    return animation;
  },
  open,
  /** Shows fractional frame `x` (stops playing) and draws it now. */
  show(x) {
    playing = false;
    fixedFrame = x;
    render();
  },
  canvasDataURL() {
    render();
    return renderer.domElement.toDataURL('image/png');
  },
};

if (q.has('like')) {
  like = await new GLTFLoader().loadAsync(q.get('like')).catch((e) => {
    showError(`like ${q.get('like')}: ${e.message ?? e}`);
    return null;
  });
}
if (q.has('src')) open(q.get('src'));
