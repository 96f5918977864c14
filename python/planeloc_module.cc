// `import planeloc`: the localizer, the plane map, evo-identical ATE and the simulator from Python
// (docs/python.md). Thin bindings over the installed library's public headers; the maths stays in
// C++. Arrays are numpy (float64 poses and planes, uint8 images); the GIL is released while
// frames are tracked. planeloc::InputError and OptionsError become ValueError with the CLI's
// message (file, line, fix).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <Eigen/Geometry>
#include <cstring>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "planeloc/eval/alignment.h"
#include "planeloc/eval/ape.h"
#include "planeloc/io/kitti_sequence.h"
#include "planeloc/io/plane_map.h"
#include "planeloc/io/trajectory.h"
#include "planeloc/localizer/localizer.h"
#include "planeloc/sim/simulator.h"
#include "planeloc/util/error.h"

namespace py = pybind11;

namespace planeloc::python {
namespace {

using Matrix4 = Eigen::Matrix4d;

py::array_t<double> PoseArray(const Rigid3d& pose) {
  const Matrix4 m = pose.Matrix4d();
  py::array_t<double> array({4, 4});
  auto out = array.mutable_unchecked<2>();
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) out(r, c) = m(r, c);
  }
  return array;
}

// A 4x4 (or 3x4) float array as a rigid pose; `name` names the argument in errors.
Rigid3d PoseFromArray(const py::array& value, const std::string& name) {
  const auto array = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(value);
  if (!array || array.ndim() != 2 || (array.shape(0) != 4 && array.shape(0) != 3) ||
      array.shape(1) != 4) {
    throw py::value_error(name + ": expected a 4x4 (or 3x4) float array, world_from_cam");
  }
  const auto in = array.unchecked<2>();
  Eigen::Matrix3d rotation;
  Eigen::Vector3d translation;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) rotation(r, c) = in(r, c);
    translation[r] = in(r, 3);
  }
  if (!rotation.allFinite() || !translation.allFinite() ||
      (rotation.transpose() * rotation - Eigen::Matrix3d::Identity()).norm() > 1e-6 ||
      rotation.determinant() < 0) {
    throw py::value_error(name + ": the rotation block is not a finite proper rotation");
  }
  return Rigid3d(Eigen::Quaterniond(rotation).normalized(), translation);
}

// An (N, 4, 4) or (N, 12) float array (KITTI rows) as poses.
PoseMatrices PosesFromArray(const py::array& value, const std::string& name) {
  const auto array = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(value);
  const bool stacked = array && array.ndim() == 3 && array.shape(1) == 4 && array.shape(2) == 4;
  const bool rows = array && array.ndim() == 2 && array.shape(1) == 12;
  if (!stacked && !rows) {
    throw py::value_error(name + ": expected an (N, 4, 4) or (N, 12) float array of poses");
  }
  PoseMatrices poses(static_cast<std::size_t>(array.shape(0)), Matrix4::Identity());
  const double* data = array.data();
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const double* p = data + i * (stacked ? 16 : 12);
    for (int r = 0; r < (stacked ? 4 : 3); ++r) {
      for (int c = 0; c < 4; ++c) poses[i](r, c) = p[r * 4 + c];
    }
  }
  return poses;
}

// A grey (H, W) or BGR (H, W, 3) uint8 image as a cv::Mat sharing the array's memory.
cv::Mat ImageFromArray(const py::array& value, const std::string& name) {
  const auto array = py::array_t<std::uint8_t, py::array::c_style>::ensure(value);
  if (!array || !(array.ndim() == 2 || (array.ndim() == 3 && array.shape(2) == 3)) ||
      !py::isinstance<py::array_t<std::uint8_t>>(value)) {
    throw py::value_error(name + ": expected a uint8 array of shape (H, W) or (H, W, 3)");
  }
  const int type = array.ndim() == 2 ? CV_8UC1 : CV_8UC3;
  return cv::Mat(static_cast<int>(array.shape(0)), static_cast<int>(array.shape(1)), type,
                 const_cast<std::uint8_t*>(array.data()));
}

py::array_t<std::uint8_t> ImageArray(const cv::Mat& image) {
  const cv::Mat grey = image.isContinuous() ? image : image.clone();
  py::array_t<std::uint8_t> array({grey.rows, grey.cols});
  std::memcpy(array.mutable_data(), grey.data, static_cast<std::size_t>(grey.total()));
  return array;
}

py::array_t<double> VectorArray(const Eigen::Vector3d& v) {
  py::array_t<double> array(3);
  auto out = array.mutable_unchecked<1>();
  for (int i = 0; i < 3; ++i) out(i) = v[i];
  return array;
}

