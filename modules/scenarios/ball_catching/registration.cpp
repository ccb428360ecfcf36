#include "viewline/scenarios/ball_catching/registration.h"

#include <algorithm>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <string>

#include "viewline/core/error.h"
#include "viewline/core/frames.h"
#include "viewline/core/random.h"
#include "viewline/scenarios/ball_catching/world.h"
#include "viewline/sim/rig.h"
#include "viewline/vision/ball_detector.h"

namespace viewline::scenarios {

RegistrationResult registerCamerasToRobot(BallCatchingConfig& cfg, const sim::Scene& room, std::uint64_t seed) {
  const CatchRegistration& rg = cfg.registration;
  core::Rng rng = core::makeRng(seed);
  core::Rng pos_rng = core::makeRng(core::deriveSeed(seed, 0x905));  // robot positioning error only
  std::vector<sim::SimCamera> sims;
  std::vector<core::Camera> est;
  std::vector<vision::BallDetector> detectors;
  vision::BallDetectorConfig dc = cfg.detector;
  dc.hsv = rg.marker_hsv;
  dc.fallback_full_frame = false;
  for (const auto& c : cfg.cameras) {  // every configured camera, whatever camera_count
    sim::SimCamera sc;
    sc.camera = c.renderCamera();
    sc.clock.rate = c.rate_hz;
    sc.effects.noise.sigma = c.noise_sigma;
    sims.push_back(std::move(sc));
    est.push_back(c.estimatorCamera());
    detectors.emplace_back(dc, est.back());
  }
  sim::CameraRig rig(sims, rng, cfg.render);
  RegistrationResult out;
  out.registered.assign(sims.size(), false);
  // Per camera: known marker positions (robot world) and their detected, undistorted normalised
  // image points (calibrated intrinsics).
  std::vector<std::vector<cv::Point3d>> obj(sims.size());
  std::vector<std::vector<cv::Point2d>> img(sims.size());
  for (double dx : rg.offsets_x)
    for (double dy : rg.offsets_y)
      for (double dz : rg.offsets_z) {
        const Eigen::Vector3d hole = cfg.robot.home + Eigen::Vector3d(dx, dy, dz);
        const Eigen::Vector3d marker = hole + rg.marker_offset;  // where the robot believes it is
        ++out.poses;
        // The robot holds the box where it is commanded up to its positioning error: the marker
        // is rendered there, the PnP below uses the commanded position.
        Eigen::Vector3d held = hole;
        if (rg.robot_position_error_m > 0.0)
          for (int k = 0; k < 3; ++k) held(k) += rg.robot_position_error_m * core::gaussian(pos_rng);
        StaticBoxWorld world(room, cfg, held);
        rig.reset(0.0);
        std::vector<bool> seen(sims.size(), false);
        for (std::size_t got = 0; got < sims.size();) {
          auto f = rig.captureNext(world);
          if (!f || seen[f->camera_index]) continue;
          const std::size_t ci = f->camera_index;
          seen[ci] = true;
          ++got;
          // Search only around where the calibrated camera expects the marker (the robot knows
          // where it holds it): other green things in the room are never taken for it.
          const auto expected = est[ci].project(marker);
          if (!expected || !est[ci].inImage(*expected, 0.0)) continue;
          const auto det = detectors[ci].detect(f->image, f->stamp, *expected);
          if (!det.ok() || (det.value().pixel - *expected).norm() > rg.gate_px) continue;  // noise blobs
          const Eigen::Vector2d x = est[ci].pixelToNormalized(det.value().pixel);
          obj[ci].emplace_back(marker.x(), marker.y(), marker.z());
          img[ci].emplace_back(x.x(), x.y());
        }
      }
  // Each camera's pose re-estimated from its own points (PnP, Levenberg-Marquardt from the
  // calibrated pose): the per-camera pose errors of the board calibration differ, so one rigid
  // transform for the whole rig cannot remove them. Cameras with fewer than min_points keep their
  // calibrated pose.
  const cv::Matx33d K = cv::Matx33d::eye();
  double ss_before = 0.0, ss_after = 0.0;
  int npts = 0;
  for (std::size_t ci = 0; ci < sims.size(); ++ci) {
    out.points_per_camera.push_back(static_cast<int>(obj[ci].size()));
    if (static_cast<int>(obj[ci].size()) < rg.min_points) continue;
    const Eigen::Isometry3d& M = est[ci].c_M_w;
    cv::Mat R0;
    cv::eigen2cv(Eigen::Matrix3d(M.linear()), R0);
    cv::Vec3d rvec, tvec(M.translation().x(), M.translation().y(), M.translation().z());
    cv::Rodrigues(R0, rvec);
    auto reproj = [&](const cv::Vec3d& rv, const cv::Vec3d& tv) {
      std::vector<cv::Point2d> p;
      cv::projectPoints(obj[ci], rv, tv, K, cv::noArray(), p);
      double ss = 0.0;
      for (std::size_t k = 0; k < p.size(); ++k) ss += std::pow(cv::norm(p[k] - img[ci][k]), 2);
      return ss;
    };
    const cv::Vec3d rvec0 = rvec, tvec0 = tvec;
    cv::solvePnP(obj[ci], img[ci], K, cv::noArray(), rvec, tvec, true, cv::SOLVEPNP_ITERATIVE);
    // One pass of outlier removal (residual > 3 x the median, at least 0.5 px), then solve again
    // from the calibrated pose.
    {
      std::vector<cv::Point2d> p;
      cv::projectPoints(obj[ci], rvec, tvec, K, cv::noArray(), p);
      std::vector<double> r;
      for (std::size_t k = 0; k < p.size(); ++k) r.push_back(cv::norm(p[k] - img[ci][k]));
      std::vector<double> sorted = r;
      std::nth_element(sorted.begin(), sorted.begin() + static_cast<long>(sorted.size() / 2), sorted.end());
      const double limit = std::max(3.0 * sorted[sorted.size() / 2], 0.5 / est[ci].focalPx());
      std::vector<cv::Point3d> o2;
      std::vector<cv::Point2d> i2;
      for (std::size_t k = 0; k < r.size(); ++k)
        if (r[k] <= limit) {
          o2.push_back(obj[ci][k]);
          i2.push_back(img[ci][k]);
        }
      if (static_cast<int>(o2.size()) < rg.min_points) continue;
      obj[ci] = o2;
      img[ci] = i2;
      out.points_per_camera.back() = static_cast<int>(o2.size());
      rvec = rvec0;
      tvec = tvec0;
      cv::solvePnP(obj[ci], img[ci], K, cv::noArray(), rvec, tvec, true, cv::SOLVEPNP_ITERATIVE);
    }
    const double after = reproj(rvec, tvec);
    cv::Mat R;
    cv::Rodrigues(rvec, R);
    Eigen::Matrix3d Re;
    cv::cv2eigen(R, Re);
    Eigen::Isometry3d Mn = Eigen::Isometry3d::Identity();
    Mn.linear() = Re;
    Mn.translation() = Eigen::Vector3d(tvec[0], tvec[1], tvec[2]);
    const double shift = (Mn.inverse().translation() - M.inverse().translation()).norm();
    const double rot = core::rotationAngle(Mn.linear(), M.linear());
    const double rms_px = est[ci].focalPx() * std::sqrt(after / static_cast<double>(obj[ci].size()));
    // Plausibility: a registration that does not fit its points, or moves the camera far more than
    // a calibration error, is refused (the camera keeps its calibrated pose).
    if (rms_px > rg.max_rms_px || shift > rg.max_shift_m || rot > rg.max_rotation_rad) {
      ++out.cameras_refused;
      continue;
    }
    ss_before += reproj(rvec0, tvec0);
    ss_after += after;
    npts += static_cast<int>(obj[ci].size());
    out.centre_shift_mm.push_back(1e3 * shift);
    out.rotation_deg.push_back(core::rad2deg(rot));
    core::Camera cam = est[ci];
    cam.c_M_w = Mn;
    cfg.cameras[ci].calibrated_camera = cam;
    cfg.cameras[ci].registered = true;
    out.registered[ci] = true;
    ++out.cameras_registered;
  }
  if (out.cameras_registered == 0)
    throw core::NumericalError("registration: no camera saw the marker at " + std::to_string(rg.min_points) +
                               " poses (check registration.marker_hsv and the offsets)");
  const double f = est.front().focalPx();
  out.reprojection_px_before = f * std::sqrt(ss_before / std::max(1, npts));
  out.reprojection_px_after = f * std::sqrt(ss_after / std::max(1, npts));
  return out;
}

}  // namespace viewline::scenarios
