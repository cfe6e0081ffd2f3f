// registration.projective against the tests' own long-double geometry
// (reference_geometry.h), on synthetic scenes whose depth is computed analytically. The
// colour image encodes its own pixel coordinates (B = u mod 256, G = v mod 256,
// R = u / 256 + 16 * (v / 256)), so the registered colour says which colour pixel the
// stage sampled.
//
// Tolerances:
// - kMappingPx = 0.01 px between the stage's mapping and the reference. The stage maps
//   in float32: colour coordinates below 2048 px are spaced 1.2e-4 px and the mapping
//   rounds about ten times, so it stays within about 2e-3 px.
// - Sampled pixels are compared exactly, except where the reference lies within
//   kMappingPx of a rounding tie (x.5) or of the image edge, where either answer is
//   right to within the mapping's accuracy.
#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <optional>
#include <span>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>

#include "calibration_file.h"
#include "color_window/region_window.h"
#include "depth_to_color.h"
#include "projective.h"
#include "reference_geometry.h"
#include "roi/region_of_interest.h"
#include "row_kernels.h"
#include "source_tree.h"
#include "tilth/error.h"
#include "tilth/frame.h"
#include "tilth/log.h"
#include "tilth/messages/color_image.h"
#include "tilth/messages/depth_image.h"
#include "tilth/messages/registered_color.h"

namespace tilth::registration {
namespace {

namespace fs = std::filesystem;
namespace ref = reference;
using nlohmann::json;
using ref::Real;

constexpr double kMappingPx = 0.01;
constexpr double kPi = 3.14159265358979323846;

const fs::path kPaperRig = testing::paper_rig_path();

using testing::CalibrationFile;

// R = Rz(z) Ry(y) Rx(x), angles in degrees.
json rotation(double x_deg, double y_deg, double z_deg) {
  const cv::Matx33d rx(1, 0, 0, 0, std::cos(x_deg * kPi / 180), -std::sin(x_deg * kPi / 180), 0,
                       std::sin(x_deg * kPi / 180), std::cos(x_deg * kPi / 180));
  const cv::Matx33d ry(std::cos(y_deg * kPi / 180), 0, std::sin(y_deg * kPi / 180), 0, 1, 0,
                       -std::sin(y_deg * kPi / 180), 0, std::cos(y_deg * kPi / 180));
  const cv::Matx33d rz(std::cos(z_deg * kPi / 180), -std::sin(z_deg * kPi / 180), 0,
                       std::sin(z_deg * kPi / 180), std::cos(z_deg * kPi / 180), 0, 0, 0, 1);
  const cv::Matx33d r = rz * ry * rx;
  return {{r(0, 0), r(0, 1), r(0, 2)}, {r(1, 0), r(1, 1), r(1, 2)}, {r(2, 0), r(2, 1), r(2, 2)}};
}

// The paper's rig with the colour camera turned about every axis and moved diagonally:
// a box on a plane then hides plane in rows and columns other than its own.
json rotated_diagonal_rig() {
  json document = testing::paper_rig_document();
  document["depth_to_color"]["R"] = rotation(3, -4, 2);
  document["depth_to_color"]["T_mm"] = {30.0, -35.0, 0.0};
  return document;
}

std::unique_ptr<Transform> make_registration(const fs::path& calibration,
                                             const std::string& interpolation = "nearest",
                                             double occlusion_tolerance_mm = 10.0,
                                             const std::string& instruction_set = "auto",
                                             const json& roi = nullptr) {
  const StageContext context{"registration",
                             Params(json{{"calibration", calibration.string()},
                                         {"occlusion_tolerance_mm", occlusion_tolerance_mm},
                                         {"interpolation", interpolation},
                                         {"instruction_set", instruction_set},
                                         {"roi", roi}}),
                             Logger("registration"),
                             {}};
  std::unique_ptr<Stage> stage = describe_projective().create(context);
  auto* transform = dynamic_cast<Transform*>(stage.get());
  if (transform == nullptr) throw std::logic_error("registration.projective is not a transform");
  stage.release();
  return std::unique_ptr<Transform>(transform);
}

std::shared_ptr<const RegisteredColor> register_color(
    Transform& stage, const cv::Mat& depth_mm, const cv::Mat& pixels,
    PixelFormat format = PixelFormat::kBgr8, std::shared_ptr<const RigCalibration> rig = nullptr,
    std::optional<cv::Point> sensor_offset = std::nullopt) {
  DepthImage depth;
  depth.mm = depth_mm;
  depth.rig = std::move(rig);
  ColorImage color;
  color.pixels = pixels;
  color.format = format;
  color.sensor_offset = sensor_offset;
  const std::vector<Packet> inputs = {
      Packet(FrameInfo{}, std::make_shared<const DepthImage>(std::move(depth))),
      Packet(FrameInfo{}, std::make_shared<const ColorImage>(std::move(color)))};
  std::vector<Packet> outputs(1);
  Frame frame(FrameInfo{}, inputs, outputs);
  stage.process(frame);
  return outputs[0].share<RegisteredColor>();
}

cv::Mat coordinate_image(int width = 1280, int height = 1024) {
  cv::Mat image(height, width, CV_8UC3);
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      image.at<cv::Vec3b>(v, u) =
          cv::Vec3b(static_cast<std::uint8_t>(u % 256), static_cast<std::uint8_t>(v % 256),
                    static_cast<std::uint8_t>(u / 256 + 16 * (v / 256)));
    }
  }
  return image;
}

cv::Point decode(const cv::Vec3b& bgr) {
  return {(bgr[2] % 16) * 256 + bgr[0], (bgr[2] / 16) * 256 + bgr[1]};
}

std::vector<ref::Vec3> depth_rays(const ref::Rig& rig) {
  std::vector<ref::Vec3> rays;
  for (int v = 0; v < rig.depth.height; ++v) {
    for (int u = 0; u < rig.depth.width; ++u) rays.push_back(ref::depth_ray(rig, u, v));
  }
  return rays;
}

// The depth image (mm from the mounting surface) of the plane through the optical-axis
// point at distance_mm whose normal is `normal` (ToF frame).
cv::Mat plane_depth(const ref::Rig& rig, const std::vector<ref::Vec3>& rays, Real distance_mm,
                    ref::Vec3 normal) {
  const ref::Vec3 on_plane{0, 0, distance_mm + rig.z_offset};
  cv::Mat depth(rig.depth.height, rig.depth.width, CV_32FC1);
  for (int v = 0; v < depth.rows; ++v) {
    for (int u = 0; u < depth.cols; ++u) {
      const ref::Vec3 ray = rays[static_cast<std::size_t>(v * depth.cols + u)];
      depth.at<float>(v, u) =
          static_cast<float>(ref::dot(normal, on_plane) / ref::dot(normal, ray) - rig.z_offset);
    }
  }
  return depth;
}

bool near_half(Real x) { return std::abs(x - std::floor(x) - 0.5L) < kMappingPx; }

bool near_edge(const ref::ColorPixel& p, const ref::Rig& rig) {
  return std::min({std::abs(p.u + 0.5L), std::abs(p.u - (rig.color.width - 0.5L)),
                   std::abs(p.v + 0.5L), std::abs(p.v - (rig.color.height - 0.5L))}) < kMappingPx;
}

struct Agreement {
  int in_image = 0;  // pixels the reference sees inside the colour image
  int compared = 0;  // of those, sampled pixels compared (not at a rounding tie)
  int status_mismatches = 0;
  int sample_mismatches = 0;
  int colour_on_flagged = 0;  // flagged pixels that are not black
  double max_mapping_error_px = 0.0;
};