py::dict PlaneDict(const MapPlane& plane) {
  py::array_t<double> polygon({static_cast<py::ssize_t>(plane.polygon.size()), py::ssize_t{3}});
  auto out = polygon.mutable_unchecked<2>();
  for (std::size_t i = 0; i < plane.polygon.size(); ++i) {
    for (int k = 0; k < 3; ++k) out(static_cast<py::ssize_t>(i), k) = plane.polygon[i][k];
  }
  py::dict dict;
  dict["id"] = plane.id;
  dict["kind"] = plane.kind;
  dict["normal"] = VectorArray(plane.plane_in_map.normal);
  dict["d"] = plane.plane_in_map.d;
  dict["centroid"] = VectorArray(plane.centroid);
  dict["inliers"] = plane.inliers;
  dict["rms"] = plane.rms;
  dict["area"] = plane.area;
  dict["polygon"] = polygon;
  dict["sigma_offset"] = plane.sigma.offset;
  dict["sigma_normal"] = py::make_tuple(plane.sigma.normal.x(), plane.sigma.normal.y());
  return dict;
}

// The plane map as Python sees it: the C++ map (handed to a Localizer) with numpy views.
struct PyPlaneMap {
  PlaneMap map;
};

py::dict FrameDict(const LocalizedFrame& frame) {
  py::dict dict;
  dict["frame"] = frame.frame;
  dict["timestamp"] = frame.timestamp;
  dict["pose"] = PoseArray(frame.world_from_cam);
  dict["state"] = std::string(TrackingStateName(frame.state));
  dict["map_lock"] = frame.map_lock;
  dict["keyframe"] = frame.keyframe;
  dict["tracked_points"] = frame.tracked_points;
  dict["localized"] = frame.Localized();
  return dict;
}

void RegisterErrors(py::module_& module) {
  // The CLI's message: "file:line: what (fix: ...)".
  py::register_exception_translator([](std::exception_ptr error) {
    try {
      if (error) std::rethrow_exception(error);
    } catch (const InputError& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    } catch (const OptionsError& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    }
  });
  (void)module;
}

