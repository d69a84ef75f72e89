#!/usr/bin/env bash
# Rate sweep: encode each given animation with JPEG at several qualities and MPEG-4 at several
# quantisers, and append one CSV row per encoding (bpvf counts every byte of the file; RMSE is the
# papers' surface measure, as a fraction of the bbox diagonal). Times are whole-process figures from
# GNU time: wall seconds, CPU seconds (user + system, steadier than wall on a shared machine) and
# peak resident memory.
#   scripts/sweep.sh OUT.csv INPUT...        (env: JPEG_QUALITIES, QSCALES, MCGV_BIN)
set -euo pipefail
bin=${MCGV_BIN:-target/release/mcgv-video}
out=$1; shift
qualities=${JPEG_QUALITIES:-"5 10 20 35 50 75"}
qscales=${QSCALES:-"2 3 4 8 16 31"}
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
[ -s "$out" ] || echo "sequence,codec,setting,bytes,bpvf,rmse,vertex_rmse,kg_error,hausdorff,encode_s,decode_s,encode_cpu_s,decode_cpu_s,encode_rss_kb,decode_rss_kb,frames,vertices" > "$out"
field() { sed -E "s/.*\"$1\":([0-9.eE+-]+).*/\1/" <<<"$2"; }
# Runs a command under GNU time; prints "wall cpu max_rss_kb".
measure() {
    /usr/bin/time -f "%e %U %S %M" -o "$tmp/time" "$@"
    awk '{ printf "%s %.2f %s\n", $1, $2 + $3, $4 }' "$tmp/time"
}
for input in "$@"; do
    name=$(basename "${input%/}"); name=${name%.*}
    runs=()
    for q in $qualities; do runs+=("jpeg --quality $q"); done
    for q in $qscales; do runs+=("mpeg4 --qscale $q"); done
    for run in "${runs[@]}"; do
        read -r codec flag value <<<"$run"
        stream="$tmp/$name.mcgv"
        read -r ew ec em < <(measure "$bin" encode "$input" -o "$stream" --codec "$codec" "$flag" "$value" --quiet)
        read -r dw dc dm < <(measure "$bin" decode "$stream" -o "$tmp/dec.pc2" --quiet)
        m=$("$bin" eval "$input" "$stream" --json --quiet)
        printf '%s,%s,%s,%d,%.4f,%.6e,%.6e,%.5f,%.6e,%s,%s,%s,%s,%s,%s,%d,%d\n' \
            "$name" "$codec" "${flag#--} $value" "$(stat -c %s "$stream")" "$(field bpvf "$m")" \
            "$(field rmse "$m")" "$(field vertex_rmse "$m")" "$(field kg_error "$m")" \
            "$(field hausdorff "$m")" "$ew" "$dw" "$ec" "$dc" "$em" "$dm" \
            "$(field frames "$m")" "$(field vertices "$m")" | tee -a "$out"
    done
done
