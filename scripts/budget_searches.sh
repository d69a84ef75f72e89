#!/usr/bin/env bash
# Budget searches, one line each: clip, budget, encodes, bytes kept, measure kept, whether it
# landed within 3 %, and every encode's quality:vertex RMSE:bits a sample (HEVC, AV1).
#   scripts/budget_searches.sh BIN CODEC "2e-4 1e-4" NAME=SEQ [NAME=SEQ ...]
#   FLAG=--target-size scripts/budget_searches.sh BIN av1 "100000" pdance=media/pdance
# SEQ is anything `mcgv-video encode` reads; the streams go to a temporary folder.
set -euo pipefail
bin=$1 codec=$2 budgets=$3
shift 3
flag=${FLAG:---target-error}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
for spec in "$@"; do
    name=${spec%%=*} seq=${spec#*=}
    for budget in $budgets; do
        json="$work/$name-$budget.json"
        "$bin" encode "$seq" -o "$work/s.mcgv" --codec "$codec" "$flag" "$budget" --json --quiet \
            --force >"$json"
        python3 - "$json" "$name" "$budget" <<'PY'
import json, sys
d = json.load(open(sys.argv[1])); b = d["budget"]
rmse = lambda t: "%.4e" % t["vertex_rmse"] if t.get("vertex_rmse") is not None else "-"
trials = " ".join("%.2f:%s:%s" % (t["quality"], rmse(t), t.get("bit_depth") or "-") for t in b["trials"])
print(sys.argv[2], sys.argv[3], b["encodes"], d["bytes"], "%.4e" % b["achieved"],
      "within" if b["within_tolerance"] else "not-within", trials)
PY
    done
done