int coloured_flagged(const RegisteredColor& out) {
  cv::Mat coloured;
  cv::transform(out.bgr, coloured, cv::Matx13f(1, 1, 1));  // b + g + r, saturated
  return cv::countNonZero((out.status != RegisteredColor::kValid) & (coloured > 0));
}

// The stage's mapping of one row of depth pixels.
struct MappedRow {
  std::vector<float> u, v, depth;

  MappedRow(const DepthToColor& map, int row, const float* z_mm)
      : u(static_cast<std::size_t>(map.row_capacity())), v(u.size()), depth(u.size()) {
    map.project_row(row, z_mm, u.data(), v.data(), depth.data());
  }
};

// Compares a registration of a scene without occlusion, nearest sampling of
// coordinate_image(), with the reference.
Agreement compare(const json& document, const fs::path& file, const cv::Mat& depth,
                  const std::vector<ref::Vec3>& rays, const RegisteredColor& out,
                  const std::string& instruction_set = "auto") {
  const ref::Rig rig = ref::rig_from(document);
  const DepthToColor map(load_calibration(file), file.string(), row_kernels(instruction_set));
  const Real right = rig.color.width - 0.5L;
  const Real bottom = rig.color.height - 0.5L;
  Agreement a;
  for (int v = 0; v < depth.rows; ++v) {
    const MappedRow mapped(map, v, depth.ptr<float>(v));
    for (int u = 0; u < depth.cols; ++u) {
      const float z = depth.at<float>(v, u);
      const auto status = out.status.at<std::uint8_t>(v, u);
      const cv::Vec3b bgr = out.bgr.at<cv::Vec3b>(v, u);
      if (status != RegisteredColor::kValid && bgr != cv::Vec3b(0, 0, 0)) ++a.colour_on_flagged;
      if (std::isnan(z)) {
        a.status_mismatches += status == RegisteredColor::kNoDepth ? 0 : 1;
        continue;
      }
      const int pixel = v * depth.cols + u;
      const ref::ColorPixel expected = ref::project(rig, rays[static_cast<std::size_t>(pixel)], z);
      const bool inside = expected.depth > 0 && expected.u >= -0.5L && expected.u < right &&
                          expected.v >= -0.5L && expected.v < bottom;
      const bool at_edge = near_edge(expected, rig);
      if (inside) {
        ++a.in_image;
        a.max_mapping_error_px = std::max(
            a.max_mapping_error_px,
            static_cast<double>(std::hypot(mapped.u[u] - expected.u, mapped.v[u] - expected.v)));
      }
      if (at_edge) continue;
      const auto expected_status =
          inside ? RegisteredColor::kValid : RegisteredColor::kOutsideColor;
      a.status_mismatches += status == expected_status ? 0 : 1;
      if (inside && status == RegisteredColor::kValid && !near_half(expected.u) &&
          !near_half(expected.v)) {
        ++a.compared;
        const cv::Point sampled = decode(bgr);
        const cv::Point nearest(static_cast<int>(std::floor(expected.u + 0.5L)),
                                static_cast<int>(std::floor(expected.v + 0.5L)));
        a.sample_mismatches += sampled == nearest ? 0 : 1;
      }
    }
  }
  return a;
}

void expect_agreement(const Agreement& a, int min_in_image) {
  EXPECT_LT(a.max_mapping_error_px, kMappingPx);
  EXPECT_EQ(a.status_mismatches, 0);
  EXPECT_EQ(a.sample_mismatches, 0);
  EXPECT_EQ(a.colour_on_flagged, 0);
  EXPECT_GE(a.in_image, min_in_image);
  // Ties exclude about 2 * 2 * 0.01 of the pixels.
  EXPECT_GT(a.compared, a.in_image * 9 / 10);
}

ref::Vec3 tilted_normal() { return {0.18L, -0.36L, 1.0L}; }  // 10 and 20 degrees

// Every instruction-set level this CPU runs (row_kernels.h) is held to the reference.
std::vector<std::string> levels() {
  std::vector<std::string> names;
  for (const RowKernels* kernels : available_row_kernels()) names.emplace_back(kernels->level);
  return names;
}

// A tilted plane at 518 mm seen by the rig of `document` (in the file `calibration`),
// registered at every level the CPU runs and held to the reference; returns each level's
// output for further checks.
std::vector<std::shared_ptr<const RegisteredColor>> expect_every_level_matches_the_reference(
    const json& document, const fs::path& calibration, const cv::Mat& color, int min_in_image,
    const std::string& what) {
  const ref::Rig rig = ref::rig_from(document);
  const auto rays = depth_rays(rig);
  const cv::Mat depth = plane_depth(rig, rays, 518, tilted_normal());
  std::vector<std::shared_ptr<const RegisteredColor>> outputs;
  for (const std::string& level : levels()) {
    SCOPED_TRACE(level);
    outputs.push_back(
        register_color(*make_registration(calibration, "nearest", 10.0, level), depth, color));
    const Agreement a = compare(document, calibration, depth, rays, *outputs.back(), level);
    expect_agreement(a, min_in_image);
    std::cout << what << ", " << level << ": max mapping error " << a.max_mapping_error_px
              << " px over " << a.in_image << " pixels\n";
  }
  return outputs;
}

TEST(ProjectiveRegistration, TiltedPlaneMatchesTheReferenceProjection) {
  // The colour camera sees most of the ToF image: all but a band on the side away from
  // the baseline.
  expect_every_level_matches_the_reference(testing::paper_rig_document(), kPaperRig,
                                           coordinate_image(), 250000, "paper rig, tilted plane");
}

TEST(ProjectiveRegistration, RotatedRigWithLensDistortionMatchesTheReferenceProjection) {
  json document = testing::paper_rig_document();
  document["depth_to_color"]["R"] = rotation(4, -6, 2);
  document["depth_to_color"]["T_mm"] = {45.0, -8.0, 5.0};
  document["depth_camera"]["distortion"] = {-0.12, 0.03, 0.0008, -0.0005, 0.0};
  document["color_camera"]["distortion"] = {-0.2, 0.08, -0.001, 0.0006, -0.01};
  const CalibrationFile file(document);
  expect_every_level_matches_the_reference(document, file.path(), coordinate_image(), 200000,
                                           "rotated rig with distortion");
}

TEST(ProjectiveRegistration, ImagesOfNoWholeVectorsMatchTheReferenceToTheirLastPixel) {
  // A depth row of 613 pixels ends in a partial vector at every level, and a colour image
  // of 1279 x 1021 pixels has odd rows and ends on a byte that no whole word after it
  // covers: the last partial vector and the last colour pixels are read and written
  // exactly, and nothing beyond them is. With the colour camera on the left, the ToF
  // image's right edge is in its view.
  json document = testing::paper_rig_document();
  document["depth_to_color"]["T_mm"] = {-45.0, 0.0, 0.0};
  document["depth_camera"]["width"] = 613;
  document["color_camera"]["width"] = 1279;
  document["color_camera"]["height"] = 1021;
  const CalibrationFile file(document);
  for (const auto& out : expect_every_level_matches_the_reference(
           document, file.path(), coordinate_image(1279, 1021), 230000, "613 x 480 px")) {
    // The last column is seen and sampled like the others.
    EXPECT_GT(cv::countNonZero(out->status.col(612) == RegisteredColor::kValid), 400);
  }
}

TEST(ProjectiveRegistration, AnInstructionSetTheCpuDoesNotRunIsRefused) {
  std::string runnable;
  for (const std::string& level : levels()) runnable += (runnable.empty() ? "" : ", ") + level;
  try {
    make_registration(kPaperRig, "nearest", 10.0, "x86-64-v9");
    ADD_FAILURE() << "x86-64-v9 was accepted";
  } catch (const Error& error) {
    EXPECT_EQ(std::string(error.what()),
              "this CPU does not run instruction set x86-64-v9; it runs " + runnable);
  }
}

