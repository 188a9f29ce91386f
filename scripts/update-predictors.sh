#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Measures the predictors' Spearman rho on the simulated E1 with ten repeats and writes
# configs/predictors/e1-sim.json, the file `binocle design` ranks by (the predictor with
# the highest rho). Run after a change to the sim, the matcher, the evaluator or the
# predictors; about 15 s on an idle 2-core machine.
set -euo pipefail
cd "$(dirname "$0")/.."
binocle=${BINOCLE:-build/bin/binocle}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
"$binocle" experiment configs/experiments/e1.yaml --set repeats=10 --out "$out" --quiet
python3 - "$out/results.json" configs/predictors/e1-sim.json <<'PY'
import json, sys
doc = json.load(open(sys.argv[1]))
keep = {
    "experiment": doc["experiment"],
    "how": "binocle experiment configs/experiments/e1.yaml --set repeats=10 (scripts/update-predictors.sh)",
    "predictors": doc["predictors"],
    "eta_3d_percent": {r["test"]: r["eta_3d_percent"] for r in doc["tests"]},
}
with open(sys.argv[2], "w") as f:
    json.dump(keep, f, indent=2)
    f.write("\n")
PY
echo "configs/predictors/e1-sim.json: best predictor $(grep -o '"best": "[a-z_]*"' configs/predictors/e1-sim.json)"