void DefineCore(py::module_& m) {
  py::class_<StereoCamera>(m, "StereoCamera",
                           "A rectified stereo camera: pixels, baseline in metres")
      .def(py::init([](double fx, double fy, double cx, double cy, double baseline, int width,
                       int height) {
             if (!(fx > 0 && fy > 0 && baseline > 0 && width > 0 && height > 0)) {
               throw py::value_error(
                   "StereoCamera: fx, fy, baseline, width and height must be positive");
             }
             StereoCamera camera;
             camera.fx = fx;
             camera.fy = fy;
             camera.cx = cx;
             camera.cy = cy;
             camera.baseline = baseline;
             camera.width = width;
             camera.height = height;
             return camera;
           }),
           py::arg("fx"), py::arg("fy"), py::arg("cx"), py::arg("cy"), py::arg("baseline"),
           py::arg("width"), py::arg("height"))
      .def_readonly("fx", &StereoCamera::fx)
      .def_readonly("fy", &StereoCamera::fy)
      .def_readonly("cx", &StereoCamera::cx)
      .def_readonly("cy", &StereoCamera::cy)
      .def_readonly("baseline", &StereoCamera::baseline)
      .def_readonly("width", &StereoCamera::width)
      .def_readonly("height", &StereoCamera::height)
      .def("__repr__", [](const StereoCamera& c) {
        return "StereoCamera(fx=" + std::to_string(c.fx) +
               ", baseline=" + std::to_string(c.baseline) + ", " + std::to_string(c.width) + "x" +
               std::to_string(c.height) + ")";
      });

  py::class_<PyPlaneMap>(m, "PlaneMap", "A plane map (planes.json)")
      .def_property_readonly("planes",
                             [](const PyPlaneMap& self) {
                               py::list planes;
                               for (const MapPlane& plane : self.map.planes) {
                                 planes.append(PlaneDict(plane));
                               }
                               return planes;
                             })
      .def_property_readonly(
          "ids",
          [](const PyPlaneMap& self) {
            py::array_t<int> ids(static_cast<py::ssize_t>(self.map.planes.size()));
            for (std::size_t i = 0; i < self.map.planes.size(); ++i) {
              ids.mutable_at(static_cast<py::ssize_t>(i)) = self.map.planes[i].id;
            }
            return ids;
          })
      .def_property_readonly(
          "normals",
          [](const PyPlaneMap& self) {
            py::array_t<double> normals(
                {static_cast<py::ssize_t>(self.map.planes.size()), py::ssize_t{3}});
            auto out = normals.mutable_unchecked<2>();
            for (std::size_t i = 0; i < self.map.planes.size(); ++i) {
              for (int k = 0; k < 3; ++k) {
                out(static_cast<py::ssize_t>(i), k) = self.map.planes[i].plane_in_map.normal[k];
              }
            }
            return normals;
          })
      .def_property_readonly(
          "offsets",
          [](const PyPlaneMap& self) {
            py::array_t<double> d(static_cast<py::ssize_t>(self.map.planes.size()));
            for (std::size_t i = 0; i < self.map.planes.size(); ++i) {
              d.mutable_at(static_cast<py::ssize_t>(i)) = self.map.planes[i].plane_in_map.d;
            }
            return d;
          })
      .def_property_readonly("frame", [](const PyPlaneMap& self) { return self.map.frame.name; })
      .def("__len__", [](const PyPlaneMap& self) { return self.map.planes.size(); });

  m.def(
      "read_plane_map",
      [](const std::filesystem::path& path) { return PyPlaneMap{OpenPlaneMap(path)}; },
      py::arg("path"),
      "Reads planes.json (`planeloc map planes`) or a simulator's planes_gt.json. normals (N, 3) "
      "and offsets (N,) give n . x + d = 0 per plane; planes lists each plane as a dict.");

  py::class_<Localizer>(m, "Localizer",
                        "Localizes rectified stereo frames in a plane map (visual odometry "
                        "without one). Poses are world_from_cam, 4x4, in the map's frame.")
      .def(py::init([](const StereoCamera& camera, const std::optional<PyPlaneMap>& plane_map,
                       const std::optional<py::array>& initial_pose,
                       const std::optional<std::tuple<double, double, double>>& init_sigma,
                       const std::optional<std::filesystem::path>& settings, bool deterministic) {
             LocalizerOptions options;
             if (settings) options.tracker = ReadTrackerOptions(*settings);
             if (initial_pose) {
               options.world_from_cam_initial = PoseFromArray(*initial_pose, "initial_pose");
             }
             if (init_sigma) {
               options.start_prior = StartPrior{std::get<0>(*init_sigma), std::get<1>(*init_sigma),
                                                std::get<2>(*init_sigma)};
             }
             options.deterministic = deterministic;
             std::optional<PlaneMap> map;
             if (plane_map) map = plane_map->map;
             return std::make_unique<Localizer>(camera, options, std::move(map));
           }),
           py::arg("camera"), py::arg("plane_map") = std::nullopt,
           py::arg("initial_pose") = std::nullopt, py::arg("init_sigma") = std::nullopt,
           py::arg("settings") = std::nullopt, py::arg("deterministic") = false,
           "init_sigma: (metres horizontal, metres vertical, degrees of heading) of the initial "
           "pose in the map, as `planeloc run --init-sigma`; None: exact. settings: a settings "
           "YAML (docs/tracking.md). deterministic: bit-identical to `planeloc run "
           "--deterministic`.")
      .def(
          "track",
          [](Localizer& self, const py::array& left, const py::array& right, double timestamp) {
            const cv::Mat left_image = ImageFromArray(left, "left");
            const cv::Mat right_image = ImageFromArray(right, "right");
            LocalizedFrame frame;
            {
              py::gil_scoped_release release;
              frame = self.Track(left_image, right_image, timestamp);
            }
            return FrameDict(frame);
          },
          py::arg("left"), py::arg("right"), py::arg("timestamp"),
          "Tracks one rectified pair (uint8, (H, W) grey or (H, W, 3) BGR, the camera's size). "
          "Returns a dict: frame, timestamp, pose (4x4), state, map_lock, keyframe, "
          "tracked_points, localized.")
      .def(
          "skip",
          [](Localizer& self, double timestamp) {
            py::gil_scoped_release release;
            const LocalizedFrame frame = self.Skip(timestamp);
            py::gil_scoped_acquire acquire;
            return FrameDict(frame);
          },
          py::arg("timestamp"), "A frame without images: the motion model's pose.")
      .def(
          "finish",
          [](Localizer& self) {
            py::gil_scoped_release release;
            self.Finish();
          },
          "Waits for the running local BA; call after the last frame.")
      .def_property_readonly("frames", &Localizer::frames);

  py::class_<KittiSequence>(m, "KittiSequence",
                            "A KITTI-layout stereo sequence (odometry or raw): calibration, "
                            "timestamps, rectified grey pairs")
      .def(
          py::init([](const std::filesystem::path& folder) { return KittiSequence::Open(folder); }),
          py::arg("folder"))
      .def("__len__", &KittiSequence::size)
      .def_property_readonly("camera", &KittiSequence::camera)
      .def("timestamp", &KittiSequence::timestamp, py::arg("index"))
      .def(
          "stereo_pair",
          [](const KittiSequence& self, std::size_t index) {
            if (index >= self.size()) throw py::index_error("frame index out of range");
            const StereoPair pair = self.LoadStereoPair(index);
            return py::make_tuple(ImageArray(pair.left), ImageArray(pair.right));
          },
          py::arg("index"), "The rectified grey pair of frame `index`: (left, right) uint8 arrays");

  m.def(
      "read_poses",
      [](const std::filesystem::path& path) {
        // The rows as written (what `planeloc eval` and evo evaluate), not re-orthonormalized.
        const std::vector<Eigen::Matrix<double, 3, 4>> rows = ReadKittiPoseMatrices(path);
        py::array_t<double> poses(
            {static_cast<py::ssize_t>(rows.size()), py::ssize_t{4}, py::ssize_t{4}});
        auto out = poses.mutable_unchecked<3>();
        for (std::size_t i = 0; i < rows.size(); ++i) {
          for (int r = 0; r < 4; ++r) {
            for (int c = 0; c < 4; ++c) {
              out(static_cast<py::ssize_t>(i), r, c) = r < 3 ? rows[i](r, c) : (c == 3 ? 1.0 : 0.0);
            }
          }
        }
        return poses;
      },
      py::arg("path"), "A KITTI pose file as an (N, 4, 4) array");
}