TEST(ProjectiveRegistration, PixelsOutsideTheColourImageAreFlaggedAndBlack) {
  json document = testing::paper_rig_document();
  document["color_camera"]["fx"] = 1800.0;  // a narrower colour view than the ToF's
  document["color_camera"]["fy"] = 1800.0;
  const CalibrationFile file(document);
  const ref::Rig rig = ref::rig_from(document);
  const auto rays = depth_rays(rig);
  cv::Mat depth = plane_depth(rig, rays, 518, tilted_normal());
  depth(cv::Rect(300, 200, 10, 10)).setTo(std::numeric_limits<float>::quiet_NaN());
  const auto out = register_color(*make_registration(file.path()), depth, coordinate_image());
  const Agreement a = compare(document, file.path(), depth, rays, *out);
  expect_agreement(a, 60000);
  EXPECT_GT(cv::countNonZero(out->status == RegisteredColor::kOutsideColor), 100000);
  EXPECT_EQ(cv::countNonZero(out->status == RegisteredColor::kNoDepth), 100);
}

// Without a file named, the stage registers with the calibration the depth image carries:
// a rig turned and moved registers exactly as with its file named.
TEST(ProjectiveRegistration, TheDepthsCarriedCalibrationIsUsed) {
  json document = testing::paper_rig_document();
  document["depth_to_color"]["T_mm"] = {-38.0, 12.0, 6.0};
  const CalibrationFile file(document);
  const ref::Rig rig = ref::rig_from(document);
  const cv::Mat depth = plane_depth(rig, depth_rays(rig), 518, tilted_normal());
  const auto named = register_color(*make_registration(file.path()), depth, coordinate_image());
  const auto carried =
      register_color(*make_registration(""), depth, coordinate_image(), PixelFormat::kBgr8,
                     std::make_shared<const RigCalibration>(load_calibration(file.path())));
  EXPECT_EQ(cv::norm(named->bgr, carried->bgr, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(named->status, carried->status, cv::NORM_INF), 0.0);
  const auto paper = register_color(*make_registration(kPaperRig), depth, coordinate_image());
  EXPECT_GT(cv::norm(paper->bgr, carried->bgr, cv::NORM_INF), 0.0);  // the rig matters
}

TEST(ProjectiveRegistration, PointsBeyondTheDistortionsFoldAreOutsideNotFoldedIn) {
  // Barrel distortion r (1 + k1 r^2) turns back at r^2 = -1 / (3 k1); with the colour
  // camera turned 35 degrees, ToF pixels up to 67 degrees off its axis exist, and the
  // polynomial maps some of them back into the image.
  json document = testing::paper_rig_document();
  const Real k1 = -0.15L;
  document["color_camera"]["distortion"] = {static_cast<double>(k1), 0, 0, 0, 0};
  document["depth_to_color"]["R"] = rotation(0, 35, 0);
  const CalibrationFile file(document);
  const ref::Rig rig = ref::rig_from(document);
  const auto rays = depth_rays(rig);
  const cv::Mat depth = plane_depth(rig, rays, 518, {0, 0, 1});
  const auto out = register_color(*make_registration(file.path()), depth, coordinate_image());
  const Real fold_radius2 = -1 / (3 * k1);
  int beyond_fold = 0;
  int folded_into_image = 0;
  int beyond_fold_not_outside = 0;
  int within_checked = 0;
  int within_mismatches = 0;
  for (int v = 0; v < depth.rows; ++v) {
    for (int u = 0; u < depth.cols; ++u) {
      const auto status = out->status.at<std::uint8_t>(v, u);
      const auto p = ref::project(rig, rays[static_cast<std::size_t>(v * depth.cols + u)],
                                  depth.at<float>(v, u));
      const bool lands_inside = p.u >= -0.5L && p.u < rig.color.width - 0.5L && p.v >= -0.5L &&
                                p.v < rig.color.height - 0.5L;
      // 1 % margins around the fold: the stage finds it numerically.
      if (p.radius2 > fold_radius2 * 1.01L) {
        ++beyond_fold;
        folded_into_image += lands_inside ? 1 : 0;
        beyond_fold_not_outside += status == RegisteredColor::kOutsideColor ? 0 : 1;
      } else if (p.radius2 < fold_radius2 * 0.99L && !near_edge(p, rig)) {
        ++within_checked;
        const auto expected =
            lands_inside ? RegisteredColor::kValid : RegisteredColor::kOutsideColor;
        within_mismatches += status == expected ? 0 : 1;
      }
    }
  }
  EXPECT_GT(folded_into_image, 1000);  // the case exists in this scene
  EXPECT_GT(beyond_fold, folded_into_image);
  EXPECT_EQ(beyond_fold_not_outside, 0);
  EXPECT_GT(within_checked, 100000);
  EXPECT_EQ(within_mismatches, 0);
}

struct BoxOcclusion {
  int clearly_occluded = 0;  // by the geometry
  int missed = 0;            // of those, not flagged kOccluded
  int clearly_visible = 0;
  int flagged = 0;  // of those, not kValid
  int coloured_flagged = 0;
};

// A plane at 518 mm and a 150 mm tall box on it, 120 x 120 mm around the ToF's axis, as
// the ToF of `rig` sees it; `hidden_mm`: how far behind the first surface the colour
// camera meets on its way to each point. Wherever the colour camera's centre (-R^T T)
// lies to the side, it cannot see a strip of plane the ToF sees just beyond the box's
// far edge.
cv::Mat box_on_a_plane(const ref::Rig& rig, cv::Mat& hidden_mm) {
  const auto rays = depth_rays(rig);
  const Real plane = 518 + rig.z_offset;
  const ref::Vec3 box_low{-60, -60, plane - 150};
  const ref::Vec3 box_high{60, 60, plane};
  const ref::Vec3 origin{0, 0, 0};
  const ref::Vec3 colour_centre = ref::color_centre(rig);

  cv::Mat depth(rig.depth.height, rig.depth.width, CV_32FC1);
  hidden_mm.create(depth.size(), CV_32FC1);
  for (int v = 0; v < depth.rows; ++v) {
    for (int u = 0; u < depth.cols; ++u) {
      const ref::Vec3 ray = rays[static_cast<std::size_t>(v * depth.cols + u)];
      const auto box = ref::enter_box(origin, ray, box_low, box_high);
      const Real optical_centre_depth = box ? std::min(*box, plane) : plane;
      depth.at<float>(v, u) = static_cast<float>(optical_centre_depth - rig.z_offset);
      const ref::Vec3 point = optical_centre_depth * ray;
      const auto blocked = ref::enter_box(colour_centre, point - colour_centre, box_low, box_high);
      const Real behind = blocked ? (1 - *blocked) * ref::to_color(rig, point).z : 0;
      hidden_mm.at<float>(v, u) = static_cast<float>(std::max(behind, Real{0}));
    }
  }
  return depth;
}

// The box on the plane registered with the rig in `document`.
BoxOcclusion occlusion_by_a_box(const json& document) {
  const CalibrationFile file(document);
  cv::Mat hidden_mm;
  const cv::Mat depth = box_on_a_plane(ref::rig_from(document), hidden_mm);
  const auto out = register_color(*make_registration(file.path()), depth, coordinate_image());

  // Clearly occluded: hidden by more than the tolerance (10 mm) + 15 mm, as are all
  // neighbours within 2 pixels. Clearly visible: no neighbour within 3 pixels hidden and
  // no depth step over the tolerance there. The bands between are where a z-buffer cell
  // (3 colour pixels, 1.5 ToF pixels for these rigs) straddles the occlusion's edge.
  BoxOcclusion result;
  for (int v = 3; v < depth.rows - 3; ++v) {
    for (int u = 3; u < depth.cols - 3; ++u) {
      const auto status = out->status.at<std::uint8_t>(v, u);
      if (status == RegisteredColor::kOutsideColor) continue;
      double min_hidden = 1e9;
      double max_hidden = 0;
      double max_step = 0;
      for (int dv = -3; dv <= 3; ++dv) {
        for (int du = -3; du <= 3; ++du) {
          const float h = hidden_mm.at<float>(v + dv, u + du);
          if (std::abs(du) <= 2 && std::abs(dv) <= 2) min_hidden = std::min<double>(min_hidden, h);
          max_hidden = std::max<double>(max_hidden, h);
          max_step = std::max<double>(
              max_step, std::abs(depth.at<float>(v + dv, u + du) - depth.at<float>(v, u)));
        }
      }
      if (min_hidden > 10 + 15) {
        ++result.clearly_occluded;
        result.missed += status == RegisteredColor::kOccluded ? 0 : 1;
      } else if (max_hidden < 1e-3 && max_step < 10) {
        ++result.clearly_visible;
        result.flagged += status == RegisteredColor::kValid ? 0 : 1;
      }
    }
  }
  result.coloured_flagged = coloured_flagged(*out);
  std::cout << cv::countNonZero(out->status == RegisteredColor::kOccluded)
            << " pixels flagged occluded, " << result.clearly_occluded
            << " clearly occluded by the geometry\n";
  return result;
}

void expect_occlusion_found(const BoxOcclusion& box, int min_occluded) {
  EXPECT_GE(box.clearly_occluded, min_occluded);  // the scene has the case
  EXPECT_EQ(box.missed, 0);
  EXPECT_GT(box.clearly_visible, 200000);
  EXPECT_EQ(box.flagged, 0);
  EXPECT_EQ(box.coloured_flagged, 0);
}

// The expected strip widths: the colour ray over the box's top edge (x = 60, 392 mm from
// the ToF centre) meets the plane (541.97 mm) beyond where the ToF's own ray does.

TEST(ProjectiveRegistration, PlaneBehindABoxIsOccludedForThePaperRig) {
  // Colour camera 45 mm to -x: strip from 83 to 100 mm, 16 pixels by 113.
  expect_occlusion_found(occlusion_by_a_box(testing::paper_rig_document()), 1200);
}

TEST(ProjectiveRegistration, PlaneBehindABoxIsOccludedWithTheColourCameraOnTheOtherSide) {
  json document = testing::paper_rig_document();
  document["depth_to_color"]["T_mm"] = {-45.0, 0.0, 0.0};
  expect_occlusion_found(occlusion_by_a_box(document), 1200);
}

TEST(ProjectiveRegistration, PlaneBehindABoxIsOccludedForARotatedDiagonalRig) {
  // The box top's samples reach the colour image as a turned lattice; z-buffer cells one
  // depth pixel wide left holes in it here, and the plane behind them got the box's colour.
  const json document = rotated_diagonal_rig();
  expect_occlusion_found(occlusion_by_a_box(document), 1200);
}

TEST(ProjectiveRegistration, PlaneBehindABoxIsOccludedWithTheEpipoleInsideTheImage) {
  // Colour camera 150 mm behind and 60 mm to -x: its epipole lies inside the ToF image
  // (pixel 517, 240), so the parallax runs radially from there rather than along one
  // direction; strip from 83 to 93 mm.
  json document = testing::paper_rig_document();
  document["depth_to_color"]["T_mm"] = {60.0, 0.0, 150.0};
  expect_occlusion_found(occlusion_by_a_box(document), 500);
}

// A tilted plane with Gaussian depth noise of 5 mm (several times a ToF camera's in
// shade). Each z-buffer cell keeps the nearest of its noisy samples, and with the fixed
// 10 mm tolerance 13.3 % of the plane lay that far behind it: the samples the noise put
// farthest, so the soil that was left read nearer than it is. The tolerance follows the
// frame's noise (4 sigma, 20 mm here); the nearest of a cell's several samples is about
// 1.3 sigma near, and 0.5 % of the plane still lies 4 sigma behind it.
TEST(ProjectiveRegistration, NoisyDepthIsNotTakenForOcclusion) {
  const ref::Rig rig = ref::rig_from(testing::paper_rig_document());
  cv::Mat depth = plane_depth(rig, depth_rays(rig), 518, tilted_normal());
  cv::Mat noise(depth.size(), CV_32FC1);
  cv::RNG rng(3);
  rng.fill(noise, cv::RNG::NORMAL, 0.0, 5.0);
  depth += noise;
  const auto out = register_color(*make_registration(kPaperRig), depth, coordinate_image());
  const int occluded = cv::countNonZero(out->status == RegisteredColor::kOccluded);
  const int seen = cv::countNonZero(out->status == RegisteredColor::kValid) + occluded;
  EXPECT_GT(seen, 250000);
  EXPECT_LT(occluded, 0.01 * seen);
}

// The box's hidden strip lies about 150 mm behind its top: under 5 mm of noise, and the
// 20 mm tolerance that brings, it stays occluded. Not all of it: the noise moves each of
// the box top's samples by up to about 2 colour pixels (parallax), which leaves a few of
// the 3-pixel cells under its edge without one, and the plane behind such a hole is seen
// (docs/registration.md, "Occlusion"). 95.1 % of the strip is flagged, 95.7 % with the
// fixed 10 mm.
TEST(ProjectiveRegistration, PlaneBehindABoxStaysOccludedUnderNoise) {
  const json document = testing::paper_rig_document();
  const CalibrationFile file(document);
  cv::Mat hidden_mm;
  cv::Mat depth = box_on_a_plane(ref::rig_from(document), hidden_mm);
  cv::Mat noise(depth.size(), CV_32FC1);
  cv::RNG rng(4);
  rng.fill(noise, cv::RNG::NORMAL, 0.0, 5.0);
  depth += noise;
  const auto out = register_color(*make_registration(file.path()), depth, coordinate_image());
  cv::Mat deeply_hidden = hidden_mm > 100.0f;
  cv::erode(deeply_hidden, deeply_hidden, cv::Mat::ones(5, 5, CV_8UC1));  // not at its edge
  const int hidden = cv::countNonZero(deeply_hidden);
  EXPECT_GE(hidden, 1000);
  const int occluded =
      cv::countNonZero(deeply_hidden & (out->status == RegisteredColor::kOccluded));
  EXPECT_GE(occluded, 0.94 * hidden);
}

TEST(ProjectiveRegistration, ARegionIsRegisteredAsInTheWholeImage) {
  // The rotated diagonal rig: the box hides plane in rows other than its own, so a band
  // that holds hidden plane but not all of the box needs the z-buffer of every row.
  const json document = rotated_diagonal_rig();
  const CalibrationFile file(document);
  cv::Mat hidden_mm;
  const cv::Mat depth = box_on_a_plane(ref::rig_from(document), hidden_mm);
  for (const std::string interpolation : {"nearest", "bilinear"}) {
    SCOPED_TRACE(interpolation);
    const auto whole =
        register_color(*make_registration(file.path(), interpolation), depth, coordinate_image());
    int occluded_in_bands = 0;
    // Bands at every height; their columns from whole vectors (x 200) or not, and one
    // reaching the image's right edge.
    for (const auto [y, x, width] : {std::array{0, 200, 240},
                                     {100, 203, 237},
                                     {160, 17, 300},
                                     {220, 200, 240},
                                     {280, 500, 140},
                                     {340, 203, 237},
                                     {440, 200, 240}}) {
      const json roi = {{"x", x}, {"y", y}, {"width", width}, {"height", 40}};
      const auto part =
          register_color(*make_registration(file.path(), interpolation, 10.0, "auto", roi), depth,
                         coordinate_image());
      // kMarginPx around the region, clipped to the image; its columns rounded out to whole
      // vectors of 16.
      const int margin = RegionOfInterest::kMarginPx;
      const cv::Range rows(std::max(y - margin, 0), std::min(y + 40 + margin, depth.rows));
      const cv::Range columns((x - margin) / 16 * 16,
                              std::min((x + width + margin + 15) / 16 * 16, depth.cols));
      for (int v = 0; v < depth.rows; ++v) {
        for (int u = 0; u < depth.cols; ++u) {
          const bool inside =
              v >= rows.start && v < rows.end && u >= columns.start && u < columns.end;
          const auto status = part->status.at<std::uint8_t>(v, u);
          const auto bgr = part->bgr.at<cv::Vec3b>(v, u);
          if (inside) {
            ASSERT_EQ(status, whole->status.at<std::uint8_t>(v, u)) << "at " << u << ", " << v;
            ASSERT_EQ(bgr, whole->bgr.at<cv::Vec3b>(v, u)) << "at " << u << ", " << v;
          } else {
            ASSERT_EQ(status, RegisteredColor::kNotRegistered) << "at " << u << ", " << v;
            ASSERT_EQ(bgr, cv::Vec3b()) << "at " << u << ", " << v;
          }
        }
      }
      occluded_in_bands +=
          cv::countNonZero(part->status(rows, columns) == RegisteredColor::kOccluded);
    }
    EXPECT_GT(occluded_in_bands, 500);  // the bands hold the case
  }
}

std::string process_error(Transform& stage, const cv::Mat& depth, const cv::Mat& color,
                          PixelFormat format,
                          std::optional<cv::Point> sensor_offset = std::nullopt) {
  try {
    register_color(stage, depth, color, format, nullptr, sensor_offset);
  } catch (const Error& error) {
    return error.what();
  }
  return "registered";
}

// A colour camera reading out a window of its sensor: each depth pixel whose colour lies
// in the window gets the colour it gets from the whole image, the others are outside the
// colour image. The coordinate image keeps its sensor coordinates when cut, so a
// registered colour says which sensor pixel was sampled. Two differences are expected:
// - The window's mapping is the whole one's moved by a whole number of pixels, computed
//   again in float32, so a point within a float's rounding of a tie between two pixels
//   may round the other way: the two may differ by one pixel, at the few ties the scene
//   has.
// - The z-buffer's cells tile the window from its corner, so they lie otherwise than on
//   the whole image: on the box's silhouette, within a cell (3 px here) of an occluded
//   pixel, a point may compare with another nearest point and turn occluded or visible.
TEST(ProjectiveRegistration, AColourWindowGivesTheWholeImagesColoursWhereItReaches) {
  const json document = rotated_diagonal_rig();
  const CalibrationFile file(document);
  cv::Mat hidden_mm;
  const cv::Mat depth = box_on_a_plane(ref::rig_from(document), hidden_mm);
  const cv::Mat sensor = coordinate_image();
  const auto stage = make_registration(file.path());
  const auto whole = register_color(*stage, depth, sensor);
  const cv::Rect window(300, 250, 600, 480);
  const auto part = register_color(*stage, depth, sensor(window).clone(), PixelFormat::kBgr8,
                                   nullptr, window.tl());

  cv::Mat near_occlusion;
  cv::dilate(whole->status == RegisteredColor::kOccluded, near_occlusion,
             cv::Mat::ones(7, 7, CV_8U));
  const int occluded = cv::countNonZero(whole->status == RegisteredColor::kOccluded);
  int inside = 0;
  int outside = 0;
  int moved = 0;
  int turned = 0;
  for (int v = 0; v < depth.rows; ++v) {
    for (int u = 0; u < depth.cols; ++u) {
      const auto status = whole->status.at<std::uint8_t>(v, u);
      const auto part_status = part->status.at<std::uint8_t>(v, u);
      const bool occlusion_turned =
          (status == RegisteredColor::kOccluded && part_status == RegisteredColor::kValid) ||
          (status == RegisteredColor::kValid && part_status == RegisteredColor::kOccluded);
      if (occlusion_turned) {
        EXPECT_NE(near_occlusion.at<std::uint8_t>(v, u), 0) << "(" << u << ", " << v << ")";
        ++turned;
        continue;
      }
      if (status != RegisteredColor::kValid) {
        EXPECT_TRUE(part_status == status || part_status == RegisteredColor::kOutsideColor)
            << "(" << u << ", " << v << ")";
        continue;
      }
      const cv::Point sampled = decode(whole->bgr.at<cv::Vec3b>(v, u));
      if (part_status != RegisteredColor::kValid) {
        EXPECT_EQ(part_status, RegisteredColor::kOutsideColor) << "(" << u << ", " << v << ")";
        EXPECT_FALSE(cv::Rect(window.x + 1, window.y + 1, window.width - 2, window.height - 2)
                         .contains(sampled))
            << "(" << u << ", " << v << ")";
        ++outside;
        continue;
      }
      const cv::Point part_sampled = decode(part->bgr.at<cv::Vec3b>(v, u));
      EXPECT_TRUE(window.contains(part_sampled));
      EXPECT_LE(cv::norm(part_sampled - sampled), std::sqrt(2.0)) << "(" << u << ", " << v << ")";
      moved += part_sampled != sampled;
      ++inside;
    }
  }
  // The window shows about a quarter of what the depth pixels see (71 463 of 271 506).
  EXPECT_GT(inside, 60000);
  EXPECT_GT(outside, 180000);
  EXPECT_LT(moved, inside / 1000);
  EXPECT_GT(occluded, 500);           // the scene holds the case
  EXPECT_LT(turned, occluded / 100);  // 6 of 3 598

  EXPECT_EQ(process_error(*stage, depth, sensor(cv::Rect(0, 0, 640, 480)), PixelFormat::kBgr8,
                          cv::Point(700, 100)),
            "colour image window 640x480 px at (700, 100) is not inside the colour camera's "
            "1280x1024 px image in the calibration " +
                file.path().string());
}

// The window color_window_for gives for the chain's region and a range of ground
// distances holds every colour pixel the registration of that region reads: a plane
// anywhere in the range registers in the region exactly as with the whole image; nearer,
// the stage says the window is too small.
TEST(ProjectiveRegistration, TheWindowARegionNeedsRegistersItAsTheWholeImage) {
  const json document = testing::paper_rig_document();
  const CalibrationFile file(document);
  const ref::Rig rig = ref::rig_from(document);
  const auto rays = depth_rays(rig);
  const RegionOfInterest roi("middle_half", RegionOfInterest::Whole::kImage);
  const cv::Rect region = roi.around(cv::Size(640, 480), RegionOfInterest::kMarginPx);
  const cv::Rect window = color_window_for(load_calibration(file.path()), region, 400, 700, 16);
  const cv::Mat sensor = coordinate_image();
  const auto stage = make_registration(file.path(), "nearest", 10.0, "auto", "middle_half");
  for (const Real distance_mm : {400.0L, 550.0L, 700.0L}) {
    SCOPED_TRACE(std::to_string(static_cast<double>(distance_mm)) + " mm");
    const cv::Mat depth = plane_depth(rig, rays, distance_mm, {0, 0, 1});
    const auto whole = register_color(*stage, depth, sensor);
    const auto part = register_color(*stage, depth, sensor(window).clone(), PixelFormat::kBgr8,
                                     nullptr, window.tl());
    EXPECT_EQ(cv::countNonZero(whole->status(region) != RegisteredColor::kValid), 0);
    EXPECT_EQ(cv::countNonZero(part->status(region) != RegisteredColor::kValid), 0);
    EXPECT_EQ(cv::norm(whole->bgr(region), part->bgr(region), cv::NORM_INF), 0.0);
  }
  // Nearer than the range, the region's edge sees colour outside the window: said once.
  std::vector<std::string> warnings;
  const LogHandler previous =
      set_log_handler([&](LogLevel level, std::string_view, std::string_view text) {
        if (level == LogLevel::kWarning) warnings.emplace_back(text);
      });
  const cv::Rect measured = roi.on(cv::Size(640, 480));
  for (int repeat = 0; repeat < 2; ++repeat) {
    const auto too_near =
        register_color(*stage, plane_depth(rig, rays, 300, {0, 0, 1}), sensor(window).clone(),
                       PixelFormat::kBgr8, nullptr, window.tl());
    const int outside =
        cv::countNonZero(too_near->status(measured) == RegisteredColor::kOutsideColor);
    // The region's last column, u 479, is seen at colour u 1000 / 509.935 (479 - 313.05) +
    // 639.5 + 45000 / 323.97 = 1103.8, past the window's last pixel, 1103: its 240 pixels.
    EXPECT_EQ(outside, 240);
    if (repeat == 0) {
      ASSERT_EQ(warnings.size(), 1u);
      EXPECT_EQ(warnings[0], std::to_string(outside) +
                                 " of the region's 76800 px see colour outside the colour window "
                                 "736x512 px at (368, 256): is the ground nearer or farther than "
                                 "the window was chosen for? Widen it (tilth calibrate "
                                 "color-window); said once per window");
    }
  }
  set_log_handler(previous);
  EXPECT_EQ(warnings.size(), 1u);
}

// The 2x2 tile of each mosaic, row by row.
std::string_view tile(PixelFormat format) {
  switch (format) {
    case PixelFormat::kBayerRggb8:
      return "RGGB";
    case PixelFormat::kBayerBggr8:
      return "BGGR";
    case PixelFormat::kBayerGrbg8:
      return "GRBG";
    default:
      return "GBRG";
  }
}

cv::Mat mosaic(const cv::Mat& bgr, PixelFormat format) {
  cv::Mat out(bgr.size(), CV_8UC1);
  for (int y = 0; y < bgr.rows; ++y) {
    for (int x = 0; x < bgr.cols; ++x) {
      const char site = tile(format)[static_cast<std::size_t>((y % 2) * 2 + x % 2)];
      out.at<std::uint8_t>(y, x) = bgr.at<cv::Vec3b>(y, x)[site == 'B' ? 0 : site == 'G' ? 1 : 2];
    }
  }
  return out;
}

constexpr PixelFormat kBayerFormats[] = {PixelFormat::kBayerRggb8, PixelFormat::kBayerBggr8,
                                         PixelFormat::kBayerGrbg8, PixelFormat::kBayerGbrg8};

std::vector<std::pair<PixelFormat, std::string>> every_pattern_at_every_level() {
  std::vector<std::pair<PixelFormat, std::string>> cases;
  for (const PixelFormat format : kBayerFormats) {
    for (const std::string& level : levels()) cases.emplace_back(format, level);
  }
  return cases;
}

TEST(ProjectiveRegistration, EachBayerPatternGivesBackAKnownColour) {
  // Demosaicing a uniform mosaic gives its colour back exactly, and only with the right
  // pattern: one swapped diagonal turns (30, 120, 210) into (210, 120, 30), one pixel of
  // offset reads green as red and blue.
  const cv::Mat uniform(1024, 1280, CV_8UC3, cv::Scalar(30, 120, 210));
  const auto stage = make_registration(kPaperRig);
  const ref::Rig rig = ref::rig_from(testing::paper_rig_document());
  const cv::Mat depth = plane_depth(rig, depth_rays(rig), 518, tilted_normal());
  for (const PixelFormat format : kBayerFormats) {
    const auto out = register_color(*stage, depth, mosaic(uniform, format), format);
    const cv::Mat valid = out->status == RegisteredColor::kValid;
    EXPECT_GT(cv::countNonZero(valid), 250000) << to_string(format);
    cv::Mat as_expected;
    cv::inRange(out->bgr, cv::Scalar(30, 120, 210), cv::Scalar(30, 120, 210), as_expected);
    EXPECT_EQ(cv::countNonZero(valid & ~as_expected), 0) << to_string(format);
  }
}

TEST(ProjectiveRegistration, NearestSamplingOfAMosaicReadsTheQuadNearestThePoint) {
  // Every 2x2 quad of a mosaic holds one red, one blue and two greens, whichever pixel it
  // starts on: with the two green sites at 100 and 51, each registered pixel is (blue,
  // (100 + 51 + 1) / 2, red) exactly, for every pattern and every phase of the quad.
  const ref::Rig rig = ref::rig_from(testing::paper_rig_document());
  const cv::Mat depth = plane_depth(rig, depth_rays(rig), 518, tilted_normal());
  for (const auto& [format, level] : every_pattern_at_every_level()) {
    SCOPED_TRACE(level);
    const auto stage = make_registration(kPaperRig, "nearest", 10.0, level);
    cv::Mat mosaic_image(1024, 1280, CV_8UC1);
    for (int y = 0; y < mosaic_image.rows; ++y) {
      for (int x = 0; x < mosaic_image.cols; ++x) {
        const char site = tile(format)[static_cast<std::size_t>((y % 2) * 2 + x % 2)];
        mosaic_image.at<std::uint8_t>(y, x) = site == 'R'   ? 210
                                              : site == 'B' ? 30
                                              : y % 2       ? 51
                                                            : 100;
      }
    }
    const auto out = register_color(*stage, depth, mosaic_image, format);
    const cv::Mat valid = out->status == RegisteredColor::kValid;
    EXPECT_GT(cv::countNonZero(valid), 250000) << to_string(format);
    cv::Mat as_expected;
    cv::inRange(out->bgr, cv::Scalar(30, 76, 210), cv::Scalar(30, 76, 210), as_expected);
    EXPECT_EQ(cv::countNonZero(valid & ~as_expected), 0) << to_string(format);
  }
}

TEST(ProjectiveRegistration, BayerRgbAndMonoInputAgreeWithBgrForASmoothImage) {
  cv::Mat smooth(1024, 1280, CV_8UC3);
  for (int y = 0; y < smooth.rows; ++y) {
    for (int x = 0; x < smooth.cols; ++x) {
      smooth.at<cv::Vec3b>(y, x) = cv::Vec3b(
          cv::saturate_cast<std::uint8_t>(128 + 100 * std::sin(x / 60.0) * std::cos(y / 80.0)),
          cv::saturate_cast<std::uint8_t>(40 + 0.15 * x + 0.05 * y),
          cv::saturate_cast<std::uint8_t>(200 - 0.12 * y));
    }
  }
  const ref::Rig rig = ref::rig_from(testing::paper_rig_document());
  const cv::Mat depth = plane_depth(rig, depth_rays(rig), 518, tilted_normal());
  // Bilinear: demosaicing reproduces a linear ramp exactly; this image's curvature is at
  // most 100 / 60^2 = 0.03 levels per pixel^2, far below a level over the 1-pixel
  // neighbourhood, so what remains is the rounding of the image (0.5 level) and of the
  // neighbour averages (0.5 level) and of bilinear sampling (0.5 level): 2 levels.
  // Nearest: each channel comes from its site in the quad nearest the point, at most one
  // pixel from the bgr8 image's nearest pixel in x and in y; blue changes by at most
  // 100 / 60 + 100 / 80 = 2.9 levels over that, plus the rounding of the image and of
  // the greens' mean: 4 levels.
  const std::map<std::string, double> levels_off = {{"nearest", 4}, {"bilinear", 2}};
  for (const auto& [interpolation, max_levels] : levels_off) {
    const auto stage = make_registration(kPaperRig, interpolation);
    const auto bgr = register_color(*stage, depth, smooth);
    const cv::Mat valid = bgr->status == RegisteredColor::kValid;
    ASSERT_GT(cv::countNonZero(valid), 250000);
    for (const PixelFormat format : kBayerFormats) {
      const auto bayer = register_color(*stage, depth, mosaic(smooth, format), format);
      EXPECT_EQ(cv::countNonZero(bayer->status != bgr->status), 0);
      EXPECT_LE(cv::norm(bayer->bgr, bgr->bgr, cv::NORM_INF, valid), max_levels)
          << to_string(format) << ", " << interpolation;
    }
    cv::Mat rgb;
    cv::cvtColor(smooth, rgb, cv::COLOR_BGR2RGB);
    const auto from_rgb = register_color(*stage, depth, rgb, PixelFormat::kRgb8);
    EXPECT_EQ(cv::norm(from_rgb->bgr, bgr->bgr, cv::NORM_INF), 0) << interpolation;

    cv::Mat blue;
    cv::extractChannel(smooth, blue, 0);
    const auto from_mono = register_color(*stage, depth, blue, PixelFormat::kMono8);
    cv::Mat registered_blue;
    cv::extractChannel(bgr->bgr, registered_blue, 0);
    cv::Mat expected_gray;
    cv::merge(std::vector<cv::Mat>(3, registered_blue), expected_gray);
    EXPECT_EQ(cv::norm(from_mono->bgr, expected_gray, cv::NORM_INF), 0) << interpolation;
  }
}

TEST(ProjectiveRegistration, RgbAndMonoInputReadTheBgrPixelAtEveryLevel) {
  // Nearest sampling reads an rgb8 or mono8 image's pixel where it reads the bgr8 one,
  // at each level's way of reading a pixel's bytes.
  cv::Mat noise(1024, 1280, CV_8UC3);
  cv::randu(noise, 0, 256);
  cv::Mat rgb, blue;
  cv::cvtColor(noise, rgb, cv::COLOR_BGR2RGB);
  cv::extractChannel(noise, blue, 0);
  const ref::Rig rig = ref::rig_from(testing::paper_rig_document());
  const cv::Mat depth = plane_depth(rig, depth_rays(rig), 518, tilted_normal());
  for (const std::string& level : levels()) {
    SCOPED_TRACE(level);
    const auto stage = make_registration(kPaperRig, "nearest", 10.0, level);
    const auto bgr = register_color(*stage, depth, noise);
    ASSERT_GT(cv::countNonZero(bgr->status == RegisteredColor::kValid), 250000);
    const auto from_rgb = register_color(*stage, depth, rgb, PixelFormat::kRgb8);
    EXPECT_EQ(cv::norm(from_rgb->bgr, bgr->bgr, cv::NORM_INF), 0);
    const auto from_mono = register_color(*stage, depth, blue, PixelFormat::kMono8);
    cv::Mat registered_blue, expected_gray;
    cv::extractChannel(bgr->bgr, registered_blue, 0);
    cv::merge(std::vector<cv::Mat>(3, registered_blue), expected_gray);
    EXPECT_EQ(cv::norm(from_mono->bgr, expected_gray, cv::NORM_INF), 0);
  }
}

TEST(ProjectiveRegistration, BilinearSamplingFollowsARampBetweenPixels) {
  // B = 4 (u - 600) and G = 4 (v - 400) in a window: bilinear sampling reproduces the
  // ramp at the projected position to within rounding (0.5 level) and 1/256 weights
  // (4/512 level); nearest sampling would be up to 2 levels off.
  cv::Mat ramp(1024, 1280, CV_8UC3, cv::Scalar(0, 0, 0));
  for (int v = 400; v < 464; ++v) {
    for (int u = 600; u < 664; ++u) {
      ramp.at<cv::Vec3b>(v, u) = cv::Vec3b(static_cast<std::uint8_t>(4 * (u - 600)),
                                           static_cast<std::uint8_t>(4 * (v - 400)), 0);
    }
  }
  const json document = testing::paper_rig_document();
  const ref::Rig rig = ref::rig_from(document);
  const auto rays = depth_rays(rig);
  const cv::Mat depth = plane_depth(rig, rays, 518, tilted_normal());
  const auto out = register_color(*make_registration(kPaperRig, "bilinear"), depth, ramp);
  int compared = 0;
  double worst = 0;
  for (int v = 0; v < depth.rows; ++v) {
    for (int u = 0; u < depth.cols; ++u) {
      const auto p = ref::project(rig, rays[static_cast<std::size_t>(v * depth.cols + u)],
                                  depth.at<float>(v, u));
      if (p.u < 600.5L || p.u > 662.5L || p.v < 400.5L || p.v > 462.5L) continue;
      ++compared;
      const cv::Vec3b bgr = out->bgr.at<cv::Vec3b>(v, u);
      worst = std::max({worst, static_cast<double>(std::abs(bgr[0] - 4 * (p.u - 600))),
                        static_cast<double>(std::abs(bgr[1] - 4 * (p.v - 400)))});
    }
  }
  EXPECT_GT(compared, 800);
  EXPECT_LT(worst, 0.5 + 4.0 / 512 + 1e-3);
}

// The paper's eq. 3 reads W = K_d^-1 M K_c, which does not multiply (3x3, 3x4, 3x3); the
// product that maps a depth pixel to a colour pixel is W = K_c [R | T] [K_d^-1 0; 0 1]
// (3x4), and eqs. 4-5 use its first two rows, u = x w11 + y w12 + w13 + w14 / z, without
// dividing by the third row. z is the depth image's value (eq. 1's result).
struct Linearised {
  Real w[3][4];

  explicit Linearised(const ref::Rig& rig) {
    const Real kd_inverse[3][3] = {{1 / rig.depth.fx, 0, -rig.depth.cx / rig.depth.fx},
                                   {0, 1 / rig.depth.fy, -rig.depth.cy / rig.depth.fy},
                                   {0, 0, 1}};
    const Real kc[3][3] = {
        {rig.color.fx, 0, rig.color.cx}, {0, rig.color.fy, rig.color.cy}, {0, 0, 1}};
    const Real t[3] = {rig.t.x, rig.t.y, rig.t.z};
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) {
        w[i][j] = 0;
        for (int a = 0; a < 3; ++a) {
          for (int b = 0; b < 3; ++b) w[i][j] += kc[i][a] * rig.r[a][b] * kd_inverse[b][j];
        }
      }
      w[i][3] = kc[i][0] * t[0] + kc[i][1] * t[1] + kc[i][2] * t[2];
    }
  }

  ref::Point2 map(int x, int y, Real z) const {
    return {x * w[0][0] + y * w[0][1] + w[0][2] + w[0][3] / z,
            x * w[1][0] + y * w[1][1] + w[1][2] + w[1][3] / z};
  }
};

