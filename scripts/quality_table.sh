#!/usr/bin/env bash
# Per sequence, codec and --quality: one CSV row of bpvf and error (the table issue 15 asks for).
#   scripts/quality_table.sh OUT.csv INPUT...
# env: MCGV_BIN (default target/release/mcgv-video), CODECS (default "jpeg mpeg4 tdct"),
#      QUALITIES (default "10 30 50 75 90 97"), EXTRA (more encoder flags, e.g. "--predictor skinning").
# rmse is the papers' surface measure, vertex_rmse the per-vertex one, both / bbox diagonal.
set -euo pipefail
bin=${MCGV_BIN:-target/release/mcgv-video}
out=$1; shift
codecs=${CODECS:-"jpeg mpeg4 tdct"}
qualities=${QUALITIES:-"10 30 50 75 90 97"}
read -ra extra <<<"${EXTRA:-}"
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
[ -s "$out" ] || echo "sequence,codec,quality,extra,bytes,bpvf,rmse,vertex_rmse" > "$out"
field() { sed -E "s/.*\"$1\":([0-9.eE+-]+).*/\1/" <<<"$2"; }
for input in "$@"; do
    name=$(basename "${input%/}"); name=${name%.*}
    for codec in $codecs; do
        for q in $qualities; do
            stream="$tmp/s.mcgv"
            "$bin" encode "$input" -o "$stream" --codec "$codec" --quality "$q" \
                ${extra[@]+"${extra[@]}"} --quiet
            m=$("$bin" eval "$input" "$stream" --json --quiet)
            printf '%s,%s,%s,%s,%d,%.4f,%.4e,%.4e\n' "$name" "$codec" "$q" "${EXTRA:-}" \
                "$(stat -c %s "$stream")" "$(field bpvf "$m")" "$(field rmse "$m")" \
                "$(field vertex_rmse "$m")" | tee -a "$out"
        done
    done
done
