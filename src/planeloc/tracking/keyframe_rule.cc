#include "planeloc/tracking/keyframe_rule.h"

namespace planeloc {

KeyframeDecision DecideKeyframe(const KeyframeRuleInput& input,
                                const KeyframeRuleOptions& options) {
  KeyframeDecision d;
  d.c1a = input.frames_since_keyframe >= options.max_frames;
  d.c1b = input.frames_since_keyframe >= options.min_frames && input.mapping_idle;
  d.c1c = input.inliers < 0.25 * input.reference_matches || input.need_close;
  d.c2 = (input.inliers < options.tracked_ratio * input.reference_matches || input.need_close) &&
         input.inliers > 15;
  d.turned = options.max_rotation_deg > 0 &&
             input.rotation_since_keyframe_deg >= options.max_rotation_deg && input.inliers > 15;
  d.insert = ((d.c1a || d.c1b || d.c1c) && d.c2) || d.turned;
  return d;
}

}  // namespace planeloc
