#!/bin/bash
# Seed 003's own configuration against lucent's defaults, at the thesis's knobs (K 16, N 50, M 1000;
# 16 frames; W_s = W_l = W_S, default 256, which its Section 6.2.3 finds no worse than its 1024,
# and a quarter of 512's time on llvmpipe): Dal Corso's exponential disc, its N nearest points every frame, the
# mip blur (2 levels at the first frame) and equal layer weights ("thesis"), against the profile
# disc, radius strata, no blur and cos-weighted layers ("lucent"). 30 mm spheres of the
# previews_vs_truth scenes, 64 px, subsurface term only, against the path-traced truth (pt_<scene>.exr,
# TRUTH_SAMPLES paths a pixel, reused from WORKDIR: previews_vs_truth.sh's) and the CPU reference
# (512 probes). Rows: scene,material,config,technique,mean_R,mean_G,mean_B,relative_rmse vs truth,
# relative_rmse vs reference,frame_ms (the four passes' per-frame mean),setup_ms,memory_mib (the
# maps' GPU memory, radiance_maps.h),seed_formula_mib (Dal Corso's Table 5.1 formula).
# Usage: thesis_vs_defaults.sh [LUCENT] [WORKDIR] > thesis_vs_defaults.csv  (~25 min on 2 cores)
set -euo pipefail
L=${1:-build/ci/cli/lucent}
W=${2:-$(mktemp -d)}
export MESA_SHADER_CACHE_DISABLE=true
N=${TRUTH_SAMPLES:-512}
seed="--maps-directions 16 --maps-radiance-map ${W_S:-256} --maps-light-map ${W_S:-256} --maps-samples 50 --maps-disc-points 1000 --maps-frames 16"
thesis="--maps-disc-distribution exponential --maps-disc-selection nearest --maps-max-blur 2 --maps-layer-weights equal"
lucent="--maps-disc-distribution profile --maps-disc-selection strata --maps-max-blur 0 --maps-layer-weights cos"
echo "scene,material,config,mean_R,mean_G,mean_B,rmse_vs_truth,rmse_vs_reference,frame_ms,setup_ms,memory_mib,seed_formula_mib"
field() {  # the compare line's relative RMSE, or its R,G,B means
  sed -E "s/.*relative RMSE ([0-9.e+-]+) over [0-9]+ pixels.*/\1/" <<<"$1"
}
for s in marble:directional:0.4,0.5,1:front potato:directional:0.4,0.5,1:front skin1:directional:0.4,0.5,1:front ketchup:directional:-1,0.3,-0.5:back; do
  mat=${s%%:*}; rest=${s#*:}; name=${rest##*:}; light=${rest%:*}
  tag=${mat}_own_30_${name}
  common="--material $mat --mesh sphere --object-size-mm 30 --size 64x64 --light $light:1,1,1 --specular off"
  [ -f "$W/pt_$tag.exr" ] || "$L" render --technique pathtrace --pathtrace-samples-pixel $N $common -o "$W/pt_$tag.exr" >/dev/null
  [ -f "$W/ref_$tag.exr" ] || "$L" render --technique reference --reference-samples-pixel 512 $common -o "$W/ref_$tag.exr" >/dev/null
  for config in thesis lucent; do
    "$L" render --technique maps $common $seed ${!config} --stats "$W/${config}_$tag.json" -o "$W/${config}_$tag.exr" >/dev/null
    truth=$("$L" compare "$W/${config}_$tag.exr" "$W/pt_$tag.exr" | tail -1)
    ref=$("$L" compare "$W/${config}_$tag.exr" "$W/ref_$tag.exr" | tail -1)
    rgb=$(sed -E 's/.*R ([0-9.e+-]+) G ([0-9.e+-]+) B ([0-9.e+-]+).*/\1,\2,\3/' <<<"$truth")
    stats=$(python3 -c "
import json; d = json.load(open('$W/${config}_$tag.json')); p = {x['name']: x['ms'] for x in d['passes']}
frame = sum(p.get(k, 0) for k in ('light map', 'radiance map', 'mip blur', 'final'))
m = d['details'].get('memory_mib', {})
print('%.1f,%.1f,%.1f,%.1f' % (frame, p.get('setup', 0), m.get('total', 0), m.get('seed_formula', 0)))")
    echo "$tag,$mat,$config,$rgb,$(field "$truth"),$(field "$ref"),$stats"
  done
done