struct LinearisationError {
  Real exact_vs_reference_px = 0;  // the stage's mapping
  Real min_px = INFINITY;          // eqs. 4-5 against the reference
  Real max_px = 0;
  Real max_with_optical_centre_depth_px = 0;  // eqs. 4-5 with z + z_offset for z
};

LinearisationError linearisation_error(const json& document, const fs::path& file, Real z) {
  const ref::Rig rig = ref::rig_from(document);
  const DepthToColor map(load_calibration(file), file.string(), row_kernels("auto"));
  const Linearised paper(rig);
  LinearisationError e;
  const std::vector<float> depth_row(static_cast<std::size_t>(rig.depth.width),
                                     static_cast<float>(z));
  for (int y = 0; y < rig.depth.height; ++y) {
    const MappedRow mapped(map, y, depth_row.data());
    for (int x = 0; x < rig.depth.width; ++x) {
      const auto exact = ref::project(rig, ref::depth_ray(rig, x, y), z);
      if (exact.u < -0.5L || exact.u >= rig.color.width - 0.5L || exact.v < -0.5L ||
          exact.v >= rig.color.height - 0.5L) {
        continue;
      }
      e.exact_vs_reference_px = std::max(e.exact_vs_reference_px,
                                         std::hypot(mapped.u[x] - exact.u, mapped.v[x] - exact.v));
      const ref::Point2 linear = paper.map(x, y, z);
      const Real error = std::hypot(linear.x - exact.u, linear.y - exact.v);
      e.min_px = std::min(e.min_px, error);
      e.max_px = std::max(e.max_px, error);
      const ref::Point2 centred = paper.map(x, y, z + rig.z_offset);
      e.max_with_optical_centre_depth_px = std::max(
          e.max_with_optical_centre_depth_px, std::hypot(centred.x - exact.u, centred.y - exact.v));
    }
  }
  return e;
}

