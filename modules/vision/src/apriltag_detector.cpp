#include "viewline/vision/apriltag_detector.h"

#include <algorithm>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <visp3/core/vpMeterPixelConversion.h>
#include <visp3/core/vpPixelMeterConversion.h>

#include "viewline/core/checks.h"
#include "viewline/core/error.h"
#include "viewline/core/frames.h"
#include "viewline/vision/color.h"

namespace viewline::vision {

namespace {

int parseId(const std::string& message) {
  const auto pos = message.find("id: ");
  if (pos == std::string::npos) return -1;
  try {
    return std::stoi(message.substr(pos + 4));
  } catch (const std::exception&) {
    return -1;
  }
}

}  // namespace

void AprilTagDetectorConfig::validate() const {
  core::requirePositive(tag_size_m, "AprilTagDetectorConfig.tag_size_m");
  for (const auto& [id, size] : tag_sizes_m)
    core::requirePositive(size, "AprilTagDetectorConfig.tag_sizes_m[" + std::to_string(id) + "]");
  if (!(quad_decimate >= 1.0F))
    throw core::InvalidInput("AprilTagDetectorConfig.quad_decimate must be >= 1");
  if (threads < 1) throw core::InvalidInput("AprilTagDetectorConfig.threads must be >= 1");
  core::requirePositive(corner_sigma_px, "AprilTagDetectorConfig.corner_sigma_px");
  if (!(std::abs(apriltag_pixel_offset) <= 1.0))
    throw core::InvalidInput("AprilTagDetectorConfig.apriltag_pixel_offset must be in [-1, 1] px");
}

double AprilTagDetectorConfig::sizeOf(int id) const {
  const auto it = tag_sizes_m.find(id);
  return it == tag_sizes_m.end() ? tag_size_m : it->second;
}

AprilTagDetector::AprilTagDetector(AprilTagDetectorConfig config) : config_(std::move(config)) {
  config_.validate();
  detector_ = std::make_unique<vpDetectorAprilTag>(config_.family, config_.pose_method);
  detector_->setAprilTagQuadDecimate(config_.quad_decimate);
  detector_->setAprilTagNbThreads(config_.threads);
  detector_->setDisplayTag(false);
}

AprilTagDetector::~AprilTagDetector() = default;

Result<AprilTagMeasurement> AprilTagDetector::detect(const vpImage<unsigned char>& image,
                                                     const vpCameraParameters& cam,
                                                     core::Timestamp stamp) {
  if (image.getWidth() == 0 || image.getHeight() == 0)
    throw core::InvalidInput("AprilTagDetector::detect: image is empty");
  core::requireFinite(stamp, "AprilTagDetector::detect: stamp");
  detector_->detect(image);
  const std::size_t n = detector_->getNbObjects();
  if (n == 0) return Result<AprilTagMeasurement>::fail(FailureReason::NotFound, "no AprilTag in the image");
  AprilTagMeasurement out;
  out.stamp = stamp;
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (std::size_t i = 0; i < n; ++i) {
    TagObservation tag;
    tag.message = detector_->getMessage(i);
    tag.id = parseId(tag.message);
    tag.size_m = config_.sizeOf(tag.id);
    const std::vector<vpImagePoint> poly = detector_->getPolygon(i);
    if (poly.size() != 4) continue;
    // The AprilTag library puts pixel centres at +0.5 (pixel (0,0) spans [0,1]); ViSP passes its
    // corners on unchanged. Our convention (ViSP, OpenCV) has pixel centres at integers, so the
    // corners move by -0.5 px and the pose is refined on them.
    for (std::size_t k = 0; k < 4; ++k)
      tag.corners[k] = {poly[k].get_u() - config_.apriltag_pixel_offset, poly[k].get_v() - config_.apriltag_pixel_offset};
    const vpImagePoint cog = detector_->getCog(i);
    tag.center = {cog.get_u() - config_.apriltag_pixel_offset, cog.get_v() - config_.apriltag_pixel_offset};
    vpHomogeneousMatrix cMo;
    if (!detector_->getPose(i, tag.size_m, cam, cMo)) continue;
    tag.c_M_o = core::toEigen(cMo);
    if (!tag.c_M_o.matrix().allFinite()) continue;
    // Match the image corners with the tag-frame corners through the pose.
    const double h = 0.5 * tag.size_m;
    const std::array<Eigen::Vector3d, 4> candidates{Eigen::Vector3d(-h, -h, 0.0), Eigen::Vector3d(h, -h, 0.0),
                                                    Eigen::Vector3d(h, h, 0.0), Eigen::Vector3d(-h, h, 0.0)};
    std::vector<cv::Point3d> object;
    std::vector<cv::Point2d> ideal;
    for (std::size_t k = 0; k < 4; ++k) {
      double best = 1e300;
      for (const auto& c : candidates) {
        const Eigen::Vector3d p = tag.c_M_o * c;
        double u = 0.0, v = 0.0;
        vpMeterPixelConversion::convertPoint(cam, p.x() / p.z(), p.y() / p.z(), u, v);
        const double d = (Eigen::Vector2d(u, v) - tag.corners[k]).squaredNorm();
        if (d < best) {
          best = d;
          tag.corners_3d[k] = c;
        }
      }
      object.emplace_back(tag.corners_3d[k].x(), tag.corners_3d[k].y(), 0.0);
      double x = 0.0, y = 0.0;
      vpPixelMeterConversion::convertPoint(cam, tag.corners[k].x(), tag.corners[k].y(), x, y);
      ideal.emplace_back(x, y);
    }
    if (config_.apriltag_pixel_offset != 0.0) {
      // Refine ViSP's pose on the shifted corners (normalised coordinates, distortion removed).
      cv::Mat rvec, tvec(3, 1, CV_64F);
      cv::Matx33d R;
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) R(r, c) = tag.c_M_o.linear()(r, c);
      cv::Rodrigues(R, rvec);
      for (int r = 0; r < 3; ++r) tvec.at<double>(r) = tag.c_M_o.translation()(r);
      cv::solvePnPRefineLM(object, ideal, cv::Matx33d::eye(), cv::noArray(), rvec, tvec);
      cv::Rodrigues(rvec, R);
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) tag.c_M_o.linear()(r, c) = R(r, c);
      tag.c_M_o.translation() = Eigen::Vector3d(tvec.at<double>(0), tvec.at<double>(1), tvec.at<double>(2));
      if (!tag.c_M_o.matrix().allFinite()) continue;
    }
    mean += tag.center;
    out.tags.push_back(std::move(tag));
  }
  if (out.tags.empty())
    return Result<AprilTagMeasurement>::fail(FailureReason::PoseFailed, "tags found but no pose computed");
  const double m = static_cast<double>(out.tags.size());
  out.pixel = mean / m;
  // Centre of a tag = mean of 4 corners (var σc²/4); the mean over m tags divides by m again.
  out.pixel_covariance = Eigen::Matrix2d::Identity() * (config_.corner_sigma_px * config_.corner_sigma_px / (4.0 * m));
  out.quality = Quality::Good;
  out.score = 1.0;
  return out;
}

