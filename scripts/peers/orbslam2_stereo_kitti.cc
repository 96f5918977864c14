// Benchmark runner for the ORB-SLAM2 peer (out of tree; built by scripts/peers/build_orbslam2.sh
// against build-peers/ORB_SLAM2/lib/libORB_SLAM2.so). Not part of planeloc.
//
//   orbslam2_stereo_kitti VOCABULARY SETTINGS SEQUENCE_DIR OUT_POSES
//
// Same job as ORB-SLAM2's Examples/Stereo/stereo_kitti.cc (feed image_0/image_1 pairs with the
// times of times.txt to System::TrackStereo), but:
//  - no viewer and no real-time wait: frames are fed as fast as ORB-SLAM2 takes them;
//  - the loop-closing thread is never created ("ORB-SLAM2 without loop closing", the paper's
//    baseline; needs patch 0004). ORBSLAM2_LOOP_CLOSING=1 in the environment turns it back on;
//  - one pose line per frame is written and flushed as soon as the frame is tracked (KITTI
//    format: the 3x4 [R|t] of the LEFT camera, camera-to-world, world = the camera at the frame
//    where ORB-SLAM2 initialised, normally frame 0);
//  - OUT_POSES.timing.csv holds one row per frame: decode and TrackStereo wall time and the
//    tracking state (see docs/peers.md for the columns and the rules for lost frames);
//  - after the last frame ORB-SLAM2's own end-of-run trajectory (SaveTrajectoryKITTI, poses
//    re-derived from the final keyframes) is written to OUT_POSES.final.txt.
// Exit status: 0 = ran (lost frames are not a failure, they are in the CSV), 1 = input/output
// error, 2 = usage, 3 = ran but no frame was ever tracked.

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <opencv2/core/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "System.h"

namespace {

using Clock = std::chrono::steady_clock;

double MsSince(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

bool FileReadable(const std::string& path) {
  std::ifstream f(path);
  return f.good();
}

const char* StateName(int state) {
  switch (state) {
    case -1:
      return "SYSTEM_NOT_READY";
    case 0:
      return "NO_IMAGES_YET";
    case 1:
      return "NOT_INITIALIZED";
    case 2:
      return "OK";
    case 3:
      return "LOST";
    default:
      return "UNKNOWN";
  }
}

// times.txt: one timestamp (s) per line; image_0/%06d.png, image_1/%06d.png.
bool LoadSequence(const std::string& dir, std::vector<std::string>* left,
                  std::vector<std::string>* right, std::vector<double>* times) {
  std::ifstream f(dir + "/times.txt");
  if (!f) {
    std::cerr << "orbslam2_stereo_kitti: cannot read " << dir << "/times.txt\n";
    return false;
  }
  std::string line;
  while (std::getline(f, line)) {
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    std::istringstream is(line);
    double t = 0;
    if (!(is >> t)) {
      std::cerr << "orbslam2_stereo_kitti: bad line in times.txt: '" << line << "'\n";
      return false;
    }
    char name[32];
    std::snprintf(name, sizeof name, "%06zu.png", times->size());
    left->push_back(dir + "/image_0/" + name);
    right->push_back(dir + "/image_1/" + name);
    times->push_back(t);
  }
  if (times->empty()) {
    std::cerr << "orbslam2_stereo_kitti: " << dir << "/times.txt has no frames\n";
    return false;
  }
  return true;
}

size_t CountTracked(const std::vector<ORB_SLAM2::MapPoint*>& points) {
  return static_cast<size_t>(std::count_if(
      points.begin(), points.end(), [](const ORB_SLAM2::MapPoint* p) { return p != nullptr; }));
}

void WritePose(std::ostream& out, const cv::Mat& Twc) {
  out << std::setprecision(9);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) out << Twc.at<float>(r, c) << ((r == 2 && c == 3) ? '\n' : ' ');
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 5) {
    std::cerr << "usage: orbslam2_stereo_kitti VOCABULARY SETTINGS SEQUENCE_DIR OUT_POSES\n"
                 "  SEQUENCE_DIR: KITTI odometry layout (image_0/, image_1/, times.txt)\n"
                 "  writes OUT_POSES (one KITTI pose line per frame), OUT_POSES.timing.csv,\n"
                 "  OUT_POSES.final.txt; ORBSLAM2_LOOP_CLOSING=1 enables loop closing\n";
    return 2;
  }
  const std::string vocabulary = argv[1], settings = argv[2], sequence = argv[3],
                    out_path = argv[4];
  for (const std::string& f : {vocabulary, settings}) {
    if (!FileReadable(f)) {
      std::cerr << "orbslam2_stereo_kitti: cannot read " << f << "\n";
      return 1;
    }
  }
  std::vector<std::string> left_files, right_files;
  std::vector<double> times;
  if (!LoadSequence(sequence, &left_files, &right_files, &times)) return 1;

