#include "viewline/calib/extrinsics.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <visp3/core/vpPixelMeterConversion.h>
#include <visp3/vision/vpPose.h>

#include "viewline/core/error.h"
#include "viewline/core/frames.h"

namespace viewline::calib {
namespace {

Eigen::Isometry3d fromCv(const cv::Mat& rvec, const cv::Mat& tvec) {
  cv::Mat R;
  cv::Rodrigues(rvec, R);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) T.linear()(r, c) = R.at<double>(r, c);
    T.translation()(r) = tvec.at<double>(r);
  }
  return T;
}

void toCv(const Eigen::Isometry3d& T, cv::Mat& rvec, cv::Mat& tvec) {
  cv::Mat R(3, 3, CV_64F);
  tvec = cv::Mat(3, 1, CV_64F);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) R.at<double>(r, c) = T.linear()(r, c);
    tvec.at<double>(r) = T.translation()(r);
  }
  cv::Rodrigues(R, rvec);
}

// Small pose increment: exp of (rotation vector, translation), applied on the left.
Eigen::Isometry3d delta(const Eigen::Matrix<double, 6, 1>& d) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  const double a = d.head<3>().norm();
  if (a > 0) T.linear() = Eigen::AngleAxisd(a, d.head<3>() / a).toRotationMatrix();
  T.translation() = d.tail<3>();
  return T;
}

}  // namespace

PoseCamera PoseCamera::fromOpenCv(const io::OpenCvIntrinsics& o) {
  PoseCamera c;
  c.K = cv::Mat(3, 3, CV_64F);
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k) c.K.at<double>(r, k) = o.camera_matrix(r, k);
  c.D = cv::Mat(static_cast<int>(o.distortion.size()), 1, CV_64F);
  for (int i = 0; i < c.D.rows; ++i) c.D.at<double>(i) = o.distortion(i);
  return c;
}

PoseCamera PoseCamera::fromVisp(const vpCameraParameters& cam) {
  PoseCamera c;
  c.K = (cv::Mat_<double>(3, 3) << cam.get_px(), 0, cam.get_u0(), 0, cam.get_py(), cam.get_v0(), 0, 0, 1);
  if (cam.get_projModel() == vpCameraParameters::perspectiveProjWithDistortion) c.visp = cam;
  return c;
}

std::vector<cv::Point2f> PoseCamera::normalize(const std::vector<cv::Point2f>& px) const {
  std::vector<cv::Point2f> out;
  if (visp) {
    for (const auto& p : px) {
      double x = 0, y = 0;
      vpPixelMeterConversion::convertPoint(*visp, p.x, p.y, x, y);
      out.emplace_back(static_cast<float>(x), static_cast<float>(y));
    }
    return out;
  }
  if (px.empty()) return out;
  cv::undistortPoints(px, out, K, D, cv::noArray(), cv::noArray(),
                      cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 50, 1e-10));
  return out;
}

std::vector<cv::Point2d> PoseCamera::project(const std::vector<cv::Point3f>& pts, const Eigen::Isometry3d& c_M_o) const {
  std::vector<cv::Point2d> out;
  if (visp) {
    for (const auto& p : pts) {
      const Eigen::Vector3d q = c_M_o * Eigen::Vector3d(p.x, p.y, p.z);
      const double x = q.x() / q.z(), y = q.y() / q.z();
      const double k = 1.0 + visp->get_kud() * (x * x + y * y);
      out.emplace_back(visp->get_u0() + visp->get_px() * x * k, visp->get_v0() + visp->get_py() * y * k);
    }
    return out;
  }
  cv::Mat rvec, tvec;
  toCv(c_M_o, rvec, tvec);
  std::vector<cv::Point3d> p3;
  for (const auto& p : pts) p3.emplace_back(p.x, p.y, p.z);
  cv::projectPoints(p3, rvec, tvec, K, D, out);
  return out;
}

