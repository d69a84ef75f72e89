// Decodes a glTF binary whose animation is a morph-target weights track (as written by
// scripts/peers_meshopt.py and packed by gltfpack) back to vertex positions, one set per keyframe.
//   node gltf_frames.mjs IN.glb OUT.bin
// OUT.bin: int32 frames F, vertices V, triangles T, morph targets K; float32 positions F x V x 3
// (world space: the mesh node's world matrix applied, which carries gltfpack's dequantisation);
// uint32 indices T x 3; float32 keyframe times F. Every triangle primitive of every mesh node is
// appended in scene order. Fails when a primitive has no weights track or the tracks disagree.
import { readFileSync, writeFileSync } from 'node:fs';
import { NodeIO } from '@gltf-transform/core';
import { ALL_EXTENSIONS } from '@gltf-transform/extensions';
import { MeshoptDecoder } from 'meshoptimizer';

function die(message) {
	console.error(`gltf_frames.mjs: error: ${message}`);
	process.exit(1);
}

// Times and F x K weight rows of the animation channel that drives `node`'s morph weights.
function weightsTrack(doc, node, k) {
	for (const animation of doc.getRoot().listAnimations()) {
		for (const channel of animation.listChannels()) {
			if (channel.getTargetNode() !== node || channel.getTargetPath() !== 'weights') continue;
			const sampler = channel.getSampler();
			const times = Array.from(sampler.getInput().getArray());
			const out = sampler.getOutput();
			const per = sampler.getInterpolation() === 'CUBICSPLINE' ? 3 : 1;
			if (out.getCount() !== times.length * k * per) die(`weights output has ${out.getCount()} values for ${times.length} keys x ${k} targets`);
			const rows = [];
			for (let f = 0; f < times.length; f++) {
				const row = new Float64Array(k);
				const at = (f * per + (per === 3 ? 1 : 0)) * k; // a cubic spline key's value sits between its tangents
				for (let j = 0; j < k; j++) row[j] = out.getScalar(at + j);
				rows.push(row);
			}
			return { times, rows, interpolation: sampler.getInterpolation() };
		}
	}
	return null;
}

function elements(accessor) {
	const n = accessor.getCount();
	const out = new Float64Array(3 * n);
	const e = [0, 0, 0];
	for (let i = 0; i < n; i++) {
		accessor.getElement(i, e);
		out[3 * i] = e[0]; out[3 * i + 1] = e[1]; out[3 * i + 2] = e[2];
	}
	return out;
}

// Positions of one primitive at every key: base + sum of weight x delta, then the world matrix.
function primitiveFrames(prim, track, matrix) {
	const base = elements(prim.getAttribute('POSITION'));
	const deltas = prim.listTargets().map((t) => elements(t.getAttribute('POSITION')));
	const n = base.length / 3;
	return track.rows.map((row) => {
		const local = Float64Array.from(base);
		row.forEach((w, j) => {
			if (w === 0) return;
			const d = deltas[j];
			for (let i = 0; i < local.length; i++) local[i] += w * d[i];
		});
		const world = new Float32Array(3 * n);
		const m = matrix;
		for (let i = 0; i < n; i++) {
			const x = local[3 * i], y = local[3 * i + 1], z = local[3 * i + 2];
			world[3 * i] = m[0] * x + m[4] * y + m[8] * z + m[12];
			world[3 * i + 1] = m[1] * x + m[5] * y + m[9] * z + m[13];
			world[3 * i + 2] = m[2] * x + m[6] * y + m[10] * z + m[14];
		}
		return world;
	});
}

async function main() {
	const [input, output] = process.argv.slice(2);
	if (!input || !output) die('usage: node gltf_frames.mjs IN.glb OUT.bin');
	await MeshoptDecoder.ready;
	const io = new NodeIO().registerExtensions(ALL_EXTENSIONS).registerDependencies({ 'meshopt.decoder': MeshoptDecoder });
	const doc = await io.readBinary(new Uint8Array(readFileSync(input)));
	const parts = [], indices = [];
	let vertices = 0, track0 = null, targets = 0;
	for (const node of doc.getRoot().listNodes()) {
		const mesh = node.getMesh();
		if (!mesh) continue;
		for (const prim of mesh.listPrimitives()) {
			if (prim.getMode() !== 4) die('only triangle primitives are expected');
			const k = prim.listTargets().length;
			const track = weightsTrack(doc, node, k);
			if (!track) die('a mesh node has no morph weights animation');
			if (track0 && track.times.length !== track0.times.length) die('mesh nodes have different key counts');
			track0 = track0 || track;
			targets = Math.max(targets, k);
			parts.push(primitiveFrames(prim, track, node.getWorldMatrix()));
			const idx = prim.getIndices().getArray();
			for (const i of idx) indices.push(i + vertices);
			vertices += prim.getAttribute('POSITION').getCount();
		}
	}
	if (!track0) die('no animated mesh');
	const frames = track0.times.length;
	const head = Int32Array.from([frames, vertices, indices.length / 3, targets]);
	const pos = new Float32Array(frames * vertices * 3);
	for (let f = 0; f < frames; f++) {
		let at = f * vertices * 3;
		for (const part of parts) { pos.set(part[f], at); at += part[f].length; }
	}
	const chunks = [head, pos, Uint32Array.from(indices), Float32Array.from(track0.times)];
	writeFileSync(output, Buffer.concat(chunks.map((c) => Buffer.from(c.buffer, c.byteOffset, c.byteLength))));
	console.log(JSON.stringify({ frames, vertices, triangles: indices.length / 3, targets, interpolation: track0.interpolation }));
}

main().catch((e) => die(e.stack || String(e)));