  std::ofstream poses(out_path);
  std::ofstream timing(out_path + ".timing.csv");
  if (!poses || !timing) {
    std::cerr << "orbslam2_stereo_kitti: cannot write " << out_path << "[.timing.csv]\n";
    return 1;
  }
  timing << "frame,time_s,decode_ms,track_ms,state,pose_valid,map_id,tracked_map_points\n";

  const char* lc_env = std::getenv("ORBSLAM2_LOOP_CLOSING");
  const bool loop_closing = lc_env != nullptr && std::string(lc_env) == "1";
  const auto t_load = Clock::now();
  ORB_SLAM2::System slam(vocabulary, settings, ORB_SLAM2::System::STEREO, /*bUseViewer=*/false,
                         /*bUseLoopClosing=*/loop_closing);
  const double load_ms = MsSince(t_load);
  std::cerr << "orbslam2_stereo_kitti: " << times.size() << " frames, loop closing "
            << (loop_closing ? "ON" : "off") << ", system ready in " << load_ms << " ms\n";

  // Pose bookkeeping. ORB-SLAM2 returns Tcw in the frame of its current map. After a reset
  // (tracking lost while the map has <= 5 keyframes) it starts a new map whose origin is the
  // camera at re-initialisation (Tcw exactly identity); the runner chains that map to the last
  // pose it wrote (anchor), so the file stays in the first map's frame. Lost frames repeat
  // the last pose written, with pose_valid = 0.
  cv::Mat anchor = cv::Mat::eye(4, 4, CV_32F);  // first-map-from-current-map
  cv::Mat last_written = cv::Mat::eye(4, 4, CV_32F);
  bool ever_tracked = false;
  int map_id = 0;
  std::vector<double> track_ms_all;
  size_t n_valid = 0;
  const auto t_run = Clock::now();
  for (size_t i = 0; i < times.size(); ++i) {
    const auto t_dec = Clock::now();
    cv::Mat im_left = cv::imread(left_files[i], cv::IMREAD_UNCHANGED);
    cv::Mat im_right = cv::imread(right_files[i], cv::IMREAD_UNCHANGED);
    const double decode_ms = MsSince(t_dec);
    if (im_left.empty() || im_right.empty()) {
      std::cerr << "orbslam2_stereo_kitti: cannot load "
                << (im_left.empty() ? left_files[i] : right_files[i]) << "\n";
      slam.Shutdown();
      return 1;
    }
    const auto t_track = Clock::now();
    cv::Mat Tcw = slam.TrackStereo(im_left, im_right, times[i]);
    const double track_ms = MsSince(t_track);
    track_ms_all.push_back(track_ms);
    const int state = slam.GetTrackingState();
    const bool valid = !Tcw.empty() && state == 2;
    if (valid) {
      if (ever_tracked && cv::countNonZero(Tcw != cv::Mat::eye(4, 4, CV_32F)) == 0) {
        anchor = last_written.clone();  // new map after a reset
        ++map_id;
      }
      last_written = anchor * Tcw.inv();
      ever_tracked = true;
      ++n_valid;
    }
    WritePose(poses, last_written);
    poses.flush();
    timing << i << ',' << std::setprecision(9) << times[i] << ',' << std::setprecision(6)
           << decode_ms << ',' << track_ms << ',' << StateName(state) << ',' << (valid ? 1 : 0)
           << ',' << map_id << ',' << (valid ? CountTracked(slam.GetTrackedMapPoints()) : 0)
           << '\n';
    timing.flush();
    if (!poses || !timing) {
      std::cerr << "orbslam2_stereo_kitti: write error on " << out_path << "\n";
      slam.Shutdown();
      return 1;
    }
  }
  const double run_s = MsSince(t_run) / 1000.0;
  slam.Shutdown();
  slam.SaveTrajectoryKITTI(out_path + ".final.txt");

  std::vector<double> sorted = track_ms_all;
  std::sort(sorted.begin(), sorted.end());
  const size_t n = sorted.size();
  const double median = n % 2 ? sorted[n / 2] : 0.5 * (sorted[n / 2 - 1] + sorted[n / 2]);
  std::cerr << "orbslam2_stereo_kitti: " << times.size() << " frames in " << run_s << " s ("
            << times.size() / run_s << " fps, vocabulary/system load " << load_ms / 1000.0
            << " s not included), median TrackStereo " << median << " ms, frames without a pose "
            << times.size() - n_valid << ", map resets " << map_id << "\n";
  return ever_tracked ? 0 : 3;
}
