// Decode speed of the WebAssembly decoder in headless Chromium and in Node (both V8), and the
// player page's memory while it plays, for docs/web.md. The native figure beside it comes from
// `cargo run --release -p mcgv-web --example decode_speed -- FILE.mcgv`.
//
//   node web/bench.mjs FILE.mcgv [RUNS]     (after `make web-build`)
import { spawn } from 'node:child_process';
import fs from 'node:fs';
import path from 'node:path';
import readline from 'node:readline';
import { fileURLToPath } from 'node:url';
import { chromium } from 'playwright-core';
import { MCGV } from './mcgv.js';

const web = path.dirname(fileURLToPath(import.meta.url));
const root = path.resolve(web, '..');
const file = path.resolve(process.argv[2] ?? '');
const runs = Number(process.argv[3] ?? 5);
if (!fs.existsSync(file)) {
  console.error('usage: node web/bench.mjs FILE.mcgv [RUNS]');
  process.exit(2);
}
const name = path.basename(file);

// Node: the same module and .wasm.
const bytes = fs.readFileSync(file);
const mcgv = await MCGV.load(fs.readFileSync(path.join(web, 'mcgv_web.wasm')));
let nodeBest = Infinity;
let frames = 0;
for (let i = 0; i < runs; i++) {
  const s = mcgv.stream();
  const t0 = performance.now();
  s.append(bytes);
  frames = s.open().frames;
  s.decodeAll();
  nodeBest = Math.min(nodeBest, performance.now() - t0);
  s.free();
}

const server = spawn(process.execPath, [path.join(web, 'serve.mjs'), web,
  '--mount', `/three=${path.join(root, 'scripts/node/node_modules/three')}`,
  '--mount', `/data=${path.dirname(file)}`], { stdio: ['ignore', 'pipe', 'inherit'] });
const port = Number(await new Promise((resolve) => readline.createInterface({ input: server.stdout }).once('line', resolve)));
const browser = await chromium.launch({
  executablePath: process.env.CHROMIUM ?? '/usr/bin/chromium',
  args: ['--no-sandbox', '--disable-gpu', '--no-first-run', '--disable-background-networking', '--disable-component-update',
    '--disable-sync', '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--enable-precise-memory-info'],
});
try {
  const page = await browser.newPage();
  await page.goto(`http://127.0.0.1:${port}/example/?ui=0`);
  const browserBest = await page.evaluate(async ({ src, runs }) => {
    const { MCGV } = await import('/mcgv.js');
    const m = await MCGV.load('/mcgv_web.wasm');
    const b = new Uint8Array(await (await fetch(src)).arrayBuffer());
    let best = Infinity;
    for (let i = 0; i < runs; i++) {
      const s = m.stream();
      const t0 = performance.now();
      s.append(b);
      s.open();
      s.decodeAll();
      best = Math.min(best, performance.now() - t0);
      s.free();
    }
    return best;
  }, { src: `/data/${name}`, runs });
  await page.close();

  // The player, playing the clip for 5 s: the renderer process's resident memory, the JS heap and
  // the decoder's WebAssembly memory.
  const player = await browser.newPage({ viewport: { width: 1280, height: 720 } });
  await player.goto(`http://127.0.0.1:${port}/example/?src=/data/${name}`);
  await player.waitForFunction(() => ['done', 'error'].includes(window.mcgvPage?.state.phase), null, { timeout: 120000 });
  await player.waitForTimeout(5000);
  const memory = await player.evaluate(() => ({
    heap: performance.memory.usedJSHeapSize,
    decoder: window.mcgvPage.animation.decoderBytes,
    error: window.mcgvPage.state.error,
  }));
  const cdp = await browser.newBrowserCDPSession();
  const { processInfo } = await cdp.send('SystemInfo.getProcessInfo');
  const renderers = processInfo.filter((p) => p.type === 'renderer').map((p) => p.id);
  // The page's renderer is the largest (the others: a spare one, the closed speed page's).
  const sizes = renderers.map(vmRss).sort((a, b) => b - a);
  const rss = sizes[0] ?? 0;
  const mb = (x) => (x / 1048576).toFixed(1);
  console.log(`${name}: ${frames} frames; decode of every frame (open included), best of ${runs}:`);
  console.log(`  Chromium ${browserBest.toFixed(1)} ms (${((1000 * frames) / browserBest).toFixed(0)} frames/s)`);
  console.log(`  Node     ${nodeBest.toFixed(1)} ms (${((1000 * frames) / nodeBest).toFixed(0)} frames/s)`);
  console.log(`player while playing: renderer RSS ${mb(rss)} MB (other renderers: ${sizes.slice(1).map(mb).join(', ')} MB), ` +
    `JS heap ${mb(memory.heap)} MB, decoder memory ${mb(memory.decoder)} MB${memory.error ? `, error: ${memory.error}` : ''}`);
} finally {
  await browser.close();
  server.kill();
}

function vmRss(pid) {
  const m = /VmRSS:\s+(\d+) kB/.exec(fs.readFileSync(`/proc/${pid}/status`, 'utf8'));
  return m ? 1024 * Number(m[1]) : 0;
}
