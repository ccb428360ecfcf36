#include "viewline/scenarios/ball_catching/flight_fit.h"

#include <algorithm>
#include <cmath>
#include <set>

#include "viewline/core/error.h"

namespace viewline::scenarios {

using Vec6 = Eigen::Matrix<double, 6, 1>;
using Mat6 = Eigen::Matrix<double, 6, 6>;

FlightFit::FlightFit(FlightFitConfig cfg, std::vector<core::Camera> cameras, estimation::DragBallisticModel model)
    : cfg_(cfg), cams_(std::move(cameras)), model_(std::move(model)) {
  if (cfg_.min_images < 6) throw core::InvalidInput("flight_fit.min_images: expected >= 6 (six unknowns)");
  if (cfg_.min_cameras < 1) throw core::InvalidInput("flight_fit.min_cameras: expected >= 1");
  if (cfg_.max_iterations < 1) throw core::InvalidInput("flight_fit.max_iterations: expected >= 1");
  model_.q = 0.0;
  model_.validate();
}

void FlightFit::reset() {
  images_.clear();
  x_ref_.reset();
  H_.setZero();
}

std::optional<estimation::StateEstimate> FlightFit::add(const FitImage& image, const estimation::StateEstimate& guess) {
  if (image.camera >= cams_.size()) throw core::InvalidInput("FlightFit::add: camera index out of range");
  if (!(image.sigma_px > 0.0) || !image.uv.allFinite() || !std::isfinite(image.t))
    throw core::InvalidInput("FlightFit::add: expected a finite pixel and stamp and a positive sigma");
  const auto pos = std::upper_bound(images_.begin(), images_.end(), image.t,
                                    [](double t, const FitImage& f) { return t < f.t; });
  const bool new_front = pos == images_.begin();
  images_.insert(pos, image);
  if (static_cast<int>(images_.size()) < cfg_.min_images) return std::nullopt;
  std::set<std::size_t> cams;
  for (const FitImage& f : images_) cams.insert(f.camera);
  if (static_cast<int>(cams.size()) < cfg_.min_cameras) return std::nullopt;
  if (!x_ref_ || new_front) {
    // Seed: the tracker's (drag-free) state carried back to the first image, x(t) = x_ref + ...
    // under gravity alone; Gauss-Newton removes the drag's share.
    const Vec6 x = guess.x();
    const double d = guess.t() - images_.front().t;
    const Eigen::Vector3d g = model_.gravity();
    Vec6 x0;
    x0.head<3>() = x.head<3>() - x.tail<3>() * d + 0.5 * g * d * d;
    x0.tail<3>() = x.tail<3>() - g * d;
    x_ref_ = x0;
  }
  if (!solve()) {
    reset();  // a diverged fit is dropped; the tracker's estimate is used until it is rebuilt
    return std::nullopt;
  }
  // The state at the newest image and its covariance Φ H⁻¹ Φᵀ.
  Vec6 x = *x_ref_;
  Mat6 Phi = Mat6::Identity();
  const double dt = images_.back().t - images_.front().t;
  if (dt > 0.0) {
    Phi = model_.jacobianFixed(x, dt);
    x = model_.propagateFixed(x, dt);
  }
  const Mat6 P = Phi * H_.ldlt().solve(Mat6::Identity()) * Phi.transpose();
  return estimation::StateEstimate(x, 0.5 * (P + P.transpose()), images_.back().t);
}

bool FlightFit::solve() {
  for (int it = 0; it < cfg_.max_iterations; ++it) {
    Mat6 H = Mat6::Zero();
    Vec6 b = Vec6::Zero();
    Vec6 x = *x_ref_;
    Mat6 Phi = Mat6::Identity();
    double t_prev = images_.front().t;
    for (const FitImage& f : images_) {
      const double dt = f.t - t_prev;
      if (dt > 0.0) {
        Phi = model_.jacobianFixed(x, dt) * Phi;
        x = model_.propagateFixed(x, dt);
        t_prev = f.t;
      }
      const core::Camera& cam = cams_[f.camera];
      const Eigen::Vector3d p = x.head<3>();
      const auto uv = cam.project(p);
      if (!uv) continue;  // behind the camera at this iterate
      Eigen::Matrix<double, 2, 3> Jp;
      bool ok = true;
      for (int k = 0; k < 3 && ok; ++k) {
        const double h = 1e-5;  // m: central differences of the distorted projection
        Eigen::Vector3d dp = Eigen::Vector3d::Zero();
        dp(k) = h;
        const auto up = cam.project(p + dp), um = cam.project(p - dp);
        if (!up || !um) ok = false;
        else Jp.col(k) = (*up - *um) / (2.0 * h);
      }
      if (!ok) continue;
      const Eigen::Matrix<double, 2, 6> J = Jp * Phi.topRows<3>();
      const double w = 1.0 / (f.sigma_px * f.sigma_px);
      H += w * J.transpose() * J;
      b += w * J.transpose() * (f.uv - *uv);
    }
    const Eigen::LDLT<Mat6> ldlt(H);
    if (ldlt.info() != Eigen::Success || !ldlt.isPositive()) return false;
    const Vec6 delta = ldlt.solve(b);
    if (!delta.allFinite()) return false;
    *x_ref_ += delta;
    H_ = H;
    if (delta.head<3>().norm() < 1e-6 && delta.tail<3>().norm() < 1e-5) break;
  }
  return x_ref_->allFinite();
}

}  // namespace viewline::scenarios