BoardPose estimatePose(const PoseCamera& cam, const std::vector<cv::Point3f>& obj, const std::vector<cv::Point2f>& img) {
  if (obj.size() < 4 || obj.size() != img.size())
    throw core::InvalidInput("estimatePose: need at least 4 matched points, got " + std::to_string(obj.size()) + "/" +
                             std::to_string(img.size()));
  // Work in normalised coordinates so that ViSP's and OpenCV's distortion models are both honoured.
  const std::vector<cv::Point2f> xy = cam.normalize(img);
  const cv::Mat I = cv::Mat::eye(3, 3, CV_64F);
  cv::Mat rvec, tvec;
  bool planar = true;
  for (const auto& p : obj) planar = planar && std::abs(p.z) < 1e-9f;
  const int method = planar ? (obj.size() == 4 ? cv::SOLVEPNP_IPPE_SQUARE : cv::SOLVEPNP_IPPE) : cv::SOLVEPNP_ITERATIVE;
  bool ok = false;
  if (method == cv::SOLVEPNP_IPPE_SQUARE) {
    // IPPE_SQUARE wants the corners in its own order; our tag corners already are (-h,-h)... so
    // use generic IPPE which accepts any planar layout.
    ok = cv::solvePnP(obj, xy, I, cv::noArray(), rvec, tvec, false, cv::SOLVEPNP_IPPE);
  } else {
    ok = cv::solvePnP(obj, xy, I, cv::noArray(), rvec, tvec, false, method);
  }
  if (!ok) throw core::NumericalError("estimatePose: solvePnP failed");
  // Refine on the pixel reprojection error with the real camera model.
  Eigen::Isometry3d T = fromCv(rvec, tvec);
  if (!cam.visp) {
    cv::solvePnPRefineLM(obj, img, cam.K, cam.D, rvec, tvec,
                         cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 50, 1e-12));
    T = fromCv(rvec, tvec);
  } else {
    std::vector<vpPoint> pts;
    for (std::size_t i = 0; i < obj.size(); ++i) {
      vpPoint p(obj[i].x, obj[i].y, obj[i].z);
      p.set_x(xy[i].x);
      p.set_y(xy[i].y);
      pts.push_back(p);
    }
    vpPose pose;
    pose.addPoints(pts);
    vpHomogeneousMatrix cMo = core::toVisp(T);
    pose.computePose(vpPose::VIRTUAL_VS, cMo);
    T = core::toEigen(cMo);
  }
  BoardPose out;
  out.c_M_o = T;
  out.points = obj.size();
  const auto proj = cam.project(obj, T);
  double s = 0.0;
  for (std::size_t i = 0; i < img.size(); ++i)
    s += std::pow(proj[i].x - static_cast<double>(img[i].x), 2) + std::pow(proj[i].y - static_cast<double>(img[i].y), 2);
  out.rms_px = std::sqrt(s / static_cast<double>(img.size()));
  return out;
}

std::map<int, BoardPose> estimateTagPoses(const PoseCamera& cam, const cv::Mat& gray, const BoardSpec& board) {
  std::map<int, BoardPose> out;
  const auto tags = detectAprilTags(gray, board.tag_family);
  const auto c3 = tagCorners3d(board.tag_size);
  for (const auto& [id, corners] : tags) {
    if (!board.tag_ids.empty() && std::find(board.tag_ids.begin(), board.tag_ids.end(), id) == board.tag_ids.end())
      continue;
    out[id] = estimatePose(cam, c3, corners);
  }
  return out;
}

