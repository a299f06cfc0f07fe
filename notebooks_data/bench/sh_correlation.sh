#!/bin/bash
# The SH fast translucency (--technique sh) against the CPU reference after a best-fit scale:
# bunny and sphere, back-lit and side-lit, skin1 / marble / potato; 64 px, reference 2048 probes per
# pixel, subsurface term only. Prints one line per scene (lucent compare --fit-scale);
# sh_correlation.csv holds a run (before/after the filtered thickness look-up of this stop).
# Usage: sh_correlation.sh [LUCENT] [WORKDIR]   (about 4 min on 2 cores, mostly the references)
set -euo pipefail
L=${1:-build/ci/cli/lucent}
W=${2:-$(mktemp -d)}
for mesh in bunny sphere; do
  for lit in back:0,0.3,-1 side:1,0.2,0; do
    name=${lit%%:*}; dir=${lit#*:}
    [ "$mesh" = sphere ] && [ "$name" = back ] && dir=0.6,0,-0.8
    for mat in skin1 marble potato; do
      [ "$mesh" = sphere ] && [ "$mat" = potato ] && continue
      tag=${mesh}_${name}_${mat}
      common="--material $mat --mesh $mesh --size 64x64 --light directional:$dir:3,3,3 --specular off"
      [ -f "$W/ref_$tag.exr" ] || "$L" render --technique reference --reference-samples-pixel 2048 \
        --reference-threads 2 $common -o "$W/ref_$tag.exr" >/dev/null
      "$L" render --technique sh $common -o "$W/sh_$tag.exr" >/dev/null
      echo "$tag $("$L" compare "$W/sh_$tag.exr" "$W/ref_$tag.exr" --fit-scale | grep -i correl)"
    done
  done
done
