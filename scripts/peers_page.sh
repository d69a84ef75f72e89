#!/usr/bin/env bash
# The results page of the peers (issue 19): what each peer is, the commands that measured it, the
# inputs a peer could not take and why, then scripts/rd_table.py's tables over the CSVs given.
#   scripts/peers_page.sh OUT.md SKIPPED.csv CSV...
# SKIPPED.csv is scripts/peers.py's OUT.skipped.csv (sequence,codec,setting,reason); absent: none.
# PEERS_NOT_RUN: a sentence naming the peers and inputs left out of the CSVs for time (default: nothing).
set -euo pipefail
out=$1; skipped=$2; shift 2
py=${MCGV_PYTHON:-.venv/bin/python}
here=$(dirname "$0")
versions=$(cd "$here/node" && node -e '
    for (const p of ["gltfpack", "meshoptimizer", "@gltf-transform/core"])
        process.stdout.write(`${p} ${require(`./node_modules/${p}/package.json`).version}, `)')
versions+=$("$py" -c 'import importlib.metadata as m; print(", ".join(f"{p} {m.version(p)}" for p in ("constriction", "brotli", "zstandard")))')
{
cat <<EOF
# Peers: what a game or web team would ship instead of mcgv-video

Written by \`scripts/peers_page.sh\` (\`make bench\` writes it to bench-out/peers.md). Tool versions:
$versions.

- **gltfpack**: one glTF morph target per frame and a STEP weights track, packed by \`gltfpack -cc
  -af 0 -ac -vp N\` (EXT_meshopt_compression + KHR_mesh_quantization); **gltfpack-br** is the same file
  after Brotli (quality 11), what a web server sends. Decoded back by @gltf-transform/core and
  meshoptimizer's decoder (scripts/node/gltf_frames.mjs, node world matrix applied), keys and
  targets checked equal to the frames, vertices matched to the originals over all frames (gltfpack
  renumbers and welds: the log of the run prints how many decoded vertices were used).
- **meshopt-fm / meshopt-vm**: meshoptimizer's vertex codec (format 1, level 3) on positions quantised
  to N bits over the animation's bounding cube, frame-major (glTF's order) or vertex-major (trajectories,
  temporal deltas), faces by its index codec, all zstd level 19.
- **dynapack-ac**: the dynapack peer's quantisation, traversal and extended Lorenzo predictor (same
  residuals), coded by constriction's range coder with an adaptive context model (coordinate x
  magnitude class of the same residual in the previous frame), as the paper codes them, instead of zstd.
- **draco, zstd, pca, dynapack**: as before (scripts/peers.py). Draco renumbers vertices per frame, so
  it has no vertex RMSE and no KG error (— in the tables).

Every row: one encoding and one decoding, each its own process under GNU time (whole-process CPU
seconds: Node or Python start-up included), measured by \`mcgv-video eval\` on the PC2 that
\`mcgv-video convert\` wrote (bpvf counts every byte of the stream; RMSE is the papers' surface
measure over the first frame's bbox diagonal; KG error = 100 · ‖A − Ã‖ / ‖A − E(A)‖, E(A) the
per-frame centroid). The mcgv-video rows are those of docs/bench/sweep*.csv.

Commands. \`make bench\` runs every peer at its default settings (scripts/peers.py SETTINGS). The rows
of docs/bench/peers.csv for the peers of issue 19 were measured by these (MCGV_BIN a release build of commit b0f0ade;
bench-out/media is what scripts/bench.sh unpacks from ../shared/media, SHARED is ../shared/media; the
runs went in parallel, each with its own CSV, and their rows were appended to docs/bench/peers.csv,
a setting measured twice keeping its first row; its draco, zstd, pca and dynapack rows on the six OBJ
sequences came from an earlier \`make bench\`):

\`\`\`
make node-deps venv
export PEERS_CODECS="gltfpack gltfpack-br dynapack-ac meshopt-vm meshopt-fm"
PEERS_SETTINGS="gltfpack=vp 10,vp 12,vp 14;gltfpack-br=vp 10,vp 12,vp 14;dynapack-ac=qp 10,qp 12,qp 14;meshopt-vm=qp 10,qp 12,qp 14;meshopt-fm=qp 10,qp 12,qp 14" \\
  nice -n 10 .venv/bin/python scripts/peers.py run a.csv bench-out/media/{pdance,chickenCrossing,pcow}
PEERS_SETTINGS=(the same) nice -n 10 .venv/bin/python scripts/peers.py run b.csv \\
  bench-out/media/{horse-collapse,walking_cat} media/{CesiumMan,RiggedSimple,RiggedFigure,Fox}.glb \\
  bench-out/media/horse-gallop SHARED/threejs_{Flamingo,Horse,Parrot,Stork}/*.glb
PEERS_SETTINGS="gltfpack=vp 8,vp 16;gltfpack-br=vp 8,vp 16;dynapack-ac=qp 8,qp 16;meshopt-vm=qp 8,qp 16;meshopt-fm=qp 8,qp 16" \\
  nice -n 10 .venv/bin/python scripts/peers.py run d.csv (all of the above)
PEERS_CODECS="zstd pca dynapack" nice -n 10 .venv/bin/python scripts/peers.py run c.csv \\
  media/*.glb SHARED/threejs_*/*.glb
scripts/peers_page.sh docs/bench/peers.md docs/bench/peers.skipped.csv docs/bench/sweep*.csv docs/bench/peers.csv
\`\`\`

(A first run at the default settings, vp 10–16, was stopped after horse-collapse's gltfpack rows and
pdance's gltfpack vp 10 row, to measure fewer settings; those rows were kept.)

EOF
echo "#### Inputs a peer could not take"
echo
if [ -s "$skipped" ]; then
    echo "| sequence | codec | setting | why |"
    echo "|---|---|---|---|"
    sed -E 's/^([^,]*),([^,]*),([^,]*),"?(.*[^"])"?$/| \1 | \2 | \3 | \4 |/' "$skipped"
else
    echo "None: every peer took every input it was given."
fi
echo
echo "Not measured, for time (not a limit of the peer): ${PEERS_NOT_RUN:-nothing}."
echo
"$py" "$here/rd_table.py" "$@"
} > "$out"
