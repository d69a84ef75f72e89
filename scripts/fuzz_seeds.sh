#!/usr/bin/env bash
# Seeds for the fuzz targets, made from media/ by the mcgv-video binary given as $1 into folder $2:
#   $2/decode_stream/  small real streams of every codec (64x64 lattice for the image codecs: fast to
#                      decode per execution), and of the skinning predictor and the decimation
#                      segmentation (parts and header fields the k-means/affine seeds never reach)
#   $2/read_mesh/      a kind byte (0 OBJ, 1 OBJ + NUL + PC2, 2 glTF) followed by a real file
# Regenerated every run (cheap) so that they follow the current stream format.
set -euo pipefail
bin=$1
out=$2
media=$(dirname "$0")/../media
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
mkdir -p "$out/decode_stream" "$out/read_mesh"
small=(--lattice 64x64 --clusters 4 --fps 6 --quiet)
"$bin" encode "$media/RiggedSimple.glb" -o "$out/decode_stream/jpeg.mcgv" --force --codec jpeg "${small[@]}"
"$bin" encode "$media/RiggedSimple.glb" -o "$out/decode_stream/mpeg4.mcgv" --force --codec mpeg4 --gop 3 "${small[@]}"
# HEVC: a set-up part with the sample depth, 10- and 12-bit pictures, P-frames and all-intra.
"$bin" encode "$media/RiggedSimple.glb" -o "$out/decode_stream/hevc.mcgv" --force --codec hevc --gop 3 "${small[@]}"
"$bin" encode "$media/RiggedSimple.glb" -o "$out/decode_stream/hevc-intra12.mcgv" --force --codec hevc --gop 1 \
	--bit-depth 12 "${small[@]}"
# AV1: the same set-up part behind another codec id and decoder.
"$bin" encode "$media/RiggedSimple.glb" -o "$out/decode_stream/av1.mcgv" --force --codec av1 --gop 3 "${small[@]}"
"$bin" encode "$media/RiggedSimple.glb" -o "$out/decode_stream/av1-intra12.mcgv" --force --codec av1 --gop 1 \
	--bit-depth 12 "${small[@]}"
"$bin" encode "$media/RiggedSimple.glb" -o "$out/decode_stream/jpeg-reorder.mcgv" --force --codec jpeg --reorder \
	--lattice 64x64 --clusters 2 --fps 2 --quality 10 --quiet
"$bin" encode "$media/RiggedSimple.glb" -o "$out/decode_stream/jpeg-skinning.mcgv" --force --codec jpeg \
	--predictor skinning "${small[@]}"
# Temporal DCT: no lattice; the band index (TDIX) and the progressive coefficients part (TDCT) are
# parts no image codec writes, and the skinning predictor reaches them with a different prediction.
tdct=(--codec tdct --clusters 4 --fps 6 --quality 10 --quiet)
"$bin" encode "$media/RiggedSimple.glb" -o "$out/decode_stream/tdct.mcgv" --force "${tdct[@]}"
"$bin" encode "$media/RiggedSimple.glb" -o "$out/decode_stream/tdct-skinning.mcgv" --force --predictor skinning \
	"${tdct[@]}"
# Spatial prediction of the bands (issue 18): RiggedSimple's bands never pick the one-ring mean,
# CesiumMan's do; a few frames keep the seed small.
"$bin" encode "$media/CesiumMan.glb" -o "$out/decode_stream/tdct-spatial.mcgv" --force --codec tdct --clusters 4 \
	--fps 2 --quality 90 --quiet
# A coarse first frame the residuals correct (tdct's first-frame trials keep 8-12 bits).
"$bin" encode "$media/RiggedSimple.glb" -o "$out/decode_stream/tdct-ff8.mcgv" --force --first-frame-bits 8 \
	"${tdct[@]}"
# Temporal segments (issue 20): segment markers, per-segment parts after the shared ones, a
# version-4 container; tdct bands and MPEG-4 groups of pictures restart in each segment.
"$bin" encode "$media/RiggedSimple.glb" -o "$out/decode_stream/tdct-segments.mcgv" --force --segment-frames 3 \
	"${tdct[@]}"
"$bin" encode "$media/RiggedSimple.glb" -o "$out/decode_stream/mpeg4-segments.mcgv" --force --codec mpeg4 --gop 2 \
	--segment-frames 3 "${small[@]}"
# Decimation finds K itself, so it takes no --clusters.
"$bin" encode "$media/RiggedSimple.glb" -o "$out/decode_stream/jpeg-decimation.mcgv" --force --codec jpeg \
	--segmentation decimation --lattice 64x64 --fps 6 --quiet
# Mesh readers: the decoded stream as OBJ and PC2, and two of the glTF samples.
"$bin" decode "$out/decode_stream/jpeg.mcgv" -o "$tmp/obj" --force --quiet
"$bin" decode "$out/decode_stream/jpeg.mcgv" -o "$tmp/anim.pc2" --force --quiet
{ printf '\x00'; cat "$tmp/obj/frame_0000.obj"; } >"$out/read_mesh/obj"
{ printf '\x01'; cat "$tmp/obj/frame_0000.obj"; printf '\x00'; cat "$tmp/anim.pc2"; } >"$out/read_mesh/pc2"
printf '\x00# a quad, a fan and negative indices\nv 0 0 0\nv 1 0 0\nv 1 1 0 1\nv 0 1 0\nf 1 2 3 4\nf -1 -2 -4\n' \
	>"$out/read_mesh/quad-obj"
for name in RiggedSimple RiggedFigure; do
	{ printf '\x02'; cat "$media/$name.glb"; } >"$out/read_mesh/$name"
done
ls -l "$out"/*/
