// The keyframe decision of ORB-SLAM2's stereo tracker (Tracking::NeedNewKeyFrame), as a pure
// function of what the tracker measured at the frame:
//   c1a = frames since the last keyframe >= max_frames (Camera.fps)
//   c1b = frames since the last keyframe >= min_frames and local mapping idle
//   c1c = inliers < 0.25 x reference matches, or need_close (tracking weak)
//   c2  = (inliers < tracked_ratio x reference matches, or need_close) and inliers > 15
//   insert = (c1a or c1b or c1c) and c2
// "Local mapping idle" is the BA worker's state: no local BA running, queued or waiting to be
// applied. In deterministic mode mapping is synchronous, hence always idle, and c2 decides (as it
// would in ORB-SLAM2 with a synchronous local mapper); with the BA worker, a frame that only
// satisfies c2 waits until the worker is idle, unless max_frames frames have passed or tracking
// is weak.
#pragma once

namespace planeloc {

struct KeyframeRuleInput {
  int frames_since_keyframe = 0;  // frame id minus the last keyframe's frame id
  bool mapping_idle = true;       // no local BA running, queued or waiting to be applied
  int inliers = 0;                // inliers of the frame's final pose optimization
  int reference_matches = 0;      // reference keyframe's points seen by >= 2 or 3 keyframes
  bool need_close = false;        // few tracked close points while many close ones are unmatched
  double rotation_since_keyframe_deg = 0.0;  // the view's rotation since the last keyframe
};

struct KeyframeRuleOptions {
  int min_frames = 0;           // ORB-SLAM2 mMinFrames (0)
  int max_frames = 10;          // ORB-SLAM2 mMaxFrames = Camera.fps
  double tracked_ratio = 0.75;  // ORB-SLAM2 thRefRatio for stereo
  // > 0: a keyframe once the view has turned this far (a drone's or hand-held camera's fast turns,
  // where ORB-SLAM2's ratio waits until a third of the points have left the view); 0: off.
  double max_rotation_deg = 0.0;
};

struct KeyframeDecision {
  bool c1a = false, c1b = false, c1c = false, c2 = false;
  bool turned = false;  // max_rotation_deg reached (with enough inliers)
  bool insert = false;
};

KeyframeDecision DecideKeyframe(const KeyframeRuleInput& input, const KeyframeRuleOptions& options);

}  // namespace planeloc
