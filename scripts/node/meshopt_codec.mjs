// meshoptimizer's vertex and index codecs (the ones EXT_meshopt_compression stores), for
// scripts/peers_meshopt.py. The caller lays out and quantises the vertices; this only codes bytes.
//   node meshopt_codec.mjs encode SIZE VERTICES.raw INDICES.raw OUT
//       VERTICES.raw: count x SIZE bytes (SIZE a multiple of 4); INDICES.raw: uint32 triangles.
//       OUT: uint32 length + vertex stream (format version 1, level 3: the smallest), uint32 length
//       + index stream.
//   node meshopt_codec.mjs decode SIZE COUNT TRIANGLES IN VERTICES.raw INDICES.raw
import { readFileSync, writeFileSync } from 'node:fs';
import { MeshoptDecoder, MeshoptEncoder } from 'meshoptimizer';

function die(message) {
	console.error(`meshopt_codec.mjs: error: ${message}`);
	process.exit(1);
}

function u32(n) {
	return Buffer.from(Uint32Array.from([n]).buffer);
}

async function encode(size, vertFile, idxFile, out) {
	await MeshoptEncoder.ready;
	const vert = new Uint8Array(readFileSync(vertFile));
	const idx = new Uint8Array(readFileSync(idxFile));
	if (vert.length % size !== 0) die(`${vert.length} vertex bytes are not a whole number of ${size}-byte vertices`);
	const v = MeshoptEncoder.encodeVertexBufferLevel(vert, vert.length / size, size, 3, 1);
	const i = MeshoptEncoder.encodeIndexBuffer(idx, idx.length / 4, 4);
	writeFileSync(out, Buffer.concat([u32(v.length), Buffer.from(v), u32(i.length), Buffer.from(i)]));
}

async function decode(size, count, triangles, input, vertFile, idxFile) {
	await MeshoptDecoder.ready;
	const buf = readFileSync(input);
	const vlen = buf.readUInt32LE(0);
	const v = new Uint8Array(buf.subarray(4, 4 + vlen));
	const ilen = buf.readUInt32LE(4 + vlen);
	const i = new Uint8Array(buf.subarray(8 + vlen, 8 + vlen + ilen));
	const vert = new Uint8Array(count * size);
	MeshoptDecoder.decodeVertexBuffer(vert, count, size, v);
	const idx = new Uint8Array(triangles * 3 * 4);
	MeshoptDecoder.decodeIndexBuffer(idx, triangles * 3, 4, i);
	writeFileSync(vertFile, vert);
	writeFileSync(idxFile, idx);
}

const [mode, ...args] = process.argv.slice(2);
const run = mode === 'encode' && args.length === 4 ? encode(Number(args[0]), ...args.slice(1))
	: mode === 'decode' && args.length === 6 ? decode(Number(args[0]), Number(args[1]), Number(args[2]), ...args.slice(3))
	: die('usage: see the head of meshopt_codec.mjs');
run.catch((e) => die(e.stack || String(e)));
