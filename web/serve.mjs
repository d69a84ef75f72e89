// A static file server on 127.0.0.1 for the example page and its tests (Node's standard library
// only). Serves ROOT; `--mount /PREFIX=DIR` serves DIR under /PREFIX/ too (three.js, media);
// `--throttle BYTES_PER_SECOND` sends `.mcgv` files no faster than that, in 50 slices a second,
// in 500 slices a second, as a slow network would; `--port N` (default 0: a free one). Prints the port on the first line
// of stdout, then serves until killed.
//
//   node web/serve.mjs web --mount /three=scripts/node/node_modules/three --port 8080
import http from 'node:http';
import fs from 'node:fs';
import path from 'node:path';

const args = process.argv.slice(2);
const mounts = [];
let root = null;
let throttle = 0;
let port = 0;
for (let i = 0; i < args.length; i++) {
  const a = args[i];
  if (a === '--mount') {
    const [prefix, dir] = args[++i].split('=');
    mounts.push([prefix.replace(/\/$/, '') + '/', path.resolve(dir)]);
  } else if (a === '--throttle') throttle = Number(args[++i]);
  else if (a === '--port') port = Number(args[++i]);
  else root = path.resolve(a);
}
if (!root) {
  console.error('usage: serve.mjs ROOT [--mount /PREFIX=DIR]… [--throttle BYTES_PER_SECOND] [--port N]');
  process.exit(2);
}

const TYPES = {
  '.html': 'text/html; charset=utf-8',
  '.js': 'text/javascript',
  '.mjs': 'text/javascript',
  '.json': 'application/json',
  '.wasm': 'application/wasm',
  '.glb': 'model/gltf-binary',
  '.png': 'image/png',
  '.mcgv': 'application/octet-stream',
  '.pc2': 'application/octet-stream',
};

/** The file a URL path names, inside ROOT or a mount, or null. */
function resolve(urlPath) {
  let p;
  try {
    p = decodeURIComponent(urlPath.split('?')[0]);
  } catch {
    return null;
  }
  for (const [prefix, dir] of mounts) {
    if (p.startsWith(prefix)) return inside(dir, p.slice(prefix.length));
  }
  return inside(root, p);
}

function inside(dir, rel) {
  const file = path.resolve(dir, '.' + path.posix.normalize('/' + rel));
  return file === dir || file.startsWith(dir + path.sep) ? file : null;
}

const server = http.createServer((req, res) => {
  let file = resolve(req.url);
  if (file && fs.existsSync(file) && fs.statSync(file).isDirectory()) file = path.join(file, 'index.html');
  if (!file || !fs.existsSync(file) || req.method !== 'GET') {
    res.writeHead(404, { 'content-type': 'text/plain' });
    res.end('not found\n');
    return;
  }
  const body = fs.readFileSync(file);
  const ext = path.extname(file);
  res.writeHead(200, {
    'content-type': TYPES[ext] ?? 'application/octet-stream',
    'content-length': body.length,
    'cache-control': 'no-store',
  });
  if (!throttle || ext !== '.mcgv') {
    res.end(body);
    return;
  }
  // 500 slices a second at the asked rate (2 KB every 2 ms at 1 MB/s).
  const slice = Math.max(1, Math.round(throttle / 500));
  let sent = 0;
  const next = () => {
    if (res.destroyed) return;
    const end = Math.min(body.length, sent + slice);
    res.write(body.subarray(sent, end));
    sent = end;
    if (sent < body.length) setTimeout(next, 2);
    else res.end();
  };
  next();
});
server.listen(port, '127.0.0.1', () => {
  console.log(server.address().port);
});
