#include "viewline/tracking/image_ekf.h"

#include <Eigen/LU>

#include "viewline/core/checks.h"
#include "viewline/estimation/kalman_filter.h"

namespace viewline::tracking {

bool pixelJacobian(const core::Camera& camera, const Eigen::Vector3d& p_w, Eigen::Vector2d& uv,
                   Eigen::Matrix<double, 2, 3>& H, double min_depth) {
  const Eigen::Vector3d pc = camera.c_M_w * p_w;
  if (!(pc.z() > min_depth)) return false;
  const Eigen::Vector2d xy(pc.x() / pc.z(), pc.y() / pc.z());
  uv = exactPixelOf(camera, xy);
  Eigen::Matrix<double, 2, 3> dxy_dpc;
  dxy_dpc << 1.0 / pc.z(), 0.0, -pc.x() / (pc.z() * pc.z()), 0.0, 1.0 / pc.z(), -pc.y() / (pc.z() * pc.z());
  const Eigen::Matrix2d duv_dxy = undistortionJacobian(camera, uv).inverse();
  H = duv_dxy * dxy_dpc * camera.c_M_w.linear();
  return true;
}

ImageSpaceEkf::ImageSpaceEkf(std::vector<core::Camera> cameras, TrackerConfig cfg)
    : cameras_(std::move(cameras)), cfg_(std::move(cfg)) {
  cfg_.validate();
  if (cameras_.empty()) throw core::InvalidInput("image EKF: at least one camera is needed");
}

Refusal ImageSpaceEkf::submit(const ImageMeasurement& m) {
  if (!std::isfinite(m.t) || !m.uv.allFinite()) return Refusal::NonFinite;
  if (m.camera >= cameras_.size()) return Refusal::UnknownCamera;
  if (!(m.sigma_px > 0.0)) return Refusal::BadNoise;
  if (active_ && m.t < est_.t()) return Refusal::TooOld;
  if (!active_ || m.t - last_fused_t_ > cfg_.max_coast) {
    est_ = estimation::StateEstimate(cfg_.prior_mean, cfg_.prior_cov, m.t);
    active_ = true;
    consecutive_ = 0;
    fused_in_track_ = 0;
    last_fused_t_ = m.t;
  }
  if (m.t > est_.t()) {
    estimation::predict(est_, cfg_.model.transition(m.t - est_.t()));
    est_.setTime(m.t);
  }
  const core::Camera& cam = cameras_[m.camera];
  Eigen::Vector2d uv_hat;
  Eigen::Matrix<double, 2, 3> Hp;
  bool fused = false;
  if (pixelJacobian(cam, est_.x().head<3>(), uv_hat, Hp)) {
    estimation::LinearMeasurement lin;
    lin.C = Eigen::MatrixXd::Zero(2, 6);
    lin.C.leftCols(3) = Hp;
    // Linearised about x̂: y_lin = uv − h(x̂) + H x̂ gives innovation uv − h(x̂).
    lin.y = m.uv - uv_hat + lin.C * est_.x();
    lin.R = m.sigma_px * m.sigma_px * Eigen::MatrixXd::Identity(2, 2);
    const Eigen::VectorXd d = m.uv - uv_hat;
    const GateReport g = evaluateGate(d, estimation::innovationCovariance(est_, lin.C, lin.R), cfg_.gate);
    if (!g.rejected || fused_in_track_ == 0) {
      estimation::update(est_, lin);
      fused = true;
    }
  } else {
    ++skipped_;
  }
  if (fused) {
    consecutive_ = 0;
    ++fused_in_track_;
    last_fused_t_ = m.t;
    last_fate_ = Fate::Fused;
  } else {
    ++gated_;
    ++consecutive_;
    last_fate_ = Fate::Gated;
    if (consecutive_ >= cfg_.restart_after_rejections) {
      active_ = false;
      ++restarts_;
    }
  }
  return Refusal::None;
}

}  // namespace viewline::tracking
