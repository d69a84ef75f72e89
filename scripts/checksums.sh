#!/usr/bin/env bash
# Checksums of encoded streams, to prove that a refactor changes no output: run it before and after
# and compare (`diff`). Encodes media/CesiumMan.glb and media/Fox.glb with every codec, with the
# affine predictor + k-means segmentation (the default before `auto` became it; named `default` so
# that the sums compare with older runs) and with the skinning predictor + decimation segmentation.
# Both pass their flags: the automatic choice picks among such streams.
#   scripts/checksums.sh [BIN] [WORKDIR]   (BIN defaults to target/release/mcgv-video)
set -euo pipefail
bin=${1:-target/release/mcgv-video}
work=${2:-$(mktemp -d)}
mkdir -p "$work"
for sample in media/CesiumMan.glb media/Fox.glb; do
    name=$(basename "$sample" .glb)
    for codec in jpeg mpeg4 tdct; do
        for variant in default skinning+decimation; do
            extra=(--predictor affine --segmentation kmeans)
            [ "$variant" = default ] || extra=(--predictor skinning --segmentation decimation)
            out="$work/$name-$codec-$variant.mcgv"
            "$bin" encode "$sample" -o "$out" --codec "$codec" --quiet "${extra[@]}"
            printf '%s  %s\n' "$(sha256sum <"$out" | cut -d' ' -f1)" "$name-$codec-$variant"
        done
    done
done