Eigen::Isometry3d averagePoses(const std::vector<Eigen::Isometry3d>& poses) {
  if (poses.empty()) throw core::InvalidInput("averagePoses: no poses");
  Eigen::Matrix4d A = Eigen::Matrix4d::Zero();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  for (const auto& p : poses) {
    const Eigen::Quaterniond q(p.linear());
    const Eigen::Vector4d v = q.coeffs();
    A += v * v.transpose();
    t += p.translation();
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d> es(A);
  const Eigen::Vector4d v = es.eigenvectors().col(3);
  Eigen::Quaterniond q(v(3), v(0), v(1), v(2));
  Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
  out.linear() = q.normalized().toRotationMatrix();
  out.translation() = t / static_cast<double>(poses.size());
  return out;
}

Eigen::Isometry3d groundFromBoard(BoardType type) {
  Eigen::Isometry3d b_M_g = Eigen::Isometry3d::Identity();
  if (type != BoardType::AprilTag) b_M_g.linear() = Eigen::Vector3d(1, -1, -1).asDiagonal();
  return b_M_g;
}

GroundResult cameraToGround(const std::vector<Eigen::Isometry3d>& c_M_o, BoardType type) {
  if (c_M_o.empty()) throw core::InvalidInput("camera-to-ground: no board pose");
  std::vector<Eigen::Isometry3d> c_M_g;
  for (const auto& p : c_M_o) c_M_g.push_back(p * groundFromBoard(type));
  GroundResult r;
  r.c_M_g = averagePoses(c_M_g);
  for (const auto& p : c_M_g) r.spread_rad = std::max(r.spread_rad, core::rotationAngle(p.linear(), r.c_M_g.linear()));
  const Eigen::Isometry3d g_M_c = r.c_M_g.inverse();
  r.height_m = g_M_c.translation().z();
  const Eigen::Vector3d z_c = g_M_c.linear().col(2), x_c = g_M_c.linear().col(0);
  r.pitch_rad = std::asin(std::clamp(-z_c.z(), -1.0, 1.0));
  r.roll_rad = std::asin(std::clamp(x_c.z(), -1.0, 1.0));
  if (r.height_m <= 0.0)
    throw core::InvalidInput("camera-to-ground: the camera is below the board plane; the board must lie printed side up");
  return r;
}

RigResult calibrateRig(const RigObservations& obs, std::size_t reference, std::size_t min_shared) {
  const std::size_t nc = obs.cameras.size();
  const std::size_t nk = obs.views.size();
  if (nc < 1) throw core::InvalidInput("calibrateRig: no cameras");
  if (reference >= nc) throw core::InvalidInput("calibrateRig: reference camera index out of range");
  for (std::size_t k = 0; k < nk; ++k)
    if (obs.views[k].size() != nc)
      throw core::InvalidInput("calibrateRig: instant " + std::to_string(k) + " has " +
                               std::to_string(obs.views[k].size()) + " camera slots, expected " + std::to_string(nc));
  // Per-view PnP.
  std::vector<std::vector<std::optional<Eigen::Isometry3d>>> pose(nk, std::vector<std::optional<Eigen::Isometry3d>>(nc));
  for (std::size_t k = 0; k < nk; ++k)
    for (std::size_t i = 0; i < nc; ++i)
      if (obs.views[k][i])
        pose[k][i] = estimatePose(obs.cameras[i], obs.views[k][i]->object_points, obs.views[k][i]->image_points).c_M_o;

  RigResult r;
  r.c_M_ref.assign(nc, Eigen::Isometry3d::Identity());
  r.views_used.assign(nc, 0);
  for (std::size_t i = 0; i < nc; ++i) {
    std::vector<Eigen::Isometry3d> rel;
    for (std::size_t k = 0; k < nk; ++k) {
      if (pose[k][i]) ++r.views_used[i];
      if (pose[k][i] && pose[k][reference]) rel.push_back(*pose[k][i] * pose[k][reference]->inverse());
    }
    if (i == reference) continue;
    if (rel.size() < min_shared)
      throw core::InvalidInput("calibrateRig: camera " + std::to_string(i) + " sees the board together with the reference "
                               "camera in " + std::to_string(rel.size()) + " instants, need at least " +
                               std::to_string(min_shared));
    r.c_M_ref[i] = averagePoses(rel);
  }
  // Board poses in the reference frame (instants seen by nobody are dropped).
  std::vector<std::size_t> instants;
  r.ref_M_board.assign(nk, Eigen::Isometry3d::Identity());
  for (std::size_t k = 0; k < nk; ++k) {
    std::vector<Eigen::Isometry3d> cand;
    for (std::size_t i = 0; i < nc; ++i)
      if (pose[k][i]) cand.push_back(r.c_M_ref[i].inverse() * *pose[k][i]);
    if (cand.empty()) continue;
    r.ref_M_board[k] = averagePoses(cand);
    instants.push_back(k);
  }
  if (nc == 1) {
    r.camera_rms_px.assign(1, 0.0);
    return r;
  }
  // Levenberg-Marquardt over (camera poses except reference, board poses), numeric Jacobian.
  std::vector<std::size_t> cams;
  for (std::size_t i = 0; i < nc; ++i)
    if (i != reference) cams.push_back(i);
  const Eigen::Index np = static_cast<Eigen::Index>(6 * (cams.size() + instants.size()));
  auto residuals = [&](const std::vector<Eigen::Isometry3d>& cm, const std::vector<Eigen::Isometry3d>& bm,
                       std::vector<double>* per_cam_sq, std::vector<std::size_t>* per_cam_n) {
    std::vector<double> res;
    for (std::size_t k : instants)
      for (std::size_t i = 0; i < nc; ++i) {
        if (!obs.views[k][i]) continue;
        const auto& o = *obs.views[k][i];
        const auto proj = obs.cameras[i].project(o.object_points, cm[i] * bm[k]);
        for (std::size_t p = 0; p < proj.size(); ++p) {
          const double dx = proj[p].x - static_cast<double>(o.image_points[p].x);
          const double dy = proj[p].y - static_cast<double>(o.image_points[p].y);
          res.push_back(dx);
          res.push_back(dy);
          if (per_cam_sq) {
            (*per_cam_sq)[i] += dx * dx + dy * dy;
            (*per_cam_n)[i] += 1;
          }
        }
      }
    return Eigen::VectorXd(Eigen::Map<Eigen::VectorXd>(res.data(), static_cast<Eigen::Index>(res.size())));
  };
  auto apply = [&](const Eigen::VectorXd& d, std::vector<Eigen::Isometry3d>& cm, std::vector<Eigen::Isometry3d>& bm) {
    Eigen::Index j = 0;
    for (std::size_t i : cams) {
      cm[i] = delta(d.segment<6>(j)) * cm[i];
      j += 6;
    }
    for (std::size_t k : instants) {
      bm[k] = delta(d.segment<6>(j)) * bm[k];
      j += 6;
    }
  };
  std::vector<Eigen::Isometry3d> cm = r.c_M_ref, bm = r.ref_M_board;
  Eigen::VectorXd e = residuals(cm, bm, nullptr, nullptr);
  double cost = e.squaredNorm();
  double lambda = 1e-3;
  for (int it = 0; it < 50; ++it) {
    r.iterations = it + 1;
    Eigen::MatrixXd J(e.size(), np);
    for (Eigen::Index j = 0; j < np; ++j) {
      Eigen::VectorXd d = Eigen::VectorXd::Zero(np);
      const double h = 1e-6;
      d(j) = h;
      auto cm2 = cm, bm2 = bm;
      apply(d, cm2, bm2);
      J.col(j) = (residuals(cm2, bm2, nullptr, nullptr) - e) / h;
    }
    const Eigen::MatrixXd H = J.transpose() * J;
    const Eigen::VectorXd g = J.transpose() * e;
    bool improved = false;
    for (int tries = 0; tries < 10 && !improved; ++tries) {
      Eigen::MatrixXd Hl = H;
      Hl.diagonal() += lambda * H.diagonal().cwiseMax(1e-12);
      const Eigen::VectorXd step = -Hl.ldlt().solve(g);
      auto cm2 = cm, bm2 = bm;
      apply(step, cm2, bm2);
      const Eigen::VectorXd e2 = residuals(cm2, bm2, nullptr, nullptr);
      if (e2.squaredNorm() < cost) {
        const double rel = (cost - e2.squaredNorm()) / cost;
        cm = cm2;
        bm = bm2;
        e = e2;
        cost = e2.squaredNorm();
        lambda = std::max(lambda / 10, 1e-9);
        improved = true;
        if (rel < 1e-12) it = 1000;
      } else {
        lambda *= 10;
      }
    }
    if (!improved) break;
  }
  r.c_M_ref = cm;
  r.ref_M_board = bm;
  std::vector<double> sq(nc, 0.0);
  std::vector<std::size_t> n(nc, 0);
  e = residuals(cm, bm, &sq, &n);
  r.rms_px = std::sqrt(e.squaredNorm() / static_cast<double>(e.size() / 2));
  for (std::size_t i = 0; i < nc; ++i) r.camera_rms_px.push_back(n[i] ? std::sqrt(sq[i] / static_cast<double>(n[i])) : 0.0);
  return r;
}

}  // namespace viewline::calib
