#!/usr/bin/env bash
# Rate sweep: encode each given animation with JPEG at several qualities and MPEG-4 at several
# quantisers, and append one CSV row per encoding (bpvf counts every byte of the file; RMSE is the
# papers' surface measure, as a fraction of the bbox diagonal).
#   scripts/sweep.sh OUT.csv INPUT...        (env: JPEG_QUALITIES, QSCALES, MCGV_BIN)
set -euo pipefail
bin=${MCGV_BIN:-target/release/mcgv-video}
out=$1; shift
qualities=${JPEG_QUALITIES:-"30 50 75"}
qscales=${QSCALES:-"2 4 8"}
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
[ -s "$out" ] || echo "sequence,codec,setting,bytes,bpvf,rmse,vertex_rmse,kg_error,hausdorff,encode_s,decode_s,frames,vertices" > "$out"
field() { sed -E "s/.*\"$1\":([0-9.eE+-]+).*/\1/" <<<"$2"; }
for input in "$@"; do
    name=$(basename "${input%/}"); name=${name%.*}
    runs=()
    for q in $qualities; do runs+=("jpeg --quality $q"); done
    for q in $qscales; do runs+=("mpeg4 --qscale $q"); done
    for run in "${runs[@]}"; do
        read -r codec flag value <<<"$run"
        stream="$tmp/$name.mcgv"
        t0=$(date +%s.%N)
        "$bin" encode "$input" -o "$stream" --codec "$codec" "$flag" "$value" --quiet
        t1=$(date +%s.%N)
        "$bin" decode "$stream" -o "$tmp/dec.pc2" --quiet
        t2=$(date +%s.%N)
        m=$("$bin" eval "$input" "$stream" --json --quiet)
        awk -v n="$name" -v c="$codec" -v s="${flag#--} $value" -v b="$(stat -c %s "$stream")" \
            -v bpvf="$(field bpvf "$m")" -v r="$(field rmse "$m")" -v vr="$(field vertex_rmse "$m")" \
            -v kg="$(field kg_error "$m")" -v h="$(field hausdorff "$m")" -v f="$(field frames "$m")" \
            -v v="$(field vertices "$m")" -v t0="$t0" -v t1="$t1" -v t2="$t2" \
            'BEGIN { printf "%s,%s,%s,%d,%.4f,%.6e,%.6e,%.5f,%.6e,%.2f,%.2f,%d,%d\n", n, c, s, b, bpvf, r, vr, kg, h, t1 - t0, t2 - t1, f, v }' \
            | tee -a "$out"
    done
done
