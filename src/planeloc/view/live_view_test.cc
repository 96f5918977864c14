#include "planeloc/view/live_view.h"

#include <gtest/gtest.h>
#include <httplib.h>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "planeloc/pipeline/run_sequence.h"
#include "planeloc/util/error.h"
#include "planeloc/view/frame_drawing.h"

namespace planeloc::view {
namespace {

using nlohmann::json;

StereoCamera TestCamera() {
  StereoCamera camera;
  camera.fx = camera.fy = 700;
  camera.cx = 320;
  camera.cy = 120;
  camera.baseline = 0.5;
  camera.width = 640;
  camera.height = 240;
  return camera;
}

// One facade 10 m ahead of a camera at the origin looking along +z: x in [-4, 4], y in [-3, 1].
PlaneMap TestMap() {
  PlaneMap map;
  MapPlane plane;
  plane.id = 7;
  plane.kind = "facade";
  plane.plane_in_map = Plane(Eigen::Vector3d(0, 0, -1), 10);
  plane.polygon = {{-4, -3, 10}, {4, -3, 10}, {4, 1, 10}, {-4, 1, 10}};
  map.planes.push_back(plane);
  return map;
}

FrameStats Stats(int frame) {
  FrameStats stats;
  stats.frame = frame;
  stats.map_lock = frame < 3 ? "searching" : "locked";
  stats.features = 1000 + frame;
  stats.tracked_points = 300;
  stats.ms_extract = 10;
  stats.ms_track = 5;
  return stats;
}

Rigid3d PoseAt(int frame) {
  Rigid3d pose = Rigid3d::Identity();
  pose.translation = Eigen::Vector3d(0, 0, frame);
  return pose;
}

TrackedFrameView FrameView(int frame) {
  TrackedFrameView view;
  view.frame = frame;
  view.left = cv::Mat(240, 640, CV_8UC1, cv::Scalar(200));
  view.tracked = {{320, 120}, {100, 200}};
  view.tracked_plane = {7, -1};
  return view;
}

// The next Server-Sent Event of `path` on the view, as JSON (keep-alive comments skipped).
std::vector<json> ReadEvents(int port, std::size_t count) {
  httplib::Client client("127.0.0.1", port);
  client.set_read_timeout(10, 0);
  std::vector<json> events;
  std::string buffer;
  client.Get("/events", [&](const char* data, std::size_t size) {
    buffer.append(data, size);
    std::size_t end;
    while ((end = buffer.find("\n\n")) != std::string::npos) {
      const std::string block = buffer.substr(0, end);
      buffer.erase(0, end + 2);
      if (block.rfind("data: ", 0) == 0) events.push_back(json::parse(block.substr(6)));
    }
    return events.size() < count;  // false: stop reading (the client disconnects)
  });
  return events;
}

TEST(LiveViewTest, ServesThePageTheRunSoFarAndTheImage) {
  std::shared_ptr<LiveView> live = LiveView::Start(LiveViewOptions{});
  ASSERT_GT(live->port(), 0);
  EXPECT_EQ(live->url(), "http://127.0.0.1:" + std::to_string(live->port()) + "/");
  const PlaneMap map = TestMap();
  live->OnStart(TestCamera(), 10, &map);
  for (int frame = 0; frame < 5; ++frame) live->OnFrame(Stats(frame), PoseAt(frame));
  ASSERT_TRUE(live->WantsFrameView());  // the first view is always wanted
  live->OnFrameView(FrameView(4));
  // Immediately after a view, the next is not wanted (at most max_rate per second).
  EXPECT_FALSE(live->WantsFrameView());

  // The first event holds every pose so far and the image's number.
  std::vector<json> events = ReadEvents(live->port(), 1);
  ASSERT_EQ(events.size(), 1u);
  const json& first = events[0];
  EXPECT_EQ(first["from"], 0);
  ASSERT_EQ(first["poses"].size(), 5u);
  EXPECT_DOUBLE_EQ(first["poses"][4][2].get<double>(), 4.0);  // z of frame 4
  EXPECT_EQ(first["poses"][0][3], 1);                         // searching
  EXPECT_EQ(first["poses"][4][3], 3);                         // locked
  EXPECT_EQ(first["frame"], 4);
  EXPECT_EQ(first["lock"], "locked");
  EXPECT_EQ(first["lock_changes"], json::parse(R"([[0, "searching"], [3, "locked"]])"));

  httplib::Client client("127.0.0.1", live->port());
  client.set_read_timeout(10, 0);
  // The image is drawn on the view's thread: wait for the event that announces it.
  for (int attempt = 0; attempt < 20 && events.back()["image"] == 0; ++attempt) {
    live->OnFrame(Stats(5 + attempt), PoseAt(5 + attempt));
    events = ReadEvents(live->port(), 1);
  }
  ASSERT_GE(events.back()["image"].get<int>(), 1);
  EXPECT_EQ(events.back()["image_frame"], 4);
  const httplib::Result image = client.Get("/frame.jpg");
  ASSERT_TRUE(image);
  EXPECT_EQ(image->status, 200);
  EXPECT_EQ(image->get_header_value("Content-Type"), "image/jpeg");
  const std::vector<uchar> bytes(image->body.begin(), image->body.end());
  const cv::Mat decoded = cv::imdecode(bytes, cv::IMREAD_COLOR);
  EXPECT_EQ(decoded.cols, 640);
  EXPECT_EQ(decoded.rows, 240);

  const httplib::Result page = client.Get("/");
  ASSERT_TRUE(page);
  EXPECT_EQ(page->status, 200);
  EXPECT_NE(page->body.find("id=\"live-data\""), std::string::npos);
  EXPECT_NE(page->body.find("function addPlanes("), std::string::npos);  // the report's code
  const std::size_t data = page->body.find("id=\"live-data\">");
  const json inlined =
      json::parse(page->body.substr(data + 15, page->body.find("</script>", data) - data - 15));
  ASSERT_EQ(inlined["planes"].size(), 1u);
  EXPECT_EQ(inlined["planes"][0]["id"], 7);
  EXPECT_EQ(inlined["planes"][0]["polygon"].size(), 4u);

  // Only its own page and data.
  const httplib::Result other = client.Get("/etc/passwd");
  ASSERT_TRUE(other);
  EXPECT_EQ(other->status, 404);
  live->Stop();
  EXPECT_FALSE(client.Get("/"));  // stopped with the run
}

TEST(LiveViewTest, LaterEventsCarryOnlyTheNewPoses) {
  std::shared_ptr<LiveView> live = LiveView::Start(LiveViewOptions{});
  live->OnStart(TestCamera(), 100, nullptr);
  for (int frame = 0; frame < 3; ++frame) live->OnFrame(Stats(frame), PoseAt(frame));
  httplib::Client client("127.0.0.1", live->port());
  client.set_read_timeout(10, 0);
  std::vector<json> events;
  std::string buffer;
  int frame = 3;
  client.Get("/events", [&](const char* data, std::size_t size) {
    buffer.append(data, size);
    std::size_t end;
    while ((end = buffer.find("\n\n")) != std::string::npos) {
      const std::string block = buffer.substr(0, end);
      buffer.erase(0, end + 2);
      if (block.rfind("data: ", 0) != 0) continue;
      events.push_back(json::parse(block.substr(6)));
      // Two more frames after each event.
      live->OnFrame(Stats(frame), PoseAt(frame));
      live->OnFrame(Stats(frame + 1), PoseAt(frame + 1));
      frame += 2;
    }
    return events.size() < 3;
  });
  ASSERT_EQ(events.size(), 3u);
  EXPECT_EQ(events[0]["poses"].size(), 3u);
  EXPECT_EQ(events[1]["from"], 3);
  EXPECT_EQ(events[1]["poses"].size(), 2u);
  EXPECT_DOUBLE_EQ(events[1]["poses"][1][2].get<double>(), 4.0);
  EXPECT_EQ(events[2]["from"], 5);
  // A browser that went away (the client above) changes nothing: the run goes on and a new one
  // gets everything from the start.
  live->OnFrame(Stats(frame), PoseAt(frame));
  const std::vector<json> again = ReadEvents(live->port(), 1);
  ASSERT_EQ(again.size(), 1u);
  EXPECT_EQ(again[0]["poses"].size(), static_cast<std::size_t>(frame + 1));
  EXPECT_EQ(again[0]["lock"], "locked");
}

TEST(LiveViewTest, ErrorColouringUsesTheGroundTruth) {
  LiveViewOptions options;
  options.gt_positions = {{0, 0, 0}, {0, 0, 1.5}};
  std::shared_ptr<LiveView> live = LiveView::Start(options);
  live->OnStart(TestCamera(), 3, nullptr);
  for (int frame = 0; frame < 3; ++frame) live->OnFrame(Stats(frame), PoseAt(frame));
  const std::vector<json> events = ReadEvents(live->port(), 1);
  ASSERT_EQ(events.size(), 1u);
  EXPECT_DOUBLE_EQ(events[0]["poses"][0][4].get<double>(), 0.0);
  EXPECT_DOUBLE_EQ(events[0]["poses"][1][4].get<double>(), 0.5);  // |1 - 1.5|
  EXPECT_TRUE(events[0]["poses"][2][4].is_null());                // no GT for frame 2
}

TEST(LiveViewTest, PlaneUpdatesAreSentAtTheirOwnRate) {
  std::shared_ptr<LiveView> live = LiveView::Start(LiveViewOptions{});
  const PlaneMap map = TestMap();
  live->OnStart(TestCamera(), 10, &map);
  live->OnFrame(Stats(0), PoseAt(0));
  ASSERT_TRUE(live->WantsPlaneUpdates());
  TrackedFrameView view = FrameView(0);
  PlaneUpdate corrected;
  corrected.id = 7;
  corrected.status = PlaneUpdateStatus::kCorrected;
  PlaneUpdate unseen;
  unseen.id = 8;
  view.plane_updates = {corrected, unseen};
  live->OnFrameView(view);
  // A fit per plane on the tracking thread: not asked for again within the second.
  EXPECT_FALSE(live->WantsPlaneUpdates());
  const std::vector<json> events = ReadEvents(live->port(), 1);
  ASSERT_EQ(events.size(), 1u);
  // Unseen planes are left out.
  EXPECT_EQ(events[0]["plane_states"], json::parse(R"({"7": "corrected"})"));
}

TEST(LiveViewTest, ATakenPortIsAnInputErrorNamingIt) {
  std::shared_ptr<LiveView> first = LiveView::Start(LiveViewOptions{});
  LiveViewOptions options;
  options.port = first->port();
  try {
    LiveView::Start(options);
    FAIL() << "a second server bound the same port";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("127.0.0.1:" + std::to_string(first->port())),
              std::string::npos)
        << e.what();
  }
}

TEST(LiveViewTest, MissingThreeJsIsAnInputErrorNamingTheFile) {
  LiveViewOptions options;
  options.three_js_dir = "/nonexistent/three";
  try {
    LiveView::Start(options);
    FAIL() << "started without three.js";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/three/three.min.js"), std::string::npos);
  }
}

TEST(FrameDrawingTest, DrawsPlaneOutlinesAndFeaturesInThePlanesColour) {
  const PlaneMap map = TestMap();
  const StereoCamera camera = TestCamera();
  const cv::Mat image = DrawTrackedFrame(FrameView(0), camera, Rigid3d::Identity(), &map);
  ASSERT_EQ(image.type(), CV_8UC3);
  const cv::Scalar color = PlaneColorBgr(7);
  const auto near_color = [&](cv::Point p, const cv::Scalar& want) {
    const cv::Vec3b c = image.at<cv::Vec3b>(p);
    return std::abs(c[0] - want[0]) < 40 && std::abs(c[1] - want[1]) < 40 &&
           std::abs(c[2] - want[2]) < 40;
  };
  // The polygon's left edge x = -4 at z = 10 projects to u = 320 - 280 = 40, rows 120 - 210 ..
  // 120 + 70.
  EXPECT_TRUE(near_color({40, 150}, color));
  // The feature on plane 7 at (320, 120) is a filled dot in its colour; the darkened background
  // (200 * 0.55 = 110) elsewhere.
  EXPECT_TRUE(near_color({320, 120}, color));
  EXPECT_TRUE(near_color({500, 60}, cv::Scalar(110, 110, 110)));
  // Seen from behind the plane's far side (camera at z = 20 looking along +z) nothing of it
  // is drawn: the background stays flat where the outline was.
  Rigid3d behind = Rigid3d::Identity();
  behind.translation = Eigen::Vector3d(0, 0, 20);
  TrackedFrameView view = FrameView(0);
  view.tracked.clear();
  view.tracked_plane.clear();
  const cv::Mat from_behind = DrawTrackedFrame(view, camera, behind, &map);
  cv::Mat grey;
  cv::cvtColor(from_behind, grey, cv::COLOR_BGR2GRAY);
  double low = 0, high = 0;
  cv::minMaxLoc(grey, &low, &high);
  EXPECT_EQ(low, high);
}

TEST(FrameDrawingTest, DisabledPlanesAreRed) {
  const PlaneMap map = TestMap();
  TrackedFrameView view = FrameView(0);
  view.disabled_planes = {7};
  const cv::Mat image = DrawTrackedFrame(view, TestCamera(), Rigid3d::Identity(), &map);
  const cv::Vec3b c = image.at<cv::Vec3b>(150, 40);
  EXPECT_GT(c[2], 150);  // red
  EXPECT_LT(c[1], 110);
}

}  // namespace
}  // namespace planeloc::view
