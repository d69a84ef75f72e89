#!/usr/bin/env bash
# The memory bench of temporal segments (issue 20): a generated cloth of V vertices × F frames
# (examples/long_clip, written as PC2 + OBJ one frame at a time) is encoded with segment lengths
# giving 1, 4 and 16 segments, decoded to an OBJ folder and evaluated against the original; each
# command's peak RSS and wall time come from GNU time. Output: a CSV on stdout.
#   scripts/segments_memory.sh [BIN] [WORKDIR]     env: V (default 50000), F (default 2000),
#   SEGMENTS (default "1 4 16"), CODEC (default tdct), QUALITY (default the encoder's)
set -euo pipefail
bin=${1:-target/release/mcgv-video}
work=${2:-$(mktemp -d)}
V=${V:-50000}
F=${F:-2000}
codec=${CODEC:-tdct}
quality=()
[ -n "${QUALITY:-}" ] && quality=(--quality "$QUALITY")
mkdir -p "$work"
cargo build --release --quiet --example long_clip
target/release/examples/long_clip "$work/clip" "$V" "$F" 2>/dev/null
run() { # label, command…: one CSV row
	local label=$1
	shift
	/usr/bin/time -f '%e,%M' -o "$work/time.txt" "$@" >/dev/null
	printf '%s,%s\n' "$label" "$(cat "$work/time.txt")"
}
echo "segments,segment_frames,command,seconds,peak_rss_kb,bytes"
for n in ${SEGMENTS:-1 4 16}; do
	length=$(((F + n - 1) / n))
	out="$work/clip-$n.mcgv"
	row=$(run "$n,$length,encode" "$bin" encode "$work/clip/cloth.pc2" -o "$out" --force --codec "$codec" \
		--segment-frames "$length" --quiet "${quality[@]}")
	bytes=$(stat -c %s "$out")
	echo "$row,$bytes"
	rm -rf "$work/frames"
	echo "$(run "$n,$length,decode" "$bin" decode "$out" -o "$work/frames/" --force --quiet),$bytes"
	rm -rf "$work/frames"
	echo "$(run "$n,$length,eval" "$bin" eval "$work/clip/cloth.pc2" "$out" --json),$bytes"
done
