#!/bin/bash
# The previews against the path-traced truth (--technique pathtrace: the medium itself, no
# diffusion model): spheres of 30 mm under a sun from the camera's side ("front"), one from behind
# and to the side ("back": the camera sees part of the lit side) and one from straight behind
# ("behind": it sees only light that crossed the sphere), then of 10 and 100 mm under the first
# (marble's truth at 100 mm is out of reach on a CPU), four materials from high to low albedo at
# their own eta, two at eta 1, and under a uniform white sky ("sky", 16 lights); then the issue's
# other targets (skies at 15 and 100 mm and over ketchup, the sun at eta 1 at 15 mm and on
# ketchup). 64 px, subsurface term only (--specular off), the truth at TRUTH_SAMPLES paths per
# pixel (default 512: ~0.3% noise in the object's mean). Rows: the maps at light settings (K 8, N 16, W 128, 16 frames) as they
# render by default (single scattering, the angular and the shape's factors on: "maps"), without
# the shape's factor ("mapsflat") and before all three ("mapsold"), the reference (the material's
# model, 512 probes: "ref") and the hierarchical technique (dipole: "hier"). Writes CSV lines
# (scene,material,eta,size_mm,light,technique,mean_R,mean_G,mean_B,relative_rmse,block_rmse: per
# pixel and over 4x4 blocks wholly on the object) to stdout;
# previews_vs_truth.csv holds a run. Truths already in WORKDIR (pt_<scene>.exr) are reused.
# Usage: previews_vs_truth.sh [LUCENT] [WORKDIR]   (about 90 min on 2 cores, mostly the truth)
set -euo pipefail
L=${1:-build/ci/cli/lucent}
W=${2:-$(mktemp -d)}
export MESA_SHADER_CACHE_DISABLE=true
N=${TRUTH_SAMPLES:-512}
# A uniform white sky (radiance 1), as Radiance RGBE: 1.0 = mantissa 128, exponent 129.
python3 -c "
import sys
w, h = 64, 32
sys.stdout.buffer.write(b'#?RADIANCE\\nFORMAT=32-bit_rle_rgbe\\n\\n-Y %d +X %d\\n' % (h, w) + bytes([128, 128, 128, 129]) * (w * h))
" > "$W/uniform_sky.hdr"
maps="--maps-frames 16 --maps-directions 8 --maps-samples 16 --maps-radiance-map 128 --maps-light-map 256"
echo "scene,material,eta,size_mm,light,technique,mean_R,mean_G,mean_B,relative_rmse,block_rmse"
# One scene: material, eta (own or 1.0), sphere size (mm), light (front or back).
scene() {
  local mat=$1 eta=$2 size=$3 lit=$4 m=$1 e
  if [ "$eta" = 1.0 ]; then
  m="$W/${mat}_eta1.json"
  python3 -c "import json; d=json.load(open('materials/library/$mat.json')); d['ior']=1.0; json.dump(d, open('$m','w'))"
  fi
  e=$(python3 -c "import json; print(1.0 if '$eta'=='1.0' else json.load(open('materials/library/$mat.json'))['ior'])")
  local name=${lit%%:*} dir=${lit#*:} tag common line rmse rgb t
  name=${lit%%:*}; dir=${lit#*:}
  tag=${mat}_${eta}_${size}_${name}
  local light="--light directional:$dir:1,1,1"
  [ "$dir" = sky ] && light="--env $W/uniform_sky.hdr:16"
  common="--material $m --mesh sphere --object-size-mm $size --size 64x64 $light --specular off"
  [ -f "$W/pt_$tag.exr" ] || "$L" render --technique pathtrace --pathtrace-samples-pixel $N $common -o "$W/pt_$tag.exr" >/dev/null
  # REUSE=1: keep the previews already rendered in WORKDIR (to recompute the comparisons only).
  have() { [ -n "${REUSE:-}" ] && [ -f "$W/$1_$tag.exr" ]; }
  have maps || "$L" render --technique maps $common $maps -o "$W/maps_$tag.exr" >/dev/null
  have mapsflat || "$L" render --technique maps $common $maps --geometry-factor off -o "$W/mapsflat_$tag.exr" >/dev/null
  have mapsold || "$L" render --technique maps $common $maps --single-scattering off --angular off --geometry-factor off -o "$W/mapsold_$tag.exr" >/dev/null
  have ref || "$L" render --technique reference --reference-samples-pixel 512 $common -o "$W/ref_$tag.exr" >/dev/null
  have hier || "$L" render --technique hierarchical --model dipole $common -o "$W/hier_$tag.exr" >/dev/null
  for t in maps mapsflat mapsold ref hier; do
    line=$("$L" compare "$W/${t}_$tag.exr" "$W/pt_$tag.exr" | tail -1)
    rmse=$(echo "$line" | sed -E 's/.*relative RMSE ([0-9.e+-]+) over [0-9]+ pixels.*/\1/')
    block=$(echo "$line" | sed -nE 's/.*4x4 blocks: relative RMSE ([0-9.e+-]+).*/\1/p')
    rgb=$(echo "$line" | sed -E 's/.*R ([0-9.e+-]+) G ([0-9.e+-]+) B ([0-9.e+-]+).*/\1,\2,\3/')
    echo "$tag,$mat,$e,$size,$name,$t,$rgb,$rmse,$block"
  done
}
# The materials at 30 mm under both suns (marble from behind: its truth takes over 10 min at 512
# paths, left out), then the sizes under the front sun, then eta 1.
for mat in potato skin1 marble ketchup; do
  for lit in front:0.4,0.5,1 back:-1,0.3,-0.5; do
    [ "$mat/$lit" = marble/back:-1,0.3,-0.5 ] || scene $mat own 30 $lit
  done
done
for mat in potato skin1 ketchup; do
  for size in 10 100; do scene $mat own $size front:0.4,0.5,1; done
done
for mat in potato skin1; do scene $mat 1.0 30 front:0.4,0.5,1; done
for mat in potato skin1 ketchup; do scene $mat own 30 behind:0,0.2,-1; done
scene potato own 10 behind:0,0.2,-1
for mat in potato skin1 marble; do scene $mat own 30 sky:sky; done
scene potato own 10 sky:sky
# The other target scenes: skies at 15 and 100 mm and over ketchup, the sun at eta 1 at 15 mm
# and over ketchup (a sphere of 3.6 mean free paths in red).
scene ketchup own 30 sky:sky
for mat in potato skin1 marble; do scene $mat own 15 sky:sky; done
scene ketchup own 100 sky:sky
scene potato 1.0 15 front:0.4,0.5,1
scene ketchup 1.0 30 front:0.4,0.5,1
