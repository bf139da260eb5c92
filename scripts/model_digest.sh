#!/usr/bin/env bash
# Renders a fixed set of scenes x configurations (the covering design's shape) with the cycle and
# fp24 models and stores every output: images, hit EXRs and reports without host timings. Two
# directories written by two builds are then compared with --compare: a change made for speed or
# structure must leave every modelled figure, hit record and image identical.
#   scripts/model_digest.sh BIN OUTDIR         (BIN: a saarcor binary)
#   scripts/model_digest.sh --compare DIR_A DIR_B
set -euo pipefail
if [ "${1:-}" = "--compare" ]; then
  a=$2 b=$3 bad=0
  for f in "$a"/*; do
    n=$(basename "$f")
    case "$n" in
      *.exr) idiff -q -fail 0 -failpercent 0 "$f" "$b/$n" >/dev/null || { echo "differs: $n"; bad=1; } ;;
      *) cmp -s "$f" "$b/$n" || { echo "differs: $n"; bad=1; } ;;
    esac
  done
  [ "$(ls "$a" | wc -l)" = "$(ls "$b" | wc -l)" ] || { echo "file counts differ"; bad=1; }
  [ $bad = 0 ] && echo "identical: $(ls "$a" | wc -l) files"
  exit $bad
fi
bin=$1 out=$2
mkdir -p "$out"
here=$(cd "$(dirname "$0")/.." && pwd)
shared="$here/../shared/scenes"
scenes=(builtin:room builtin:terrain builtin:suncor builtin:dynamic
        "$shared/Duck/Duck.gltf" "$shared/CesiumMilkTruck/CesiumMilkTruck.gltf"
        "$shared/2CylinderEngine/2CylinderEngine.gltf")
configs=(
  "proto|"
  "t1p1|--set threads=1 --set packet=1 --set cache.traversal.items=8 --set cache.list.items=8 --set cache.transformation.items=8"
  "t4x3p16|--set pipelines=3 --set threads=4 --set packet=16 --set cache.traversal.items=8 --set cache.traversal.ways=2 --set cache.list.items=8 --set cache.list.ways=2"
  "t16x2lat|--set pipelines=2 --set threads=16 --set mem.scene_paths=1 --set lat.add=5 --set lat.mul=3 --set lat.div=9 --set lat.cmp=2 --set mem.latency=17 --set cache.hit_latency=3"
  "p16mb2|--set packet=16 --set mailbox=2 --set triangle_mailbox=0 --set cache.list.items=8"
  "t4x4sh|--set pipelines=4 --set threads=4 --set packet=1 --shadows --depth 3"
  "sh2|--set stack=48 --set cache.misses=2 --set clip.faces_per_step=3 --shadows --depth 2"
  "nso|--set threads=16 --set packet=16 --set shared_origin=0 --set clip.exit_only=0 --set traversal.skip_empty=0"
)
for s in "${scenes[@]}"; do
  sn=$(basename "$s"); sn=${sn#builtin:}; sn=${sn%%.*}
  for c in "${configs[@]}"; do
    cn=${c%%|*} args=${c#*|}
    for m in cycle fp24; do
      [ $m = fp24 ] && [ "$cn" != proto ] && [ "$cn" != t4x4sh ] && [ "$cn" != sh2 ] && continue
      p="$out/$sn-$cn-$m"
      a=$args
      [ $m = fp24 ] && a=$(echo "$args" | sed -E 's/--set [^ ]+//g')  # cycle keys only
      # shellcheck disable=SC2086
      "$bin" render "$s" --model $m --res 40x30 --bank-mb 32 $a --out "$p" --hits "$p-hits.exr" \
        --report "$p.raw.json" > /dev/null
      python3 - "$p.raw.json" "$p.json" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
for k in ("seconds", "rays_per_second", "host", "outputs"):  # host time, paths
    d.pop(k, None)
for k in ("build_seconds", "load_seconds"):
    d.get("configuration", {}).pop(k, None)
json.dump(d, open(sys.argv[2], "w"), indent=1, sort_keys=True)
PY
      rm "$p.raw.json"
    done
  done
done
echo "wrote $(ls "$out" | wc -l) files to $out"
