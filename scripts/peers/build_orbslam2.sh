#!/usr/bin/env bash
# Builds the ORB-SLAM2 benchmark peer out of tree, into build-peers/ (ignored by git):
#   Pangolin v0.6 (no FFmpeg/Python/video/examples/tests/tools) -> build-peers/pangolin-install
#   ORB-SLAM2 f2e6f51 + its DBoW2 and g2o, patched with scripts/peers/patches/*.patch, Release
#   build-peers/bin/orbslam2_stereo_kitti (runner) and build-peers/bin/train_vocabulary
#   build-peers/vocabulary/orbvoc.txt (trained by scripts/peers/train_vocabulary.sh if absent)
# The archives are read from $PLANELOC_PEERS_DIR (default: <repo>/../shared/peers).
# A second call does nothing when the stamp build-peers/.orbslam2.stamp matches the current
# archives, patches and tool sources; stamps are removed before a stage starts and written when
# it has completed (the final one last), so an interrupted build is never taken for a good one.
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
pangolin_cmake_dir() {
  local cfg
  cfg="$(find "$out/pangolin-install" -name PangolinConfig.cmake | head -n 1)"
  [[ -n "$cfg" ]] || { echo "build_orbslam2: no PangolinConfig.cmake under $out/pangolin-install" >&2; exit 1; }
  dirname "$cfg"
}
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

# Debian packages the peer needs beyond planeloc's (scripts/setup.sh): Pangolin's OpenGL/GLEW.
# A fresh machine without them fails deep in Pangolin's CMake; say so here instead.
missing=()
for pkg in libglew-dev libgl-dev libegl-dev libopencv-dev libeigen3-dev; do
  dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "install ok installed" || missing+=("$pkg")
