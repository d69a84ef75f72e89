#!/usr/bin/env bash
# A picture codec's vertex RMSE and bytes against the quality, each clip's motion model pinned as
# a budget search pins it after its first encode: CSV lines name,bit depth,quality,vertex RMSE,bytes.
#   scripts/budget_curves.sh BIN CODEC OUT.csv "50 60 70" "10 12" "NAME|SEQ|MODEL FLAGS" ...
# e.g. "pcow|media/pcow|--predictor skinning --segmentation decimation"; a depth of "auto" leaves
# --bit-depth out. Appends to OUT.csv.
set -euo pipefail
bin=$1 codec=$2 out=$3 qualities=$4 depths=$5
shift 5
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
for spec in "$@"; do
    IFS='|' read -r name seq model <<<"$spec"
    for depth in $depths; do
        for q in $qualities; do
            extra=()
            [ "$depth" = auto ] || extra=(--bit-depth "$depth")
            # shellcheck disable=SC2086 # the model's flags split on purpose
            "$bin" encode "$seq" -o "$work/s.mcgv" --codec "$codec" --quality "$q" "${extra[@]}" \
                --first-frame-bits 12 $model --quiet --force --json >"$work/s.json"
            rmse=$("$bin" eval "$seq" "$work/s.mcgv" --fast --json --quiet |
                python3 -c "import json,sys; print(json.load(sys.stdin)['vertex_rmse'])")
            bytes=$(python3 -c "import json; print(json.load(open('$work/s.json'))['bytes'])")
            echo "$name,$depth,$q,$rmse,$bytes" >>"$out"
        done
    done
done
