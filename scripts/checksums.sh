#!/usr/bin/env bash
# Checksums of encoded streams and of what they decode to, to prove that a refactor changes no
# output: run it before and after and compare (`diff`). Each line is the stream's SHA-256, the
# SHA-256 of its decode as a PC2 point cache (the positions, bit for bit) and the stream's name.
# A change of stream format alters the first column only; the second must not move.
#
# Encodes media/CesiumMan.glb and media/Fox.glb with every codec, with the affine predictor +
# k-means segmentation (named `default` so that the sums compare with older runs) and with the
# skinning predictor + decimation segmentation (the automatic choice picks among such streams),
# and CesiumMan cut into temporal segments of 16 frames.
#   scripts/checksums.sh [BIN] [WORKDIR]   (BIN defaults to target/release/mcgv-video)
#   CODECS="tdct jpeg" scripts/checksums.sh …   (a subset; default: every codec)
set -euo pipefail
bin=${1:-target/release/mcgv-video}
work=${2:-$(mktemp -d)}
codecs=${CODECS:-jpeg mpeg4 tdct hevc av1}
mkdir -p "$work"

# Encodes with the given flags, decodes to PC2 and prints both sums and the name.
sums() {
    local name=$1 sample=$2
    shift 2
    local out="$work/$name.mcgv"
    "$bin" encode "$sample" -o "$out" --force --quiet "$@"
    rm -f "$work/$name.pc2" "$work/$name.obj"
    "$bin" decode "$out" -o "$work/$name.pc2" --force --quiet
    printf '%s  %s  %s\n' "$(sha256sum <"$out" | cut -d' ' -f1)" \
        "$(sha256sum <"$work/$name.pc2" | cut -d' ' -f1)" "$name"
}

for sample in media/CesiumMan.glb media/Fox.glb; do
    name=$(basename "$sample" .glb)
    for codec in $codecs; do
        sums "$name-$codec-default" "$sample" --codec "$codec" --predictor affine --segmentation kmeans
        sums "$name-$codec-skinning+decimation" "$sample" --codec "$codec" \
            --predictor skinning --segmentation decimation
    done
done
for codec in $codecs; do
    sums "CesiumMan-$codec-segments16" media/CesiumMan.glb --codec "$codec" --segment-frames 16 \
        --predictor affine --segmentation kmeans
done
