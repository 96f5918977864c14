#!/usr/bin/env bash
# Builds the ORB-SLAM2 benchmark peer out of tree, into build-peers/ (ignored by git):
#   Pangolin v0.6 (no FFmpeg/Python/video/examples/tests/tools) -> build-peers/pangolin-install
#   ORB-SLAM2 f2e6f51 + its DBoW2 and g2o, patched with scripts/peers/patches/*.patch, Release
#   build-peers/bin/orbslam2_stereo_kitti (runner) and build-peers/bin/train_vocabulary
#   build-peers/vocabulary/orbvoc.txt (trained by scripts/peers/train_vocabulary.sh if absent)
# The archives are read from $PLANELOC_PEERS_DIR (default: <repo>/../shared/peers).
# A second call does nothing when the stamp build-peers/.orbslam2.stamp matches the current
# archives, patches and tool sources; the stamp is removed before any build step and written last,
# so an interrupted build is never taken for a good one (.orbslam2-bin.stamp likewise marks the
# binaries as complete, so that a missing vocabulary does not rebuild them).
#
# Environment:
#   PLANELOC_PEERS_DIR    folder with ORB_SLAM2-f2e6f51.tar.gz and Pangolin-v0.6.tar.gz
#   PLANELOC_ORBVOC       use this vocabulary file (copied to build-peers/vocabulary/orbvoc.txt)
#                         instead of training one
#   PLANELOC_PEERS_NO_TRAIN=1   never train: a missing vocabulary is an error (exit 2)
#   JOBS                  make -j (default 2, the maximum on the shared machine)
# Exit status: 0 built (or already built), 2 bad input (archive missing, patch does not apply,
# vocabulary absent and not trainable), other = a build step failed (see the log it names).
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
repo="$(cd "$here/../.." && pwd)"
peers_dir="${PLANELOC_PEERS_DIR:-$repo/../shared/peers}"
out="$repo/build-peers"
jobs="${JOBS:-2}"
orb_archive="$peers_dir/ORB_SLAM2-f2e6f51.tar.gz"
pangolin_archive="$peers_dir/Pangolin-v0.6.tar.gz"
stamp="$out/.orbslam2.stamp"
voc="$out/vocabulary/orbvoc.txt"

die() { echo "build_orbslam2: $*" >&2; exit 2; }
log() { echo "build_orbslam2: $*" >&2; }
# run LOGFILE CMD...: nice'd, output to LOGFILE; on failure print its tail and stop.
run() {
  local logfile="$1"; shift
  if ! nice -n 10 "$@" >"$logfile" 2>&1; then
    tail -n 30 "$logfile" >&2
    echo "build_orbslam2: FAILED: $* (log: $logfile)" >&2
    exit 1
  fi
}

for a in "$orb_archive" "$pangolin_archive"; do
  [[ -f "$a" ]] || die "archive missing: $a (set PLANELOC_PEERS_DIR to the folder that holds it)"
done
shopt -s nullglob
patches=("$here"/patches/*.patch)
shopt -u nullglob
((${#patches[@]} > 0)) || die "no patch files in $here/patches"

# What the build depends on; a change in any of these rebuilds everything but the vocabulary.
fingerprint="$(cd "$here" && sha256sum "$orb_archive" "$pangolin_archive" patches/*.patch \
  CMakeLists.txt orbslam2_stereo_kitti.cc train_vocabulary.cc build_orbslam2.sh | sha256sum | cut -d' ' -f1)"

if [[ -f "$stamp" && "$(cat "$stamp")" == "$fingerprint" && -x "$out/bin/orbslam2_stereo_kitti" \
      && -s "$voc" ]]; then
  log "already built ($out; remove $stamp to force a rebuild)"
  exit 0
fi

mkdir -p "$out/logs"
rm -f "$stamp"
t_start=$(date +%s)
bin_stamp="$out/.orbslam2-bin.stamp"
if [[ -f "$bin_stamp" && "$(cat "$bin_stamp")" == "$fingerprint" && -x "$out/bin/orbslam2_stereo_kitti" ]]; then
  log "binaries up to date; only the vocabulary is missing"
else
rm -f "$bin_stamp"

# 1. Unpack fresh and patch (in a staging dir, so a bad patch leaves the old tree untouched).
staging="$out/.staging"
rm -rf "$staging"
mkdir -p "$staging"
tar -xzf "$orb_archive" -C "$staging" || die "cannot unpack $orb_archive"
tar -xzf "$pangolin_archive" -C "$staging" || die "cannot unpack $pangolin_archive"
[[ -d "$staging/ORB_SLAM2" && -d "$staging/Pangolin" ]] || die "archives do not hold ORB_SLAM2/ and Pangolin/"
for p in "${patches[@]}"; do
  if ! patch -d "$staging/ORB_SLAM2" -p1 --forward --batch --dry-run <"$p" >"$out/logs/patch.log" 2>&1; then
    cat "$out/logs/patch.log" >&2
    rm -rf "$staging"
    die "patch does not apply: $p"
  fi
  patch -d "$staging/ORB_SLAM2" -p1 --forward --batch --quiet <"$p"
  log "applied $(basename "$p")"
done
rm -rf "${out:?}/ORB_SLAM2" "${out:?}/Pangolin" "${out:?}/pangolin-build" "${out:?}/pangolin-install" \
  "${out:?}/tools-build" "${out:?}/bin"
mv "$staging/ORB_SLAM2" "$staging/Pangolin" "$out/"
rmdir "$staging"

# 2. Pangolin (installed into build-peers/pangolin-install).
log "Pangolin ..."
mkdir -p "$out/pangolin-build"
run "$out/logs/pangolin-cmake.log" cmake -S "$out/Pangolin" -B "$out/pangolin-build" \
  -DCMAKE_BUILD_TYPE=Release -DCMAKE_INSTALL_PREFIX="$out/pangolin-install" \
  -DBUILD_EXAMPLES=OFF -DBUILD_TESTS=OFF -DBUILD_TOOLS=OFF -DBUILD_PANGOLIN_PYTHON=OFF \
  -DBUILD_PANGOLIN_FFMPEG=OFF -DBUILD_PANGOLIN_VIDEO=OFF
run "$out/logs/pangolin-make.log" make -C "$out/pangolin-build" -j"$jobs"
run "$out/logs/pangolin-install.log" make -C "$out/pangolin-build" install
pangolin_cmake_dir="$(dirname "$(find "$out/pangolin-install" -name PangolinConfig.cmake | head -n 1)")"
[[ -f "$pangolin_cmake_dir/PangolinConfig.cmake" ]] || { echo "build_orbslam2: no PangolinConfig.cmake" >&2; exit 1; }

# 3. DBoW2 and g2o (as ORB-SLAM2's build.sh does: libraries land in Thirdparty/*/lib).
for lib in DBoW2 g2o; do
  log "$lib ..."
  src="$out/ORB_SLAM2/Thirdparty/$lib"
  run "$out/logs/$lib-cmake.log" cmake -S "$src" -B "$src/build" -DCMAKE_BUILD_TYPE=Release
  run "$out/logs/$lib-make.log" make -C "$src/build" -j"$jobs"