void DefineEval(py::module_& m) {
  py::module_ eval = m.def_submodule("eval", "Trajectory evaluation, as `planeloc eval` (= evo)");
  eval.def(
      "ate",
      [](const py::array& gt, const py::array& est, const std::string& align) {
        ApeOptions options;
        options.alignment = ParseAlignmentType(align);
        const ApeResult result =
            ComputeApe(PosesFromArray(gt, "gt"), PosesFromArray(est, "est"), options);
        py::dict stats;
        stats["rmse"] = result.stats.rmse;
        stats["mean"] = result.stats.mean;
        stats["median"] = result.stats.median;
        stats["std"] = result.stats.std;
        stats["min"] = result.stats.min;
        stats["max"] = result.stats.max;
        stats["sse"] = result.stats.sse;
        stats["scale"] = result.alignment.scale;
        py::array_t<double> errors(static_cast<py::ssize_t>(result.errors.size()));
        for (std::size_t i = 0; i < result.errors.size(); ++i) {
          errors.mutable_at(static_cast<py::ssize_t>(i)) = result.errors[i];
        }
        stats["errors"] = errors;
        return stats;
      },
      py::arg("gt"), py::arg("est"), py::arg("align") = "none",
      "Absolute trajectory error of the translation (evo_ape -r trans_part) of poses paired by "
      "index; gt and est are (N, 4, 4) or (N, 12) arrays; align: none | se3 | sim3. Returns "
      "rmse, mean, median, std, min, max, sse, scale and the per-pose errors.");
}

void DefineSim(py::module_& m) {
  py::module_ sim_module = m.def_submodule("sim", "The deterministic simulator (planeloc sim)");
  sim_module.def(
      "generate",
      [](const std::filesystem::path& out, const std::string& preset, std::uint32_t seed,
         std::optional<int> frames) {
        sim::SimOptions options = sim::SimOptions::FromPreset(preset);
        options.seed = seed;
        options.frames = frames;
        options.show_progress = false;
        options.Check();
        sim::SimResult result;
        {
          py::gil_scoped_release release;
          result = sim::GenerateSequence(options, out, /*force=*/true);
        }
        py::dict dict;
        dict["sequence"] = result.sequence_dir;
        dict["poses"] = result.poses_path;
        dict["planes"] = result.planes_path;
        dict["frames"] = result.frames;
        return dict;
      },
      py::arg("out"), py::arg("preset") = "tiny", py::arg("seed") = 1,
      py::arg("frames") = std::nullopt,
      "Writes a synthetic sequence into `out` (replacing it): a street preset (tiny, small, "
      "kitti07-like) in the KITTI layout, `room` in the ASL/EuRoC layout (docs/sim.md). Returns "
      "the paths of the sequence, its GT poses and its GT planes, and the frame count.");
}

}  // namespace
}  // namespace planeloc::python

PYBIND11_MODULE(planeloc, m) {
  m.doc() =
      "planeloc: stereo localization in a LiDAR plane map (docs/python.md). read_plane_map, "
      "Localizer, KittiSequence, read_poses; eval.ate; sim.generate.";
  planeloc::python::RegisterErrors(m);
  planeloc::python::DefineCore(m);
  planeloc::python::DefineEval(m);
  planeloc::python::DefineSim(m);
}