Result<AprilTagMeasurement> AprilTagDetector::detect(const cv::Mat& image, const core::Camera& camera,
                                                     core::Timestamp stamp) {
  requireGrayOrBgrImage(image, "AprilTagDetector::detect");
  if (image.channels() == 3)
    cv::cvtColor(image, gray_cv_, cv::COLOR_BGR2GRAY);
  else
    gray_cv_ = image.isContinuous() ? image : image.clone();
  gray_.resize(static_cast<unsigned>(gray_cv_.rows), static_cast<unsigned>(gray_cv_.cols));
  for (int r = 0; r < gray_cv_.rows; ++r)
    std::copy_n(gray_cv_.ptr<unsigned char>(r), gray_cv_.cols, gray_[static_cast<unsigned>(r)]);
  return detect(gray_, camera.intrinsics, stamp);
}

AprilTagTableDetector::AprilTagTableDetector(core::Camera camera, std::vector<TagOnTable> layout,
                                             AprilTagDetectorConfig config)
    : camera_(std::move(camera)), layout_(std::move(layout)), detector_([&] {
        for (const auto& t : layout_) config.tag_sizes_m[t.id] = t.size_m;
        return config;
      }()) {
  if (layout_.empty()) throw core::InvalidInput("AprilTagTableDetector: layout has no tag");
  for (const auto& t : layout_) {
    core::requirePositive(t.size_m, "AprilTagTableDetector: layout tag " + std::to_string(t.id) + " size_m");
    core::requireFinite(t.t_M_tag.matrix(), "AprilTagTableDetector: layout tag " + std::to_string(t.id) + " pose");
  }
}

