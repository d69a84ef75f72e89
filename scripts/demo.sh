#!/usr/bin/env bash
# `make demo`: encode a sample animation from media/ with the defaults (the temporal DCT, the smallest
# file), then with the two picture codecs for comparison (MPEG-4, then JPEG: growing sizes), decode
# it, and print size, bpvf, RMSE and time for each.
set -euo pipefail
bin=${MCGV_BIN:-target/release/mcgv-video}
sample=${1:-media/CesiumMan.glb}
out=demo-out
mkdir -p "$out"

echo "== the input"
"$bin" info "$sample"
echo
printf '%-7s %-14s %10s %8s %12s %12s %8s %8s\n' codec setting bytes bpvf "RMSE(1e-4)" "Hausdorff" "enc s" "dec s"
for run in default mpeg4 jpeg; do
    codec_flag=()
    [ "$run" = default ] || codec_flag=(--codec "$run")
    stream="$out/sample-$run.mcgv"
    t0=$(date +%s.%N)
    "$bin" encode "$sample" -o "$stream" "${codec_flag[@]}" --force --quiet
    t1=$(date +%s.%N)
    "$bin" decode "$stream" -o "$out/decoded-$run/" --force --quiet
    t2=$(date +%s.%N)
    json=$("$bin" eval "$sample" "$stream" --json --quiet)
    described=$("$bin" inspect "$stream" --json)
    # Each field on its own: a codec's description has only the settings it uses (tdct: no qscale).
    codec=$(sed -nE 's/.*"codec":"([a-z0-9]+)".*/\1/p' <<<"$described")
    quality=$(sed -nE 's/.*"quality":([0-9.]+).*/\1/p' <<<"$described")
    qscale=$(sed -nE 's/.*"qscale":([0-9]+).*/\1/p' <<<"$described")
    [ "$run" = default ] && codec="$codec*"
    case $codec in mpeg4) setting="qscale $qscale" ;; *) setting="quality $quality" ;; esac
    field() { sed -E "s/.*\"$1\":([0-9.eE+-]+).*/\1/" <<<"$json"; }
    awk -v c="$codec" -v s="$setting" -v b="$(stat -c %s "$stream")" -v bpvf="$(field bpvf)" \
        -v r="$(field rmse)" -v h="$(field hausdorff)" -v t0="$t0" -v t1="$t1" -v t2="$t2" \
        'BEGIN { printf "%-7s %-14s %10d %8.3f %12.3f %12.5f %8.2f %8.2f\n", c, s, b, bpvf, r * 1e4, h, t1 - t0, t2 - t1 }'
done
echo "(* the default codec)"
glb="$out/$(basename "${sample%.*}")-decoded.glb"
like=(); case $sample in *.glb | *.gltf) like=(--like "$sample") ;; esac
"$bin" decode "$out/sample-default.mcgv" -o "$glb" "${like[@]}" --force --quiet
echo
echo "streams and decoded OBJ frames are in $out/; look inside with: $bin inspect $out/sample-jpeg.mcgv --png $out/png"
echo "the default stream decoded to glTF (morph targets, UVs, the source's materials): $glb; drop it on https://gltf-viewer.donmccurdy.com/"
echo "or open it in Blender (File > Import > glTF 2.0) and play the timeline"
