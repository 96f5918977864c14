#!/usr/bin/env bash
# Trains the ORB vocabulary of the ORB-SLAM2 peer (the published ORBvoc.txt is not available) with
# build-peers/bin/train_vocabulary (ORB-SLAM2's own ORBextractor + bundled DBoW2).
#   scripts/peers/train_vocabulary.sh          -> build-peers/vocabulary/orbvoc.txt      (k=10, L=6)
#   scripts/peers/train_vocabulary.sh --alt    -> build-peers/vocabulary/orbvoc-alt.txt  (k=10, L=6,
#                                                 real KITTI frames only: the training-set effect)
# Training images are ones the benchmark never evaluates on:
#   planeloc sim --preset small --seed 101 --frames 150, --seed 102 --frames 150,
#   planeloc sim --preset kitti07-like --seed 103 --frames 300 (evaluation uses small 3/7/11/21 and
#   kitti07-like 1/2): every 3rd frame, left and right image;
#   KITTI raw 2011_09_26_drive_0023 (7 frames, image_02 + image_03) and drive_0052 (image_02: 20,
#   image_00: 10) from $PLANELOC_DATA_DIR (default <repo>/../shared/data).
# The sims are written once to build-peers/vocabulary/train-data/ (about 1.6 GB, ~5 min of CPU).
# Exit status: 0 ok, 2 an input is missing (planeloc CLI, trainer, KITTI data), 1 other failure.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
repo="$(cd "$here/../.." && pwd)"
out="$repo/build-peers/vocabulary"
data="${PLANELOC_DATA_DIR:-$repo/../shared/data}"
planeloc="${PLANELOC_BIN:-$repo/build/bin/planeloc}"
trainer="$repo/build-peers/bin/train_vocabulary"
k=10
levels=6
variant=main
if [[ "${1:-}" == --alt ]]; then variant=alt; fi

die() { echo "train_vocabulary: $*" >&2; exit 2; }
[[ -x "$trainer" ]] || die "trainer missing: $trainer (run scripts/peers/build_orbslam2.sh)"
raw23="$data/kitti-raw-2011_09_26_drive_0023-7frames"
raw52="$data/kitti-raw-2011_09_26_drive_0052-lidar-camera"
for d in "$raw23/image_02/data" "$raw23/image_03/data" "$raw52/image_02/data" "$raw52/image_00/data"; do
  [[ -d "$d" ]] || die "training images missing: $d (set PLANELOC_DATA_DIR)"
done

mkdir -p "$out/train-data"
list="$out/train-$variant.list"
: >"$list.tmp"
sources=()
if [[ $variant == main ]]; then
  [[ -x "$planeloc" ]] || die "planeloc CLI missing: $planeloc (build planeloc first, or set PLANELOC_BIN)"
  for spec in "small 101 150" "small 102 150" "kitti07-like 103 300"; do
    read -r preset seed frames <<<"$spec"
    name="$preset-seed$seed-${frames}f"
    dir="$out/train-data/$name"
    if [[ ! -d "$dir" ]]; then
      echo "train_vocabulary: planeloc sim --preset $preset --seed $seed --frames $frames ..." >&2
      rm -rf "$dir.partial"
      nice -n 10 "$planeloc" sim --preset "$preset" --seed "$seed" --frames "$frames" \
        --out "$dir.partial" >"$dir.log" 2>&1 || { tail -n 20 "$dir.log" >&2; exit 1; }
      mv "$dir.partial" "$dir"
    fi
    for ((i = 0; i < frames; i += 3)); do
      printf '%s/sequences/00/image_0/%06d.png\n%s/sequences/00/image_1/%06d.png\n' \
        "$dir" "$i" "$dir" "$i" >>"$list.tmp"
    done
    sources+=("planeloc sim --preset $preset --seed $seed --frames $frames: every 3rd frame, left+right")
  done
fi
find "$raw23/image_02/data" "$raw23/image_03/data" "$raw52/image_02/data" "$raw52/image_00/data" \
  -name '*.png' | sort >>"$list.tmp"
sources+=("KITTI raw 2011_09_26_drive_0023 frames 139-145 (image_02, image_03)"
  "KITTI raw 2011_09_26_drive_0052 (image_02 frames 0-19, image_00 frames 0-9)")
mv "$list.tmp" "$list"

voc="$out/orbvoc.txt"
[[ $variant == alt ]] && voc="$out/orbvoc-alt.txt"
echo "train_vocabulary: $(wc -l <"$list") images -> $voc (k=$k, L=$levels) ..." >&2
# ORBextractor breaks ties in its octree split by heap address (it sorts (size, node pointer)
# pairs), so with address-space randomisation the same image can give slightly different
# keypoints from run to run; setarch -R turns randomisation off and makes the vocabulary
# reproducible (checked: two trainings, identical files).
norand=()
if setarch "$(uname -m)" -R true 2>/dev/null; then norand=(setarch "$(uname -m)" -R); fi
stats="$(nice -n 10 "${norand[@]}" "$trainer" "$k" "$levels" "$list" "$voc")"
{
  echo "vocabulary: $(basename "$voc") (trained $(date -u +%F) by scripts/peers/train_vocabulary.sh${1:+ $1})"
  echo "trainer: ORB-SLAM2's ORBextractor(2000, 1.2, 8, 20, 7) + bundled DBoW2, TF-IDF, L1, fixed seed${norand[*]:+, ${norand[*]}}"
  printf 'source: %s\n' "${sources[@]}"
  echo "$stats"
} >"$voc.info"
cat "$voc.info"
