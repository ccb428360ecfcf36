#include "viewline/scenarios/ball_catching/flight_fit.h"

#include <algorithm>
#include <cmath>

#include "viewline/core/error.h"

namespace viewline::scenarios {

using Vec6 = Eigen::Matrix<double, 6, 1>;
using Mat6 = Eigen::Matrix<double, 6, 6>;

FlightFit::FlightFit(FlightFitConfig cfg, std::vector<core::Camera> cameras, estimation::DragBallisticModel model,
                     FitAimPlane aim)
    : cfg_(cfg), aim_(aim), cams_(std::move(cameras)), model_(std::move(model)) {
  if (cfg_.min_images < (cfg_.hasPrior() ? 1 : 6))
    throw core::InvalidInput("flight_fit.min_images: expected >= 6 (six unknowns) without a prior, >= 1 with one");
  if (!cfg_.prior_mean.allFinite() || !cfg_.prior_std.allFinite() || cfg_.prior_std.minCoeff() < 0.0 ||
      !(std::isfinite(cfg_.aim_prior_std) && cfg_.aim_prior_std >= 0.0))
    throw core::InvalidInput("flight_fit prior: expected finite means and stds >= 0");
  if (cfg_.aim_prior_std > 0.0) {
    if (!(std::abs(aim_.normal.norm() - 1.0) < 1e-9) || !aim_.centre.allFinite())
      throw core::InvalidInput("FlightFit: the aim plane needs a finite centre and a unit normal");
    // In-plane orthonormal basis: any vector not along n, made orthogonal to it, and n × it.
    const Eigen::Vector3d a = std::abs(aim_.normal.z()) < 0.9 ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d::UnitX();
    E_.col(0) = (a - aim_.normal * aim_.normal.dot(a)).normalized();
    E_.col(1) = aim_.normal.cross(E_.col(0));
  }
  if (cfg_.min_cameras < 1) throw core::InvalidInput("flight_fit.min_cameras: expected >= 1");
  if (cfg_.max_iterations < 1) throw core::InvalidInput("flight_fit.max_iterations: expected >= 1");
  model_.q = 0.0;
  model_.validate();
  camera_seen_.assign(cams_.size(), 0);
  images_.reserve(kReservedImages);
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
  // Distinct cameras among the images (flags per camera, kept between calls: no allocation).
  std::fill(camera_seen_.begin(), camera_seen_.end(), static_cast<unsigned char>(0));
  int cameras_seen = 0;
  for (const FitImage& f : images_)
    if (!camera_seen_[f.camera]) {
      camera_seen_[f.camera] = 1;
      ++cameras_seen;
    }
  if (cameras_seen < cfg_.min_cameras) return std::nullopt;
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
  if (dt > 0.0) x = model_.propagateWithJacobianFixed(x, dt, Phi);
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
        Mat6 step;  // one pass gives the step's mean and Jacobian (the bits of the two calls)
        x = model_.propagateWithJacobianFixed(x, dt, step);
        Phi = step * Phi;
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
    addPrior(*x_ref_, H, b);
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

void FlightFit::addPrior(const Vec6& x, Mat6& H, Vec6& b) const {
  for (int k = 0; k < 6; ++k)
    if (cfg_.prior_std(k) > 0.0) {
      const double w = 1.0 / (cfg_.prior_std(k) * cfg_.prior_std(k));
      H(k, k) += w;
      b(k) += w * (cfg_.prior_mean(k) - x(k));
    }
  if (!(cfg_.aim_prior_std > 0.0)) return;
  // Crossing of the plane through the aim centre: march in steps until n·(p − c) changes sign,
  // then Newton on the time (as planning::predictCrossing; here on the fixed-size model).
  const Eigen::Vector3d& n = aim_.normal;
  auto side = [&](const Vec6& s) { return n.dot(s.head<3>() - aim_.centre); };
  if (!(side(x) > 0.0) || !(n.dot(x.tail<3>()) < 0.0)) return;  // not heading for the plane at this iterate
  const double step = 0.02, horizon = 3.0;
  double tau = 0.0;
  Vec6 s = x;
  while (side(s) > 0.0) {
    if (tau >= horizon) return;
    s = model_.propagateFixed(s, step);
    tau += step;
  }
  Mat6 F_tau = Mat6::Identity();  // ∂x(τ)/∂x at the final τ: set with the last iterate's propagation
  for (int it = 0; it < 8; ++it) {
    const double nv = n.dot(s.tail<3>());
    if (!(nv < 0.0)) return;
    const double dtau = -side(s) / nv;
    tau += dtau;
    if (!(tau > 0.0 && tau < horizon)) return;
    const bool last = std::abs(dtau) < 1e-9 || it == 7;
    s = last ? model_.propagateWithJacobianFixed(x, tau, F_tau) : model_.propagateFixed(x, tau);
    if (std::abs(dtau) < 1e-9) break;
  }
  const double nv = n.dot(s.tail<3>());
  if (!(tau > 0.0) || !(nv < 0.0) || !s.allFinite()) return;
  // δc = A δp(τ), A = I − v nᵀ / (n·v): the point moves along the flight to stay in the plane.
  const Eigen::Matrix3d A = Eigen::Matrix3d::Identity() - s.tail<3>() * n.transpose() / nv;
  const Eigen::Matrix<double, 2, 6> Jc = E_.transpose() * A * F_tau.topRows<3>();
  const double w = 1.0 / (cfg_.aim_prior_std * cfg_.aim_prior_std);
  H += w * Jc.transpose() * Jc;
  b += w * Jc.transpose() * (E_.transpose() * (aim_.centre - s.head<3>()));
}

}  // namespace viewline::scenarios
