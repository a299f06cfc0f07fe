#!/usr/bin/env bash
# The previewer's targets measured (issue "A previewer that answers"): `lucent render`'s first image
# and refined image under its default budget, and `lucent view`'s first image and frame times while
# it refines with an orbit a second, at 640 x 480 on the machine it runs on. Writes previewer.csv
# here (or in $1). Run from the repository root with a built lucent ($LUCENT, default build/ci).
set -euo pipefail
lucent="${LUCENT:-build/ci/cli/lucent}"
out="${1:-notebooks_data/bench}"
runs="${RUNS:-3}"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
csv="$out/previewer.csv"
echo "command,material,mesh,size,shader_cache,run,first_image_s,total_s,level,frames_rendered,median_frame_ms,p95_frame_ms,longest_frame_ms,frames_over_100ms" >"$csv.tmp"

for material in skin1 marble; do
  # render: the time from launch to the first image file, and to the end.
  for run in $(seq "$runs"); do
    export MESA_SHADER_CACHE_DIR="$tmp/cache-render-$material"
    rm -f "$tmp/r.png"
    start=$(date +%s.%N)
    "$lucent" render --material "$material" --mesh bunny --size 640x480 -o "$tmp/r.png" \
      --stats "$tmp/r.json" >"$tmp/r.out" 2>"$tmp/r.err" &
    pid=$!
    first=""
    while kill -0 "$pid" 2>/dev/null; do
      if [ -z "$first" ] && [ -s "$tmp/r.png" ]; then first=$(date +%s.%N); fi
      sleep 0.02
    done
    wait "$pid"
    end=$(date +%s.%N)
    [ -z "$first" ] && first=$end
    level=$(python3 -c "import json;d=json.load(open('$tmp/r.json'));print(d['budget']['quality'].replace(',',''))")
    cache=$([ "$run" = 1 ] && echo cold || echo warm)
    echo "render,$material,bunny,640x480,$cache,$run,$(python3 -c "print(round($first - $start, 2))"),$(python3 -c "print(round($end - $start, 2))"),$level,,,,," >>"$csv.tmp"
  done
  # view: an orbit a second for 25 s while it refines; its summary line has the figures.
  script="wait 2"
  for i in $(seq 25); do script="$script;sleep 1;orbit 8 0"; done
  script="$script;quit"
  for run in $(seq "$runs"); do
    export MESA_SHADER_CACHE_DIR="$tmp/cache-view-$material"
    xvfb-run -a -s "-screen 0 1400x900x24" "$lucent" view --material "$material" --mesh bunny \
      --size 640x480 --script "$script" >"$tmp/v.out" 2>"$tmp/v.err"
    line=$(grep "first image after" "$tmp/v.out")
    level=$(sed -n 's/.*quality level \([0-9]*\) of \([0-9]*\) (\([^)]*\)).*/level \1 of \2 \3/p' "$tmp/v.out" | tr -d ',')
    cache=$([ "$run" = 1 ] && echo cold || echo warm)
    echo "$line" | python3 -c "
import re,sys
l=sys.stdin.read()
m=re.search(r'first image after ([0-9.]+) s; ([0-9]+) frames rendered after it: median ([0-9]+) ms, 95% within ([0-9]+) ms, longest ([0-9]+) ms, ([0-9]+) over 100 ms',l)
print(','.join(['view','$material','bunny','640x480','$cache','$run',m.group(1),'26','$level',m.group(2),m.group(3),m.group(4),m.group(5),m.group(6)]))" >>"$csv.tmp"
  done
done
mv "$csv.tmp" "$csv"
echo "previewer_bench: wrote $csv"
