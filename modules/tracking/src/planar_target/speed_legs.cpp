// Constant-speed legs and learnt turns: model in the header.
#include "viewline/tracking/planar_target/speed_legs.h"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>

#include "viewline/core/checks.h"
#include "viewline/core/frames.h"
#include "viewline/tracking/planar_target/waypoint_region.h"

namespace viewline::tracking {

void ConstantSpeedLeg::add(double t, const Eigen::Vector2d& z, const Eigen::Matrix2d& R) {
  const Eigen::Matrix2d Ri = R.inverse();
  const double tau = t - t_c;
  A += Ri;
  Bz += Ri * z;
  Bt += tau * Ri;
  Ctz += tau * (Ri * z);
  Ctt += tau * tau * Ri;
  zz += z.dot(Ri * z);
}

double ConstantSpeedLeg::logPrior(double th) const {
  double lp = log_norm;
  if (region) {
    // log(2π R² / (2A)); R floored at 0.1 mm so that a corner estimated on the boundary stays finite.
    const double R = std::max(boxReach(region_c, region_lo, region_hi, th), 1e-4);
    lp += region_log_scale + 2.0 * std::log(R);
  }
  if (prior_mu.empty() || prior_weight <= 0.0) return lp;
  double g = 0.0;
  for (double mu : prior_mu) {
    const double d = std::remainder(th - mu, 2.0 * core::kPi);  // wrapped to [−π, π]; σ ≪ π, one wrap suffices
    if (d * d < 100.0 * prior_sigma * prior_sigma) g += std::exp(-0.5 * d * d / (prior_sigma * prior_sigma));  // (e^-50 beyond)
  }
  g *= std::sqrt(2.0 * core::kPi) / prior_sigma / static_cast<double>(prior_mu.size());
  return lp + std::log((1.0 - prior_weight) + prior_weight * g);
}

double ConstantSpeedLeg::logLikelihood(double th, Eigen::Vector3d* m, Eigen::Matrix3d* cov) const {
  const Eigen::Vector2d u(std::cos(th), std::sin(th));
  Eigen::Matrix3d L = P0_inv;
  L.topLeftCorner<2, 2>() += A;
  const Eigen::Vector2d Btu = Bt * u;
  L.block<2, 1>(0, 2) += Btu;
  L.block<1, 2>(2, 0) += Btu.transpose();
  L(2, 2) += u.dot(Ctt * u);
  const Eigen::Vector3d P0_b0 = P0_inv * beta0;
  Eigen::Vector3d eta = P0_b0;
  eta.head<2>() += Bz;
  eta(2) += u.dot(Ctz);
  const Eigen::LLT<Eigen::Matrix3d> llt(L);
  const Eigen::Vector3d mean = llt.solve(eta);
  if (m != nullptr) *m = mean;
  if (cov != nullptr) *cov = llt.solve(Eigen::Matrix3d::Identity());
  const double logdet = 2.0 * Eigen::Matrix3d(llt.matrixL()).diagonal().array().log().sum();
  return -0.5 * (zz + beta0.dot(P0_b0) - eta.dot(mean)) - 0.5 * logdet;
}

// log p(measurements | leg) up to the terms every candidate corner time shares (Σ log det 2πR_i, and
// −½ log det P₀ when P₀ is the same): log of the mean over θ of p(z | θ) p(θ) 2π, on a grid of
// `points` (the rectangle rule, exact to e^(−2π² σ²/h²) for a periodic integrand of width σ, step h).
// Every θ shares Λ's top-left block M = P₀⁻¹_cc + A, so log p(z | θ) is evaluated through the Schur
// complement of M (the same value as logLikelihood(θ), a few flops per θ instead of a 3x3 factorisation):
//   b = P₀⁻¹_cs + B_τ u, c = P₀⁻¹_ss + uᵀ C_ττ u, η = (η_c, η_s), g = M⁻¹ η_c,
//   ηᵀ Λ⁻¹ η = η_cᵀ g + (η_s − bᵀ g)² / σ,  log det Λ = log det M + log σ,  σ = c − bᵀ M⁻¹ b.
double ConstantSpeedLeg::logEvidence(int points) const {
  const Eigen::Matrix2d M = P0_inv.topLeftCorner<2, 2>() + A;
  const Eigen::LLT<Eigen::Matrix2d> llt_M(M);
  const Eigen::Matrix2d Mi = llt_M.solve(Eigen::Matrix2d::Identity());
  const double logdet_M = 2.0 * Eigen::Matrix2d(llt_M.matrixL()).diagonal().array().log().sum();
  const Eigen::Vector3d P0_b0 = P0_inv * beta0;
  const Eigen::Vector2d eta_c = P0_b0.head<2>() + Bz;
  const Eigen::Vector2d g = Mi * eta_c;
  const double base = zz + beta0.dot(P0_b0) - eta_c.dot(g);
  const Eigen::Vector2d P0_cs = P0_inv.block<2, 1>(0, 2);
  // The grid's cos and sin (the same θ_k, so the same values) are kept per thread for the last grid size;
  // logPrior comes from the leg's table when it has one of this size (made from the same prior fields).
  thread_local std::vector<Eigen::Vector2d> unit;
  if (static_cast<int>(unit.size()) != points) {
    unit.resize(static_cast<std::size_t>(points));
    for (int k = 0; k < points; ++k) {
      const double th = -core::kPi + 2.0 * core::kPi * k / points;
      unit[static_cast<std::size_t>(k)] = Eigen::Vector2d(std::cos(th), std::sin(th));
    }
  }
  const double* table = log_prior_evidence && static_cast<int>(log_prior_evidence->size()) == points
                            ? log_prior_evidence->data() : nullptr;
  std::vector<double> ll(static_cast<std::size_t>(points));
  double top = -std::numeric_limits<double>::infinity();
  for (int k = 0; k < points; ++k) {
    const Eigen::Vector2d& u = unit[static_cast<std::size_t>(k)];
    const Eigen::Vector2d b = P0_cs + Bt * u;
    const double schur = P0_inv(2, 2) + u.dot(Ctt * u) - b.dot(Mi * b);
    const double r = P0_b0(2) + u.dot(Ctz) - b.dot(g);
    const double prior = table != nullptr ? table[k] : logPrior(-core::kPi + 2.0 * core::kPi * k / points);
    ll[static_cast<std::size_t>(k)] = -0.5 * (base - r * r / schur) - 0.5 * (logdet_M + std::log(schur)) + prior;
    top = std::max(top, ll[static_cast<std::size_t>(k)]);
  }
  double sum = 0.0;
  for (double v : ll) sum += std::exp(v - top);
  return top + std::log(sum / points);
}

estimation::StateEstimate ConstantSpeedLeg::moments(double t) const {
  struct Point {
    double th = 0.0, ll = 0.0;
    Eigen::Vector3d m = Eigen::Vector3d::Zero();
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  };
  const auto evaluate = [&](double th, const double* prior) {
    Point pt;
    pt.th = th;
    pt.ll = logLikelihood(th, &pt.m, &pt.cov) + (prior != nullptr ? *prior : logPrior(th));
    return pt;
  };
  // Grid over θ: 180 points on the circle, then refined (±2 steps of the previous grid, 81 points)
  // while one point holds more than 30 % of the mass, so a narrow posterior is still resolved. The first
  // grid's logPrior comes from the leg's table when it has one (the same values).
  double lo = -core::kPi, step = 2.0 * core::kPi / 180.0;
  int count = 180;
  const double* table = log_prior_moments && log_prior_moments->size() == 180 ? log_prior_moments->data() : nullptr;
  std::vector<Point> grid;
  for (int level = 0; level < 6; ++level) {
    grid.clear();
    for (int k = 0; k < count; ++k) grid.push_back(evaluate(lo + step * k, level == 0 && table != nullptr ? table + k : nullptr));
    const auto best = std::max_element(grid.begin(), grid.end(), [](const Point& a, const Point& b) { return a.ll < b.ll; });
    double total = 0.0;
    for (const Point& pt : grid) total += std::exp(pt.ll - best->ll);
    if (1.0 / total < 0.3) break;
    lo = best->th - 2.0 * step;
    step = 4.0 * step / 80.0;
    count = 81;
  }
  double top = -1e300;
  for (const Point& pt : grid) top = std::max(top, pt.ll);
  const double tau = t - t_c;
  Eigen::Vector4d mean = Eigen::Vector4d::Zero();
  Eigen::Matrix4d second = Eigen::Matrix4d::Zero();
  double wsum = 0.0;
  for (const Point& pt : grid) {
    const double w = std::exp(pt.ll - top);
    if (w < 1e-12) continue;
    const Eigen::Vector2d u(std::cos(pt.th), std::sin(pt.th));
    Eigen::Matrix<double, 4, 3> J = Eigen::Matrix<double, 4, 3>::Zero();  // (p, v) = J β
    J.topLeftCorner<2, 2>() = Eigen::Matrix2d::Identity();
    J.block<2, 1>(0, 2) = tau * u;
    J.block<2, 1>(2, 2) = u;
    const Eigen::Vector4d x = J * pt.m;
    wsum += w;
    mean += w * x;
    second += w * (x * x.transpose() + J * pt.cov * J.transpose());
  }
  mean /= wsum;
  Eigen::Matrix4d P = second / wsum - mean * mean.transpose();
  P = 0.5 * (P + P.transpose()).eval();
  P.diagonal().array() += 1e-12;
  return estimation::StateEstimate(Eigen::VectorXd(mean), Eigen::MatrixXd(P), t);
}

std::vector<double> ConstantSpeedLeg::logPriorOnGrid(int points, bool evidence) const {
  // The θ_k exactly as logEvidence and moments() form them.
  std::vector<double> out(static_cast<std::size_t>(points));
  const double step = 2.0 * core::kPi / points;
  for (int k = 0; k < points; ++k)
    out[static_cast<std::size_t>(k)] = logPrior(evidence ? -core::kPi + 2.0 * core::kPi * k / points : -core::kPi + step * k);
  return out;
}

int legEvidencePoints(double turn_prior_sigma_deg) {
  // Steps of 3° or the turn prior's σ if smaller: θ's likelihood is wider than ~2° over a few seconds of
  // leg, so the rectangle rule's relative error stays below ~1e-4 (see logEvidence).
  return std::max(120, static_cast<int>(std::ceil(360.0 / turn_prior_sigma_deg)));
}

void LegSpeed::set(double speed, double variance) {
  core::requirePositive(speed, "PlanarTargetFilter::setSpeed: speed");
  core::requirePositive(variance, "PlanarTargetFilter::setSpeed: variance");
  sum_ = speed / variance;
  info_ = 1.0 / variance;
}

void LegSpeed::learn(const PlanarHistory& history, std::size_t end, int min_samples) {
  // Weighted least-squares line z = a + b t per axis through history[0..end] (the segment that
  // ended at the detected jump, or its last jump_window s): var b = 1 / Σ w (t − t̄)², t̄ the weighted
  // mean time. s_k = |b|, var s_k = b̂ᵀ diag(var b) b̂ (b̂ = b / |b|). Segments under 0.5 s or with
  // fewer than 2 jump_min_samples measurements are skipped (their slope is mostly noise).
  if (end + 1 < static_cast<std::size_t>(2 * min_samples)) return;
  if (history[end].t - history.front().t < 0.5) return;
  Eigen::Vector2d b, var_b;
  for (int a = 0; a < 2; ++a) {
    double sw = 0.0, swt = 0.0, swz = 0.0;
    for (std::size_t i = 0; i <= end; ++i) {
      const double w = 1.0 / history[i].R(a, a);
      sw += w;
      swt += w * history[i].t;
      swz += w * history[i].z(a);
    }
    const double tm = swt / sw, zm = swz / sw;
    double stt = 0.0, stz = 0.0;
    for (std::size_t i = 0; i <= end; ++i) {
      const double w = 1.0 / history[i].R(a, a);
      stt += w * (history[i].t - tm) * (history[i].t - tm);
      stz += w * (history[i].t - tm) * (history[i].z(a) - zm);
    }
    b(a) = stz / stt;
    var_b(a) = 1.0 / stt;
  }
  const double s = b.norm();
  if (!(s > 0.0)) return;
  const Eigen::Vector2d u = b / s;
  const double var_s = u.cwiseProduct(u).dot(var_b);
  if (!(var_s > 0.0) || var_s > 0.25 * s * s) return;  // a segment whose speed is not resolved
  sum_ += s / var_s;
  info_ += 1.0 / var_s;
}

void LearntTurns::legEnded(double dir) {
  // The leg that just ended had direction dir; the one before it last_direction_: that corner's turn.
  if (!enabled_) return;
  if (std::isfinite(dir) && std::isfinite(last_direction_)) {
    turns_.push_back(std::remainder(dir - last_direction_, 2.0 * core::kPi));
    if (turns_.size() > 8) turns_.erase(turns_.begin());
  }
  last_direction_ = dir;
}

double legBayesFactor(const PlanarHistory& history, int j, const LegFactory& make, double turn_prior_sigma_deg) {
  // log p(z_{j+1..n} | a constant-speed leg from x(j|j) at t_j) − log p(z_{j+1..n} | straight on from x(j|j)).
  // Both are linear-Gaussian evidences; the Σ log det 2πR_i they share cancel.
  //   leg:  logEvidence() − ½ log det P₀ (see ConstantSpeedLeg);
  //   straight on: z_i = H_i x + e_i, H_i = [I  τ_i I], x ~ N(x̂_j, P_j): with Λ = P_j⁻¹ + Σ H_iᵀR_i⁻¹H_i,
  //         η = P_j⁻¹ x̂_j + Σ H_iᵀR_i⁻¹z_i: −½ (Σ z_iᵀR_i⁻¹z_i + x̂ᵀP_j⁻¹x̂ − ηᵀΛ⁻¹η) − ½ log det Λ − ½ log det P_j.
  const std::size_t n = history.size();
  const PlanarSnapshot& sj = history[static_cast<std::size_t>(j)];
  const Eigen::Vector4d x = sj.state.x().head<4>();
  Eigen::Matrix4d P = sj.state.P().topLeftCorner<4, 4>();
  P.diagonal().array() += 1e-10;
  const auto llt_P = P.llt();
  const Eigen::Matrix4d P_inv = llt_P.solve(Eigen::Matrix4d::Identity());
  Eigen::Matrix4d L = P_inv;
  Eigen::Vector4d eta = P_inv * x;
  double zz = 0.0;
  ConstantSpeedLeg leg = make(sj.t, x.head<2>(), P.topLeftCorner<2, 2>(), velocityDirection(sj.state));
  for (std::size_t i = static_cast<std::size_t>(j) + 1; i < n; ++i) {
    const PlanarSnapshot& si = history[i];
    const Eigen::Matrix2d Ri = si.R.inverse();
    Eigen::Matrix<double, 2, 4> H;
    H << Eigen::Matrix2d::Identity(), (si.t - sj.t) * Eigen::Matrix2d::Identity();
    L += H.transpose() * Ri * H;
    eta += H.transpose() * (Ri * si.z);
    zz += si.z.dot(Ri * si.z);
    leg.add(si.t, si.z, si.R);
  }
  const auto llt_L = L.llt();
  const double logdet_L = 2.0 * Eigen::Matrix4d(llt_L.matrixL()).diagonal().array().log().sum();
  const double logdet_P = 2.0 * Eigen::Matrix4d(llt_P.matrixL()).diagonal().array().log().sum();
  const double straight = -0.5 * (zz + x.dot(P_inv * x) - eta.dot(llt_L.solve(eta))) - 0.5 * logdet_L - 0.5 * logdet_P;
  const double logdet_P0 = -std::log(leg.P0_inv.determinant());
  return leg.logEvidence(legEvidencePoints(turn_prior_sigma_deg)) - 0.5 * logdet_P0 - straight;
}

int refineCornerTime(const PlanarHistory& history, int j, const LegFactory& make) {
  // The test's t_j is only the best kink of a free velocity step; a leg that starts a few samples
  // early or late bends towards the old direction. Among the candidates t_j' within ±6 measurements,
  // take the one of highest evidence for "straight on from x(i0|i0) until t_j', then a constant-speed
  // leg from there": the same measurements i0+1 .. n−1 are explained by both parts for every j'.
  const int n = static_cast<int>(history.size());
  const int i0 = std::max(0, j - 6);
  const PlanarSnapshot& s0 = history[static_cast<std::size_t>(i0)];
  const Eigen::Matrix2d P_pos = s0.state.P().block(0, 0, 2, 2);
  int best = j;
  double best_e = -1e300;
  for (int jj = std::max(i0 + 1, j - 6); jj <= std::min(n - 3, j + 6); ++jj) {
    double e = 0.0;
    for (int i = i0 + 1; i <= jj; ++i) {
      const PlanarSnapshot& si = history[static_cast<std::size_t>(i)];
      const Eigen::Vector2d r = si.z - extrapolatePosition(s0.state.x(), si.t - s0.t);
      e -= 0.5 * r.dot(si.R.ldlt().solve(r));
    }
    const PlanarSnapshot& sj = history[static_cast<std::size_t>(jj)];
    ConstantSpeedLeg leg = make(sj.t, extrapolatePosition(s0.state.x(), sj.t - s0.t), P_pos, velocityDirection(s0.state));
    for (int i = jj + 1; i < n; ++i) {
      const PlanarSnapshot& si = history[static_cast<std::size_t>(i)];
      leg.add(si.t, si.z, si.R);
    }
    e += leg.logEvidence();
    if (e > best_e) {
      best_e = e;
      best = jj;
    }
  }
  return best;
}

}  // namespace viewline::tracking