done
((${#missing[@]} == 0)) ||
  die "Debian packages missing: ${missing[*]} (install them: apt-get install -y ${missing[*]})"

for a in "$orb_archive" "$pangolin_archive"; do
  [[ -f "$a" ]] || die "archive missing: $a (set PLANELOC_PEERS_DIR to the folder that holds it)"
done
shopt -s nullglob
patches=("$here"/patches/*.patch)
shopt -u nullglob
((${#patches[@]} > 0)) || die "no patch files in $here/patches"

# Three stages, each with a stamp holding the fingerprint of what it depends on; a stamp is removed
# before its stage starts and written when it has completed, and a stage redone invalidates the
# later ones:
#   core  (Pangolin, DBoW2, g2o, libORB_SLAM2): the archives, the patches, this script
#   tools (runner, trainer): core + scripts/peers/CMakeLists.txt and *.cc
#   all   (tools + a vocabulary present)
core_fp="$(cd "$here" && sha256sum "$orb_archive" "$pangolin_archive" patches/*.patch build_orbslam2.sh \
  | sha256sum | cut -d' ' -f1)"
tools_fp="$( (echo "$core_fp"; cd "$here" && sha256sum CMakeLists.txt orbslam2_stereo_kitti.cc train_vocabulary.cc) \
  | sha256sum | cut -d' ' -f1)"
core_stamp="$out/.orbslam2-core.stamp"
tools_stamp="$out/.orbslam2-tools.stamp"
stamp_ok() { [[ -f "$1" && "$(cat "$1")" == "$2" ]]; }
write_stamp() { echo "$2" >"$1.tmp" && mv "$1.tmp" "$1"; }

if stamp_ok "$stamp" "$tools_fp" && [[ -x "$out/bin/orbslam2_stereo_kitti" && -s "$voc" ]]; then
  log "already built ($out; remove $stamp to force a check, $core_stamp to force a rebuild)"
  exit 0
fi

mkdir -p "$out/logs"
rm -f "$stamp"
t_start=$(date +%s)

if stamp_ok "$core_stamp" "$core_fp" && [[ -f "$out/ORB_SLAM2/lib/libORB_SLAM2.so" ]]; then
  log "ORB-SLAM2 and its dependencies up to date"
else
  rm -f "$core_stamp" "$tools_stamp"

  # 1. Unpack fresh and patch (in a staging dir, so a bad patch leaves the old tree untouched).
  staging="$out/.staging"
  rm -rf "$staging"
  mkdir -p "$staging"
  tar -xzf "$orb_archive" -C "$staging" || die "cannot unpack $orb_archive"
  tar -xzf "$pangolin_archive" -C "$staging" || die "cannot unpack $pangolin_archive"
  [[ -d "$staging/ORB_SLAM2" && -d "$staging/Pangolin" ]] || die "archives do not hold ORB_SLAM2/ and Pangolin/"
  for p in "${patches[@]}"; do
    if ! patch -d "$staging/ORB_SLAM2" -p1 --forward --batch --fuzz=0 --dry-run <"$p" >"$out/logs/patch.log" 2>&1; then
      cat "$out/logs/patch.log" >&2
      rm -rf "$staging"
      die "patch does not apply: $p"
    fi
    patch -d "$staging/ORB_SLAM2" -p1 --forward --batch --fuzz=0 --quiet <"$p"
    log "applied $(basename "$p")"
  done
  rm -rf "${out:?}/ORB_SLAM2" "${out:?}/Pangolin" "${out:?}/pangolin-build" "${out:?}/pangolin-install" \
    "${out:?}/tools-build" "${out:?}/bin"
  mv "$staging/ORB_SLAM2" "$staging/Pangolin" "$out/"
  rmdir "$staging"

  # 2. Pangolin (installed into build-peers/pangolin-install).
  log "Pangolin ..."
  run "$out/logs/pangolin-cmake.log" cmake -S "$out/Pangolin" -B "$out/pangolin-build" \
    -DCMAKE_BUILD_TYPE=Release -DCMAKE_INSTALL_PREFIX="$out/pangolin-install" \
    -DBUILD_EXAMPLES=OFF -DBUILD_TESTS=OFF -DBUILD_TOOLS=OFF -DBUILD_PANGOLIN_PYTHON=OFF \
    -DBUILD_PANGOLIN_FFMPEG=OFF -DBUILD_PANGOLIN_VIDEO=OFF
  run "$out/logs/pangolin-make.log" make -C "$out/pangolin-build" -j"$jobs"
  run "$out/logs/pangolin-install.log" make -C "$out/pangolin-build" install

  # 3. DBoW2 and g2o (as ORB-SLAM2's build.sh does: the libraries land in Thirdparty/*/lib).
  for lib in DBoW2 g2o; do
    log "$lib ..."
    src="$out/ORB_SLAM2/Thirdparty/$lib"
    run "$out/logs/$lib-cmake.log" cmake -S "$src" -B "$src/build" -DCMAKE_BUILD_TYPE=Release
    run "$out/logs/$lib-make.log" make -C "$src/build" -j"$jobs"
  done

  # 4. The ORB-SLAM2 library only (its Examples are not built: the runner replaces stereo_kitti).
  log "ORB_SLAM2 ..."
  pangolin_dir="$(pangolin_cmake_dir)"
  run "$out/logs/orbslam2-cmake.log" cmake -S "$out/ORB_SLAM2" -B "$out/ORB_SLAM2/build" \
    -DCMAKE_BUILD_TYPE=Release -DPangolin_DIR="$pangolin_dir"
  run "$out/logs/orbslam2-make.log" make -C "$out/ORB_SLAM2/build" -j"$jobs" ORB_SLAM2
  write_stamp "$core_stamp" "$core_fp"
  log "ORB-SLAM2 built in $(($(date +%s) - t_start)) s"
fi

# 5. The runner and the vocabulary trainer (scripts/peers/*.cc).
if stamp_ok "$tools_stamp" "$tools_fp" && [[ -x "$out/bin/orbslam2_stereo_kitti" && -x "$out/bin/train_vocabulary" ]]; then
  log "runner and trainer up to date"
else
  rm -f "$tools_stamp"
  log "runner and trainer ..."
  pangolin_dir="$(pangolin_cmake_dir)"
  run "$out/logs/tools-cmake.log" cmake -S "$here" -B "$out/tools-build" -DCMAKE_BUILD_TYPE=Release \
    -DORB_SLAM2_DIR="$out/ORB_SLAM2" -DPangolin_DIR="$pangolin_dir"
  run "$out/logs/tools-make.log" make -C "$out/tools-build" -j"$jobs"
  mkdir -p "$out/bin"
  cp "$out/tools-build/orbslam2_stereo_kitti" "$out/tools-build/train_vocabulary" "$out/bin/"
  write_stamp "$tools_stamp" "$tools_fp"
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

write_stamp "$stamp" "$tools_fp"
log "done in $(($(date +%s) - t_start)) s: $out/bin/orbslam2_stereo_kitti, vocabulary $voc"
