#!/usr/bin/env bash
# `make bench`: the motion bench (segmentation + prediction speed and residual energy), then a rate
# sweep of mcgv-video (JPEG and MPEG-4) over media/ and, when present, ../shared/media, written to
# bench-out/sweep.csv.
set -euo pipefail
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
rm -f bench-out/sweep.csv
bash scripts/sweep.sh bench-out/sweep.csv "${inputs[@]}"
echo "results: bench-out/motion.txt, bench-out/sweep.csv"