done

# 4. The ORB-SLAM2 library only (its Examples are not built: the runner replaces stereo_kitti).
log "ORB_SLAM2 ..."
run "$out/logs/orbslam2-cmake.log" cmake -S "$out/ORB_SLAM2" -B "$out/ORB_SLAM2/build" \
  -DCMAKE_BUILD_TYPE=Release -DPangolin_DIR="$pangolin_cmake_dir"
run "$out/logs/orbslam2-make.log" make -C "$out/ORB_SLAM2/build" -j"$jobs" ORB_SLAM2

# 5. The runner and the vocabulary trainer (scripts/peers/*.cc).
log "runner and trainer ..."
run "$out/logs/tools-cmake.log" cmake -S "$here" -B "$out/tools-build" -DCMAKE_BUILD_TYPE=Release \
  -DORB_SLAM2_DIR="$out/ORB_SLAM2" -DPangolin_DIR="$pangolin_cmake_dir"
run "$out/logs/tools-make.log" make -C "$out/tools-build" -j"$jobs"
mkdir -p "$out/bin"
cp "$out/tools-build/orbslam2_stereo_kitti" "$out/tools-build/train_vocabulary" "$out/bin/"
echo "$fingerprint" >"$bin_stamp.tmp" && mv "$bin_stamp.tmp" "$bin_stamp"
log "binaries built in $(($(date +%s) - t_start)) s"
fi

# 6. Vocabulary (kept across rebuilds; it depends only on the images and ORB-SLAM2's extractor).
mkdir -p "$out/vocabulary"
if [[ -n "${PLANELOC_ORBVOC:-}" ]]; then
  [[ -s "$PLANELOC_ORBVOC" ]] || die "vocabulary absent: PLANELOC_ORBVOC=$PLANELOC_ORBVOC is not a file"
  cp "$PLANELOC_ORBVOC" "$voc.tmp" && mv "$voc.tmp" "$voc"
  echo "copied from $PLANELOC_ORBVOC on $(date -u +%F)" >"$voc.info"
elif [[ ! -s "$voc" ]]; then
  [[ "${PLANELOC_PEERS_NO_TRAIN:-0}" != 1 ]] \
    || die "vocabulary absent: $voc (PLANELOC_PEERS_NO_TRAIN=1; set PLANELOC_ORBVOC or allow training)"
  log "vocabulary absent: training it (scripts/peers/train_vocabulary.sh) ..."
  "$here/train_vocabulary.sh" || {
    rc=$?
    [[ $rc == 2 ]] && die "vocabulary absent and cannot be trained (see above)"
    echo "build_orbslam2: vocabulary training failed ($rc)" >&2
    exit 1
  }
fi
[[ -s "$voc" ]] || die "vocabulary absent: $voc"

echo "$fingerprint" >"$stamp.tmp" && mv "$stamp.tmp" "$stamp"
log "done in $(($(date +%s) - t_start)) s: $out/bin/orbslam2_stereo_kitti, vocabulary $voc"