TEST(ProjectiveRegistration, PapersLinearisedEqs4And5AgainstTheExactMappingForTheShippedRig) {
  const json document = testing::paper_rig_document();
  const LinearisationError e = linearisation_error(document, kPaperRig, 518);
  EXPECT_LT(e.exact_vs_reference_px, kMappingPx);
  // With R = I and T_z = 0 the third row of W is (0, 0, 1, 0) and eqs. 4-5 are exact but
  // for z: they divide by the depth from the mounting surface where the projection needs
  // the optical-centre depth, which shifts every pixel along the baseline by
  // fx_c T_x (1 / z - 1 / (z + z_offset)) = 1000 * 45 * (1/518 - 1/541.97) = 3.8416 px.
  const Real shift = 1000.0L * 45.0L * (1 / 518.0L - 1 / (518.0L + 23.97L));
  EXPECT_NEAR(static_cast<double>(e.max_px), static_cast<double>(shift), 1e-9);
  EXPECT_NEAR(static_cast<double>(e.min_px), static_cast<double>(shift), 1e-9);
  EXPECT_LT(e.max_with_optical_centre_depth_px, 1e-9L);
  std::cout << "shipped rig at 518 mm: exact mapping vs reference "
            << static_cast<double>(e.exact_vs_reference_px) << " px; eqs. 4-5 vs exact "
            << static_cast<double>(e.max_px)
            << " px (with z + z_offset: " << static_cast<double>(e.max_with_optical_centre_depth_px)
            << " px)\n";
}

