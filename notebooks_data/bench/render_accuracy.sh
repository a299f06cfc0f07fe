#!/usr/bin/env bash
# The radiance maps against a converged CPU reference (issue "Previews you can trust"): meshes x
# materials x models x settings, 64 px, a directional and a point light, subsurface only
# (--specular off). Writes render_$MODE.csv beside this script. Usage:
#   [MODE=accuracy|convergence|defaults] [MESHES="sphere dragon:4"] [CSV=FILE] \
#     [DRAGON_MATERIALS="marble potato skin1"] [EXTRA="sphere:potato:tabulated ..."] \
#     notebooks_data/bench/render_accuracy.sh [LUCENT_BINARY] [WORK_DIR]
# Costs on a 2-core llvmpipe machine: ~1 min per case at the light settings, ~5 min at the
# default ones (8 s per frame), ~15 s per reference.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
lucent="${1:-$here/../../build/ci/cli/lucent}"
work="${2:-$(mktemp -d)}"
mkdir -p "$work"
mode="${MODE:-accuracy}"
csv="${CSV:-$here/render_$mode.csv}"
lights=(--light directional:1,0.5,0.5:1,1,1 --light point:-60,60,80:5000,5000,5000)
common=(--size 64x64 --reference-threads 2 --specular off "${lights[@]}")
reference_probes=8192
tmp="$csv.tmp"
echo "setting,mesh,material,model,frames,relative_rmse,mean_ratio_r,mean_ratio_g,mean_ratio_b,rmse_vs_final,seconds" > "$tmp"

reference() {  # mesh material model -> path
  local out="$work/ref_${1/:/_}_$2_$3.exr"
  if [[ ! -f "$out" ]]; then
    "$lucent" render --technique reference --reference-samples-pixel $reference_probes --seed 7 \
      --material "$2" --mesh "$1" --model "$3" "${common[@]}" -o "$out" >/dev/null 2>&1
  fi
  echo "$out"
}

run_case() {  # setting mesh material model frames snapshots... -- map options
  local setting=$1 mesh=$2 material=$3 model=$4 frames=$5 snaps=$6
  shift 6
  local ref
  ref="$(reference "$mesh" "$material" "$model")"
  local out="$work/maps_${setting}_${mesh/:/_}_${material}_${model}.exr"
  local start end
  start=$(date +%s.%N)
  "$lucent" render --material "$material" --mesh "$mesh" --model "$model" "${common[@]}" \
    --maps-frames "$frames" --snapshots "$snaps" "$@" -o "$out" >/dev/null 2>&1
  end=$(date +%s.%N)
  for t in ${snaps//,/ }; do
    local img="${out%.exr}.f$t.exr"
    local vs_ref vs_final
    vs_ref=$("$lucent" compare "$img" "$ref" --json)
    vs_final=$("$lucent" compare "$img" "$out" --json)
    python3 - "$setting" "$mesh" "$material" "$model" "$t" "$(echo "$end - $start" | bc)" \
      "$vs_ref" "$vs_final" >> "$tmp" <<'PY'
import json, sys
s, mesh, mat, model, t, secs, a, b = sys.argv[1:]
a, b = json.loads(a), json.loads(b)
print(f"{s},{mesh},{mat},{model},{t},{a['relative_rmse']:.4f},{a['mean_ratio'][0]:.4f},"
      f"{a['mean_ratio'][1]:.4f},{a['mean_ratio'][2]:.4f},{b['relative_rmse']:.4f},{float(secs):.1f}")
PY
  done
  echo "done: $setting $mesh $material $model" >&2
}

light=(--maps-directions 8 --maps-radiance-map 256 --maps-light-map 256 --maps-samples 32 --maps-disc-points 256)
if [[ "$mode" == accuracy ]]; then
  for mesh in ${MESHES:-sphere dragon:4}; do
    for material in marble potato skin1; do
      for model in dipole ddipole tabulated; do
        run_case light "$mesh" "$material" "$model" 64 1,2,4,8,16,32,64 "${light[@]}"
      done
    done
    run_case light "$mesh" ketchup ddipole 64 1,2,4,8,16,32,64 "${light[@]}"
  done
elif [[ "$mode" == defaults ]]; then
  # The rest of dragon:4's default-settings matrix (the convergence run has the ddipole rows).
  for material in ${DRAGON_MATERIALS-marble potato skin1}; do
    for model in dipole tabulated; do
      run_case default dragon:4 "$material" "$model" 32 1,2,4,8,16,32
    done
  done
  # More cases on request: EXTRA="mesh:material:model ..." (e.g. sphere:potato:tabulated).
  for extra in ${EXTRA:-}; do
    IFS=: read -r mesh material model <<< "$extra"
    run_case default "$mesh" "$material" "$model" 32 1,2,4,8,16,32
  done
else
  run_case light sphere marble ddipole 64 1,2,4,8,16,32,64 "${light[@]}"
  for material in marble potato skin1 ketchup; do
    run_case light dragon:4 "$material" ddipole 64 1,2,4,8,16,32,64 "${light[@]}"
  done
  # The defaults (K 16, W 512, N 50, M 1000), run to 32 frames (8 s a frame here).
  for mesh in sphere dragon:4; do
    run_case default "$mesh" marble ddipole 32 1,2,4,8,16,32
  done
  run_case default dragon:4 potato ddipole 32 1,2,4,8,16,32
  run_case default dragon:4 skin1 ddipole 32 1,2,4,8,16,32
  run_case default dragon:4 marble tabulated 32 1,2,4,8,16,32
fi
mv "$tmp" "$csv"
echo "wrote $csv" >&2
