#!/usr/bin/env bash
# `make bench`: the motion bench (segmentation + prediction speed and residual energy), then a rate
# sweep of mcgv-video (JPEG, MPEG-4, tdct, and HEVC and AV1 with P-frames and all-intra) and of the
# peer codecs (Draco, zstd, PCA, Dynapack-style with zstd and with an arithmetic coder, gltfpack raw
# and Brotli'd, meshoptimizer's vertex codec) over media/ and, when present, ../shared/media, then a shorter sweep of the encoder variants (skinning
# predictor, decimation segmentation, both; every codec at quality 10 and 50
# when the binary has it), then one RD plot per sequence, the README tables and the peers' page:
#   bench-out/motion.txt, sweep.csv, sweep-variants.csv, peers.csv, peers.skipped.csv (what a peer
#   could not take, and why), plots/SEQUENCE.png, table.md, peers.md; then temporal segments (issue
#   20): segments-cost.csv (bits of segmenting the OBJ sequences, examples/segment_cost) and
#   segments-memory.csv (peak RSS and time on a generated 50 000 x 2 000 clip,
#   scripts/segments_memory.sh; SEGMENTS_V / SEGMENTS_F change its size; SKIP_SEGMENTS=1 skips both);
#   last docs/results.md, the current results page, from all of these (scripts/results_page.py and
#   scripts/results_template.md)
# MCGV_PYTHON is the virtualenv's python (`make bench` passes it). BENCH_VARIANTS overrides the
# variants (scripts/sweep.sh VARIANTS); empty skips the variant sweep. JPEG_QUALITIES,
# MPEG4_QUALITIES, TDCT_QUALITIES, HEVC_QUALITIES, HEVC_INTRA_QUALITIES, AV1_QUALITIES and
# AV1_INTRA_QUALITIES override the main sweep's qualities (scripts/sweep.sh; set but empty: none).
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
    # Linked under its own name: sweep.sh names a sequence after its folder, and this one is "OBJ".
    if [ -d "$shared/walking_cat/OBJ" ]; then
        mkdir -p "$unpacked" && ln -sfn "$(realpath "$shared/walking_cat/OBJ")" "$unpacked/walking_cat"
        inputs+=("$unpacked/walking_cat")
    fi
    for glb in "$shared"/threejs_*/*.glb; do inputs+=("$glb"); done
fi
cargo bench --quiet --bench motion -- "${inputs[@]}" | tee bench-out/motion.txt
rm -f bench-out/sweep.csv bench-out/sweep-variants.csv bench-out/peers.csv bench-out/peers.skipped.csv
VARIANTS=default HEVC_QUALITIES=${HEVC_QUALITIES-"10 30 50 75 90 97"} \
    HEVC_INTRA_QUALITIES=${HEVC_INTRA_QUALITIES-"10 30 50 75 90"} \
    AV1_QUALITIES=${AV1_QUALITIES-"10 30 50 75 90 97"} \
    AV1_INTRA_QUALITIES=${AV1_INTRA_QUALITIES-"10 30 50 75 90"} \
    bash scripts/sweep.sh bench-out/sweep.csv "${inputs[@]}"
csvs=(bench-out/sweep.csv)
variants=${BENCH_VARIANTS-"skinning decimation skinning+decimation"}
if [ -n "$variants" ]; then
    VARIANTS=$variants JPEG_QUALITIES="10 50" MPEG4_QUALITIES="10 50" TDCT_QUALITIES="10 50" \
        bash scripts/sweep.sh bench-out/sweep-variants.csv "${inputs[@]}"
    csvs+=(bench-out/sweep-variants.csv)
fi
MCGV_BIN=target/release/mcgv-video "$py" scripts/peers.py run bench-out/peers.csv "${inputs[@]}"
csvs+=(bench-out/peers.csv)
cargo run --release --quiet --example rd_plot -- bench-out/plots "${csvs[@]}"
"$py" scripts/rd_table.py "${csvs[@]}" > bench-out/table.md
MCGV_PYTHON=$py bash scripts/peers_page.sh bench-out/peers.md bench-out/peers.skipped.csv "${csvs[@]}"
# The results pages in docs/ are made here: the tables, the peers page, the CSVs and the plots.
{
    echo "# Rate-distortion tables"
    echo
    echo "Written by \`make bench\` (\`scripts/rd_table.py\` over ${csvs[*]#bench-out/}, copied beside this"
    echo "page); the current results page is [../results.md](../results.md), dated and superseded measurements"
    echo "are in [../history.md](../history.md). Every file in this folder is written by \`make bench\`: these"
    echo "tables come from the CSVs named above, segments-cost.csv and segments-memory.csv from its"
    echo "temporal-segment runs; older CSVs are in ../history/."
    echo "This copy: \`make bench\` of $(date -u +%F) at commit $(git describe --always --dirty 2>/dev/null || echo unknown)."
    echo
    cat bench-out/table.md
} > docs/bench/tables.md
rm -f docs/bench/sweep-variants.csv    # made again below only if this run swept the variants
cp "${csvs[@]}" bench-out/peers.md docs/bench/
cp bench-out/plots/*.png docs/bench/
if [ -z "${SKIP_SEGMENTS:-}" ]; then
    sequences=()
    for input in "${inputs[@]}"; do [ -d "$input" ] && sequences+=("$input"); done
    cargo run --release --quiet --example segment_cost -- bench-out/segments-cost.csv "${sequences[@]}"
    V=${SEGMENTS_V:-50000} F=${SEGMENTS_F:-2000} bash scripts/segments_memory.sh target/release/mcgv-video \
        bench-out/segments-memory >bench-out/segments-memory.csv
    cp bench-out/segments-cost.csv bench-out/segments-memory.csv docs/bench/
fi
# The results page, from the copies in docs/bench/ (so that the command it prints is reproducible).
"$py" scripts/results_page.py "${csvs[@]/#bench-out\//docs/bench/}" > bench-out/results.md
cp bench-out/results.md docs/results.md
echo "results: bench-out/motion.txt, ${csvs[*]#bench-out/}, plots/, table.md, peers.md, results.md; docs/bench/ and docs/results.md updated"