TEST(ProjectiveRegistration, PapersLinearisationFailsForARotatedRig) {
  // The same rig turned 3 degrees about the ToF's y axis, a plausible mounting error:
  // the third row of W is no longer (0, 0, 1, 0) and dropping its division costs pixels
  // at the image sides even with the optical-centre depth.
  json document = testing::paper_rig_document();
  document["depth_to_color"]["R"] = rotation(0, 3, 0);
  const CalibrationFile file(document);
  const LinearisationError e = linearisation_error(document, file.path(), 518);
  EXPECT_LT(e.exact_vs_reference_px, kMappingPx);
  EXPECT_GT(e.max_with_optical_centre_depth_px, 10.0L);
  std::cout << "rig turned 3 degrees at 518 mm: eqs. 4-5 vs exact up to "
            << static_cast<double>(e.max_px)
            << " px (with z + z_offset: " << static_cast<double>(e.max_with_optical_centre_depth_px)
            << " px)\n";
}

TEST(ProjectiveRegistration, InputsThatDoNotFitTheCalibrationAreRefused) {
  const auto stage = make_registration(kPaperRig);
  const cv::Mat depth(480, 640, CV_32FC1, cv::Scalar(518));
  const cv::Mat color(1024, 1280, CV_8UC3, cv::Scalar(0, 0, 0));
  EXPECT_EQ(
      process_error(*stage, cv::Mat(240, 320, CV_32FC1, cv::Scalar(518)), color,
                    PixelFormat::kBgr8),
      "depth image is 320x240 px but the calibration " + kPaperRig.string() + " is for 640x480 px");
  EXPECT_EQ(process_error(*stage, depth, cv::Mat(480, 640, CV_8UC3), PixelFormat::kBgr8),
            "colour image is 640x480 px but the calibration " + kPaperRig.string() +
                " is for 1280x1024 px");
  EXPECT_EQ(process_error(*stage, depth, cv::Mat(1024, 1280, CV_8UC1), PixelFormat::kBgr8),
            "colour image (bgr8) has pixel type CV_8UC1; expected CV_8UC3");
  EXPECT_EQ(process_error(*stage, depth, color, PixelFormat::kBayerRggb8),
            "colour image (bayer_rggb8) has pixel type CV_8UC3; expected CV_8UC1");
  EXPECT_EQ(process_error(*stage, cv::Mat(480, 640, CV_16UC1), color, PixelFormat::kBgr8),
            "depth image has pixel type CV_16UC1; expected CV_32FC1 (mm)");
}

