#!/usr/bin/env bash
# `make bench`: the motion bench (segmentation + prediction speed and residual energy), then a rate
# sweep of mcgv-video (JPEG and MPEG-4) and of the peer codecs (Draco, zstd, PCA, Dynapack-style) over
# media/ and, when present, ../shared/media, then one RD plot per sequence and the README tables:
#   bench-out/motion.txt, sweep.csv, peers.csv, plots/SEQUENCE.png, table.md
# MCGV_PYTHON is the virtualenv's python (`make bench` passes it).
set -euo pipefail
py=${MCGV_PYTHON:-.venv/bin/python}
mkdir -p bench-out
inputs=(media/*.glb)
shared=${MCGV_SHARED_MEDIA:-../shared/media}
unpacked=bench-out/media
if [ -d "$shared" ]; then
    for tarball in "$shared"/*/*.obj-seq.tar.xz; do
        name=$(basename "$tarball" .obj-seq.tar.xz)
        [ -d "$unpacked/$name" ] || { mkdir -p "$unpacked" && tar xJf "$tarball" -C "$unpacked"; }
        inputs+=("$unpacked/$name")
    done
    [ -d "$shared/walking_cat/OBJ" ] && inputs+=("$shared/walking_cat/OBJ")
    for glb in "$shared"/threejs_*/*.glb; do inputs+=("$glb"); done
fi
cargo bench --quiet --bench motion -- "${inputs[@]}" | tee bench-out/motion.txt
rm -f bench-out/sweep.csv bench-out/peers.csv
bash scripts/sweep.sh bench-out/sweep.csv "${inputs[@]}"
MCGV_BIN=target/release/mcgv-video "$py" scripts/peers.py run bench-out/peers.csv "${inputs[@]}"
cargo run --release --quiet --example rd_plot -- bench-out/plots bench-out/sweep.csv bench-out/peers.csv
"$py" scripts/rd_table.py bench-out/sweep.csv bench-out/peers.csv > bench-out/table.md
echo "results: bench-out/motion.txt, sweep.csv, peers.csv, plots/, table.md"