Result<TableMeasurement> AprilTagTableDetector::detect(const cv::Mat& image, core::Timestamp stamp) {
  last_ = detector_.detect(image, camera_, stamp);
  if (!last_) return last_.failure();
  std::vector<cv::Point3d> object;
  std::vector<cv::Point2d> pixels;
  const double px = camera_.intrinsics.get_px(), py = camera_.intrinsics.get_py();
  const double u0 = camera_.intrinsics.get_u0(), v0 = camera_.intrinsics.get_v0();
  std::optional<Eigen::Isometry3d> start;
  double start_size = 0.0;
  std::vector<Eigen::Vector2d> used_corners;
  for (const auto& tag : last_->tags) {
    const auto it = std::find_if(layout_.begin(), layout_.end(), [&](const TagOnTable& t) { return t.id == tag.id; });
    if (it == layout_.end()) continue;
    for (std::size_t k = 0; k < 4; ++k) {
      const Eigen::Vector3d p_t = it->t_M_tag * tag.corners_3d[k];
      object.emplace_back(p_t.x(), p_t.y(), p_t.z());
      const Eigen::Vector2d xy = camera_.pixelToNormalized(tag.corners[k]);
      pixels.emplace_back(u0 + px * xy.x(), v0 + py * xy.y());
      used_corners.push_back(tag.corners[k]);
    }
    // Start from the pose of the largest tag in the image: c_M_t = c_M_tag * tag_M_t.
    const double size_px = (tag.corners[0] - tag.corners[2]).norm();
    if (size_px > start_size) {
      start_size = size_px;
      start = tag.c_M_o * it->t_M_tag.inverse();
    }
  }
  if (!start)
    return Result<TableMeasurement>::fail(FailureReason::NotFound, "no tag of the table layout in the image");
  const cv::Matx33d K(px, 0.0, u0, 0.0, py, v0, 0.0, 0.0, 1.0);
  cv::Mat rvec(3, 1, CV_64F), tvec(3, 1, CV_64F);
  {
    cv::Matx33d R;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) R(r, c) = start->linear()(r, c);
    cv::Rodrigues(R, rvec);
    for (int r = 0; r < 3; ++r) tvec.at<double>(r) = start->translation()(r);
  }
  if (object.size() >= 8) {
    try {
      cv::solvePnPRefineLM(object, pixels, K, cv::noArray(), rvec, tvec);
    } catch (const cv::Exception& e) {
      return Result<TableMeasurement>::fail(FailureReason::PoseFailed, std::string("solvePnPRefineLM: ") + e.what());
    }
  }
  TableMeasurement m;
  m.stamp = stamp;
  cv::Matx33d Rcv;
  cv::Rodrigues(rvec, Rcv);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) m.c_M_t.linear()(r, c) = Rcv(r, c);
  m.c_M_t.translation() = Eigen::Vector3d(tvec.at<double>(0), tvec.at<double>(1), tvec.at<double>(2));
  if (!m.c_M_t.matrix().allFinite() || m.c_M_t.translation().z() <= 0.0)
    return Result<TableMeasurement>::fail(FailureReason::PoseFailed, "non-physical table pose from tags");
  std::vector<cv::Point2d> reproj;
  cv::projectPoints(object, rvec, tvec, K, cv::noArray(), reproj);
  double sq = 0.0;
  for (std::size_t k = 0; k < reproj.size(); ++k) {
    const double du = reproj[k].x - pixels[k].x, dv = reproj[k].y - pixels[k].y;
    sq += du * du + dv * dv;
  }
  m.reprojection_rms_px = std::sqrt(sq / static_cast<double>(reproj.size()));
  // The table's "corners": projections of (±L/2, ±L/2, 0) are unknown here (no side length);
  // report the table origin as the pixel and keep the corners of the first tag used.
  const Eigen::Vector3d o_c = m.c_M_t.translation();
  const auto uv = camera_.normalizedToPixel({o_c.x() / o_c.z(), o_c.y() / o_c.z()});
  m.pixel = uv;
  for (std::size_t k = 0; k < 4; ++k) m.corners[k] = used_corners[k];
  const double sc = detector_.config().corner_sigma_px;
  m.pixel_covariance = Eigen::Matrix2d::Identity() * (sc * sc / static_cast<double>(used_corners.size()));
  m.quality = m.reprojection_rms_px < 1.0 ? Quality::Good : Quality::Degraded;
  m.score = 1.0 / (1.0 + m.reprojection_rms_px);
  return m;
}

}  // namespace viewline::vision
