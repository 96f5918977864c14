// The ORB-SLAM2 keyframe rule, case by case (expectations worked out by hand from
// Tracking::NeedNewKeyFrame: c1a = max frames passed, c1b = min frames passed and mapping idle,
// c1c = weak tracking, c2 = tracked-inlier ratio).
#include "planeloc/tracking/keyframe_rule.h"

#include <gtest/gtest.h>

namespace planeloc {
namespace {

// A frame that tracks 100 inliers against a reference keyframe with 200 tracked points: below
// 0.75 x 200 = 150 (c2 holds) but not below 0.25 x 200 = 50 (tracking not weak).
KeyframeRuleInput Moderate(int frames_since_keyframe, bool mapping_idle) {
  KeyframeRuleInput input;
  input.frames_since_keyframe = frames_since_keyframe;
  input.mapping_idle = mapping_idle;
  input.inliers = 100;
  input.reference_matches = 200;
  return input;
}

// The defect of issue 10: c1 was `timeout || true || weak`, so a busy local mapper never held a
// keyframe back and Camera.fps never mattered. With the BA worker busy, 3 frames after the last
// keyframe, a frame that only satisfies c2 must wait.
TEST(KeyframeRule, BusyMappingHoldsBackAFrameThatOnlyMeetsTheRatio) {
  const KeyframeDecision d = DecideKeyframe(Moderate(3, /*mapping_idle=*/false), {});
  EXPECT_TRUE(d.c2);
  EXPECT_FALSE(d.c1a);
  EXPECT_FALSE(d.c1b);
  EXPECT_FALSE(d.c1c);
  EXPECT_FALSE(d.insert);
}

TEST(KeyframeRule, MaxFramesInsertsEvenWhenMappingIsBusy) {
  KeyframeRuleOptions options;
  options.max_frames = 10;  // Camera.fps
  EXPECT_FALSE(DecideKeyframe(Moderate(9, false), options).insert);
  const KeyframeDecision d = DecideKeyframe(Moderate(10, false), options);
  EXPECT_TRUE(d.c1a);
  EXPECT_TRUE(d.insert);
  options.max_frames = 5;  // a 5 Hz sequence
  EXPECT_TRUE(DecideKeyframe(Moderate(5, false), options).insert);
}

TEST(KeyframeRule, IdleMappingInsertsAfterMinFrames) {
  EXPECT_TRUE(DecideKeyframe(Moderate(1, /*mapping_idle=*/true), {}).c1b);  // min_frames 0
  EXPECT_TRUE(DecideKeyframe(Moderate(1, true), {}).insert);
  KeyframeRuleOptions options;
  options.min_frames = 2;
  EXPECT_FALSE(DecideKeyframe(Moderate(1, true), options).insert);
  EXPECT_TRUE(DecideKeyframe(Moderate(2, true), options).insert);
}

TEST(KeyframeRule, WeakTrackingInsertsWhenMappingIsBusy) {
  KeyframeRuleInput input = Moderate(2, /*mapping_idle=*/false);
  input.inliers = 40;  // < 0.25 x 200
  const KeyframeDecision d = DecideKeyframe(input, {});
  EXPECT_TRUE(d.c1c);
  EXPECT_TRUE(d.insert);
  input.inliers = 100;
  input.need_close = true;  // too few close points tracked
  EXPECT_TRUE(DecideKeyframe(input, {}).insert);
}

TEST(KeyframeRule, NoKeyframeWithoutTheRatioCondition) {
  KeyframeRuleInput input = Moderate(20, /*mapping_idle=*/true);
  input.inliers = 160;  // >= 0.75 x 200: the reference keyframe still covers the view
  const KeyframeDecision d = DecideKeyframe(input, {});
  EXPECT_TRUE(d.c1a && d.c1b);
  EXPECT_FALSE(d.c2);
  EXPECT_FALSE(d.insert);
  input.inliers = 15;  // weak, but too few inliers to make a keyframe from (> 15 required)
  EXPECT_TRUE(DecideKeyframe(input, {}).c1c);
  EXPECT_FALSE(DecideKeyframe(input, {}).insert);
}

// A camera that turns keeps most of its points in view for a while (the ratio holds) but sees its
// keyframe's points at ever larger angles: with max_rotation_deg a keyframe comes when it has
// turned that far, even while mapping is busy.
TEST(KeyframeRule, ATurnBeyondMaxRotationInserts) {
  KeyframeRuleInput input = Moderate(2, /*mapping_idle=*/false);
  input.inliers = 190;  // the ratio alone would not insert
  input.rotation_since_keyframe_deg = 9.0;
  KeyframeRuleOptions options;
  EXPECT_FALSE(DecideKeyframe(input, options).insert);  // off by default
  options.max_rotation_deg = 10.0;
  EXPECT_FALSE(DecideKeyframe(input, options).insert);
  input.rotation_since_keyframe_deg = 10.0;
  EXPECT_TRUE(DecideKeyframe(input, options).turned);
  EXPECT_TRUE(DecideKeyframe(input, options).insert);
  input.inliers = 15;  // never from a frame tracked this weakly
  EXPECT_FALSE(DecideKeyframe(input, options).insert);
}

}  // namespace
}  // namespace planeloc