TEST(ProjectiveRegistration, ABadCalibrationIsRefusedAtConstructionWithTheFieldNamed) {
  json document = testing::paper_rig_document();
  document["color_camera"]["fy"] = 0;
  const CalibrationFile file(document);
  try {
    make_registration(file.path());
    FAIL() << "constructed";
  } catch (const Error& error) {
    EXPECT_EQ(std::string(error.what()),
              file.path().string() + ":/color_camera/fy: expected a number > 0, got 0");
  }
}

TEST(ProjectiveRegistration, OutputBuffersAreReusedInSteadyState) {
  const auto stage = make_registration(kPaperRig);
  const cv::Mat depth(480, 640, CV_32FC1, cv::Scalar(518));
  const cv::Mat color = coordinate_image();
  const std::uint8_t* bgr = nullptr;
  const std::uint8_t* status = nullptr;
  {
    const auto out = register_color(*stage, depth, color);
    bgr = out->bgr.data;
    status = out->status.data;
  }
  const auto out = register_color(*stage, depth, color);
  EXPECT_EQ(out->bgr.data, bgr);
  EXPECT_EQ(out->status.data, status);
}

TEST(ProjectiveRegistration, DescriptorDeclaresTheContract) {
  const StageDescriptor d = describe_projective();
  EXPECT_EQ(d.type, "registration.projective");
  ASSERT_EQ(d.inputs.size(), 2u);
  EXPECT_EQ(d.inputs[0].name, "depth");
  EXPECT_EQ(d.inputs[0].type, DepthImage::kTypeName);
  EXPECT_EQ(d.inputs[1].name, "color");
  EXPECT_EQ(d.inputs[1].type, ColorImage::kTypeName);
  ASSERT_EQ(d.outputs.size(), 1u);
  EXPECT_EQ(d.outputs[0].type, RegisteredColor::kTypeName);
  ASSERT_NE(d.param("calibration"), nullptr);
  EXPECT_FALSE(d.param("calibration")->required());  // "": the frames' own
  ASSERT_NE(d.param("occlusion_tolerance_mm"), nullptr);
  EXPECT_EQ(d.param("occlusion_tolerance_mm")->default_value, 10.0);
  ASSERT_NE(d.param("interpolation"), nullptr);
  EXPECT_EQ(d.param("interpolation")->choices, (std::vector<std::string>{"nearest", "bilinear"}));
  EXPECT_EQ(d.concurrency, Concurrency::kParallel);
}

}  // namespace
}  // namespace tilth::registration
