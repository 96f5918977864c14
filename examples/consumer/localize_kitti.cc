// Localizes the first frames of a KITTI-layout stereo sequence in a plane map through planeloc's
// public API, and writes one KITTI pose per frame.
//   localize_kitti SEQUENCE_DIR PLANES_JSON FRAMES OUT_TRAJECTORY
#include <planeloc/io/kitti_sequence.h>
#include <planeloc/io/trajectory.h>
#include <planeloc/localizer/localizer.h>
#include <planeloc/util/error.h>

#include <algorithm>
#include <cstdio>
#include <string>

int main(int argc, char** argv) {
  if (argc != 5) {
    std::fprintf(stderr, "usage: %s SEQUENCE_DIR PLANES_JSON FRAMES OUT_TRAJECTORY\n", argv[0]);
    return 2;
  }
  try {
    const planeloc::KittiSequence sequence = planeloc::KittiSequence::Open(argv[1]);
    planeloc::LocalizerOptions options;
    options.deterministic = true;  // exact start (the default prior), local BA in line
    planeloc::Localizer localizer(sequence.camera(), options, planeloc::OpenPlaneMap(argv[2]));
    const int frames = std::min<int>(std::stoi(argv[3]), static_cast<int>(sequence.size()));
    planeloc::TrajectoryWriter writer(argv[4], planeloc::TrajectoryFormat::kKitti);
    int localized = 0;
    for (int i = 0; i < frames; ++i) {
      const planeloc::StereoPair pair = sequence.LoadStereoPair(i);
      const planeloc::LocalizedFrame frame =
          localizer.Track(pair.left, pair.right, sequence.timestamp(i));
      writer.Write(frame.timestamp, frame.world_from_cam);
      localized += frame.Localized() ? 1 : 0;
      std::printf("frame %d: %s, map lock %s, %d tracked points, position %.3f %.3f %.3f\n",
                  frame.frame, planeloc::TrackingStateName(frame.state), frame.map_lock.c_str(),
                  frame.tracked_points, frame.world_from_cam.translation.x(),
                  frame.world_from_cam.translation.y(), frame.world_from_cam.translation.z());
    }
    localizer.Finish();
    writer.Close();
    std::printf("%d of %d frames localized\n", localized, frames);
    return localized == frames ? 0 : 1;
  } catch (const planeloc::InputError& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  }
}
