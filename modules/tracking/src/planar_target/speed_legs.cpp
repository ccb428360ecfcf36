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

namespace {
// cos θ_k and sin θ_k at θ_k = −π + 2π k / points (evidence: logEvidence's grid and the prior's normalisation)
// or −π + (2π / points) k (moments()' first grid): the same θ_k, so the same values, as evaluating them where
// they are used. Kept per thread, the last few grids.
struct UnitGrid {
  int points = 0;
  bool evidence = false;
  std::vector<double> cos, sin;
};
const UnitGrid& unitGrid(int points, bool evidence) {
  thread_local UnitGrid grids[6];
  thread_local std::size_t next = 0;
  for (const UnitGrid& g : grids) {
    if (g.points == points && g.evidence == evidence) return g;
  }
  UnitGrid& unit = grids[next];
  next = (next + 1) % 6;
  unit.points = points;
  unit.evidence = evidence;
  unit.cos.resize(static_cast<std::size_t>(points));
  unit.sin.resize(static_cast<std::size_t>(points));
  const double step = 2.0 * core::kPi / points;
  for (int k = 0; k < points; ++k) {
    const double th = evidence ? -core::kPi + 2.0 * core::kPi * k / points : -core::kPi + step * k;
    unit.cos[static_cast<std::size_t>(k)] = std::cos(th);
    unit.sin[static_cast<std::size_t>(k)] = std::sin(th);
  }
  return unit;
}
}  // namespace

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

void ConstantSpeedLeg::copySums(const ConstantSpeedLeg& from) {
  A = from.A;
  Bz = from.Bz;
  Bt = from.Bt;
  Ctz = from.Ctz;
  Ctt = from.Ctt;
  zz = from.zz;
}

double ConstantSpeedLeg::logPrior(double th) const {
  // (cos and sin only for the region prior, as boxReach(θ) takes them)
  return logPrior(th, region ? Eigen::Vector2d(std::cos(th), std::sin(th)) : Eigen::Vector2d::Zero());
}

double ConstantSpeedLeg::logPrior(double th, const Eigen::Vector2d& u) const {
  double lp = log_norm;
  if (region) {
    // log(2π R² / (2A)); R floored at 0.1 mm so that a corner estimated on the boundary stays finite.
    const double R = std::max(boxReach(region_c, region_lo, region_hi, u), 1e-4);
    lp += region_log_scale + 2.0 * std::log(R);
  }
  if (prior_mu.empty() || prior_weight <= 0.0) return lp;
  double g = 0.0;
  for (double mu : prior_mu) {
    // Wrapped to [−π, π] (σ ≪ π, one wrap suffices). remainder(x, 2π) is exact: x itself when |x| < π (the
    // float 2π is twice the float π, so the nearest integer to x / 2π is 0), x ∓ 2π when π < |x| < 2.5π (the
    // nearest integer is ±1, and the subtraction is exact: Sterbenz, 2π / 2 <= |x| <= 2 · 2π); the libm call
    // only elsewhere.
    const double x = th - mu, a = std::abs(x);
    const double d = a < core::kPi ? x
                     : a > core::kPi && a < 2.5 * core::kPi ? x - std::copysign(2.0 * core::kPi, x)
                                                            : std::remainder(x, 2.0 * core::kPi);
    if (d * d < 100.0 * prior_sigma * prior_sigma) g += std::exp(-0.5 * d * d / (prior_sigma * prior_sigma));  // (e^-50 beyond)
  }
  g *= std::sqrt(2.0 * core::kPi) / prior_sigma / static_cast<double>(prior_mu.size());
  return lp + std::log((1.0 - prior_weight) + prior_weight * g);
}

namespace {
// logLikelihood(θ) without the covariance: Λ(θ)'s Cholesky factor and the posterior mean of β are left in
// llt and mean (the covariance is llt.solve(I), formed where it is needed), the same operations in order.
// u = (cos θ, sin θ).
double factoredLogLikelihood(const ConstantSpeedLeg& leg, const Eigen::Vector2d& u, Eigen::LLT<Eigen::Matrix3d>& llt,
                             Eigen::Vector3d& mean) {
  Eigen::Matrix3d L = leg.P0_inv;
  L.topLeftCorner<2, 2>() += leg.A;
  const Eigen::Vector2d Btu = leg.Bt * u;
  L.block<2, 1>(0, 2) += Btu;
  L.block<1, 2>(2, 0) += Btu.transpose();
  L(2, 2) += u.dot(leg.Ctt * u);
  const Eigen::Vector3d P0_b0 = leg.P0_inv * leg.beta0;
  Eigen::Vector3d eta = P0_b0;
  eta.head<2>() += leg.Bz;
  eta(2) += u.dot(leg.Ctz);
  llt.compute(L);
  mean = llt.solve(eta);
  const double logdet = 2.0 * Eigen::Matrix3d(llt.matrixL()).diagonal().array().log().sum();
  return -0.5 * (leg.zz + leg.beta0.dot(P0_b0) - eta.dot(mean)) - 0.5 * logdet;
}
}  // namespace

double ConstantSpeedLeg::logLikelihood(double th, Eigen::Vector3d* m, Eigen::Matrix3d* cov) const {
  Eigen::LLT<Eigen::Matrix3d> llt;
  Eigen::Vector3d mean;
  const double ll = factoredLogLikelihood(*this, Eigen::Vector2d(std::cos(th), std::sin(th)), llt, mean);
  if (m != nullptr) *m = mean;
  if (cov != nullptr) *cov = llt.solve(Eigen::Matrix3d::Identity());
  return ll;
}

namespace {
// The parts of log p(z | θ) that every θ shares in the Schur-complement form (logEvidence, below), and the
// per-θ terms σ(θ) and t(θ) = −½ (base − r²/σ): log p(z | θ) = t − ½ (log det M + log σ).
struct SchurForm {
  explicit SchurForm(const ConstantSpeedLeg& leg) {
    const Eigen::Matrix2d M = leg.P0_inv.topLeftCorner<2, 2>() + leg.A;
    const Eigen::LLT<Eigen::Matrix2d> llt_M(M);
    Mi = llt_M.solve(Eigen::Matrix2d::Identity());
    logdet_M = 2.0 * Eigen::Matrix2d(llt_M.matrixL()).diagonal().array().log().sum();
    P0_b0 = leg.P0_inv * leg.beta0;
    const Eigen::Vector2d eta_c = P0_b0.head<2>() + leg.Bz;
    g = Mi * eta_c;
    base = leg.zz + leg.beta0.dot(P0_b0) - eta_c.dot(g);
    P0_cs = leg.P0_inv.block<2, 1>(0, 2);
  }
  /// σ_k and t_k at u_k = (cos[k], sin[k]), k < n. Written out per θ in scalars so that the compiler can run
  /// several θ at once: every product of two and sum of two terms is Eigen's (b = P₀⁻¹_cs + B_τ u, σ =
  /// P₀⁻¹_ss + uᵀ(C_ττ u) − bᵀ(M⁻¹ b), r = (P₀⁻¹β₀)_s + uᵀC_τz − bᵀg), so each value is the same to the last bit.
  void at(const ConstantSpeedLeg& leg, const double* cos, const double* sin, std::size_t n, double* schur,
          double* quad) const {
    const double bt00 = leg.Bt(0, 0), bt01 = leg.Bt(0, 1), bt10 = leg.Bt(1, 0), bt11 = leg.Bt(1, 1);
    const double ct00 = leg.Ctt(0, 0), ct01 = leg.Ctt(0, 1), ct10 = leg.Ctt(1, 0), ct11 = leg.Ctt(1, 1);
    const double mi00 = Mi(0, 0), mi01 = Mi(0, 1), mi10 = Mi(1, 0), mi11 = Mi(1, 1);
    const double p0 = P0_cs(0), p1 = P0_cs(1), c = leg.P0_inv(2, 2), e = P0_b0(2);
    const double cz0 = leg.Ctz(0), cz1 = leg.Ctz(1), g0 = g(0), g1 = g(1), bs = base;
    for (std::size_t k = 0; k < n; ++k) {
      const double u0 = cos[k], u1 = sin[k];
      const double b0 = p0 + (bt00 * u0 + bt01 * u1), b1 = p1 + (bt10 * u0 + bt11 * u1);
      const double w0 = ct00 * u0 + ct01 * u1, w1 = ct10 * u0 + ct11 * u1;
      const double m0 = mi00 * b0 + mi01 * b1, m1 = mi10 * b0 + mi11 * b1;
      const double sk = c + (u0 * w0 + u1 * w1) - (b0 * m0 + b1 * m1);
      const double r = e + (u0 * cz0 + u1 * cz1) - (b0 * g0 + b1 * g1);
      schur[k] = sk;
      quad[k] = -0.5 * (bs - r * r / sk);
    }
  }
  Eigen::Matrix2d Mi;
  double logdet_M = 0.0, base = 0.0;
  Eigen::Vector3d P0_b0;
  Eigen::Vector2d g, P0_cs;
};

// Which points of a θ grid can be skipped: those whose exp(ll_k − top) is +0, top = max_k ll_k. ll_k =
// t_k − ½ (log det M + log σ_k) + prior_k (SchurForm); exp(x) is +0 exactly for x < −745.2 (under half the
// least subnormal). With σ_min = min_k σ_k, u_k = t_k − ½ (log det M + log σ_min) + prior_k >= ll_k; a point
// whose u_k is below `exact(arg)` − margin, arg the point of highest u_k and exact(k) its ll as the caller
// evaluates it, is below top − margin too: margin >= 760, as u_k, ll_k and the caller's value of it differ by
// rounding only (far below 15). The bounds are left in u; skip[k] = 1 for a skipped point. NaN bounds are not skipped. Returns arg.
template <typename Exact>
std::size_t skippable(const SchurForm& form, const std::vector<double>& schur, const std::vector<double>& quad,
               const std::vector<double>& prior, double margin, const Exact& exact, std::vector<double>& u,
               std::vector<unsigned char>& skip) {
  const std::size_t n = schur.size();
  // min over the non-NaN σ_k, in four independent chains (the order does not change a minimum; NaN is skipped by
  // std::min(acc, NaN) in any chain, and ±0 give the same log).
  double acc[4] = {std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
                   std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
  std::size_t k4 = 0;
  for (; k4 + 4 <= n; k4 += 4) {
    for (std::size_t l = 0; l < 4; ++l) acc[l] = std::min(acc[l], schur[k4 + l]);
  }
  for (; k4 < n; ++k4) acc[0] = std::min(acc[0], schur[k4]);
  const double schur_min = std::min(std::min(acc[0], acc[1]), std::min(acc[2], acc[3]));
  const double log_schur_min = std::log(schur_min);
  u.resize(n);
  skip.resize(n);
  std::size_t arg = 0;
  for (std::size_t k = 0; k < n; ++k) {
    u[k] = quad[k] - 0.5 * (form.logdet_M + log_schur_min) + prior[k];
    if (u[k] > u[arg]) arg = k;
  }
  const double cut = exact(arg) - margin;
  for (std::size_t k = 0; k < n; ++k) skip[k] = k != arg && u[k] < cut;
  return arg;
}
}  // namespace

// log p(measurements | leg) up to the terms every candidate corner time shares (Σ log det 2πR_i, and
// −½ log det P₀ when P₀ is the same): log of the mean over θ of p(z | θ) p(θ) 2π, on a grid of
// `points` (the rectangle rule, exact to e^(−2π² σ²/h²) for a periodic integrand of width σ, step h).
// Every θ shares Λ's top-left block M = P₀⁻¹_cc + A, so log p(z | θ) is evaluated through the Schur
// complement of M (the same value as logLikelihood(θ), a few flops per θ instead of a 3x3 factorisation):
//   b = P₀⁻¹_cs + B_τ u, c = P₀⁻¹_ss + uᵀ C_ττ u, η = (η_c, η_s), g = M⁻¹ η_c,
//   ηᵀ Λ⁻¹ η = η_cᵀ g + (η_s − bᵀ g)² / σ,  log det Λ = log det M + log σ,  σ = c − bᵀ M⁻¹ b.
// Only the points that add to the sum (skippable) need their log σ and exp: the same top and the same sum,
// so the same value, as evaluating every point (test PlanarTargetFilter.LegEvidenceAndMomentsSkipOnlyPointsThatAddNothing).
double ConstantSpeedLeg::logEvidence(int points) const {
  const SchurForm form(*this);
  // The grid's cos and sin (the same θ_k, so the same values) are kept per thread for the last grid size;
  // logPrior comes from the leg's table when it has one of this size (made from the same prior fields).
  const UnitGrid& unit = unitGrid(points, true);
  const double* table = log_prior_evidence && static_cast<int>(log_prior_evidence->size()) == points
                            ? log_prior_evidence->data() : nullptr;
  thread_local std::vector<double> quad, schurs, priors, ll;
  thread_local std::vector<unsigned char> skip;
  const auto size = static_cast<std::size_t>(points);
  quad.resize(size);
  schurs.resize(size);
  priors.resize(size);
  form.at(*this, unit.cos.data(), unit.sin.data(), size, schurs.data(), quad.data());
  for (int k = 0; k < points; ++k)
    priors[static_cast<std::size_t>(k)] = table != nullptr ? table[k] : logPrior(-core::kPi + 2.0 * core::kPi * k / points);
  const auto exact = [&](std::size_t k) { return quad[k] - 0.5 * (form.logdet_M + std::log(schurs[k])) + priors[k]; };
  skippable(form, schurs, quad, priors, 760.0, exact, ll, skip);
  double top = -std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k < size; ++k) {
    if (skip[k]) continue;
    ll[k] = exact(k);
    top = std::max(top, ll[k]);
  }
  double sum = 0.0;
  for (std::size_t k = 0; k < size; ++k) {
    if (!skip[k]) sum += std::exp(ll[k] - top);
  }
  return top + std::log(sum / points);
}

estimation::StateEstimate ConstantSpeedLeg::moments(double t) const {
  struct Point {
    double th = 0.0, ll = 0.0;
    Eigen::Vector2d u = Eigen::Vector2d::Zero();  ///< (cos θ, sin θ)
    Eigen::Vector3d m = Eigen::Vector3d::Zero();
    Eigen::LLT<Eigen::Matrix3d> llt;  ///< Λ(θ)'s factor: the covariance Λ⁻¹ is solved where it is used
    bool skipped = false;             ///< exp(ll − any grid maximum) is +0 (ll not evaluated)
  };
  const auto evaluate = [&](Point& pt, double th, const double* prior) {
    pt.th = th;
    pt.u = Eigen::Vector2d(std::cos(th), std::sin(th));  // (once for the likelihood, the prior and the moments)
    pt.skipped = false;
    pt.ll = factoredLogLikelihood(*this, pt.u, pt.llt, pt.m) + (prior != nullptr ? *prior : logPrior(th, pt.u));
  };
  // Grid over θ: 180 points on the circle, then refined (±2 steps of the previous grid, 81 points)
  // while one point holds more than 30 % of the mass, so a narrow posterior is still resolved. The first
  // grid's logPrior comes from the leg's table when it has one (the same values). On the first grid only the
  // points that can weigh are evaluated (skippable, through the Schur form, with a margin of 800 for the rounding
  // of logLikelihood's form): the others have exp(ll − max) = +0 in the mass and weights below 1e-12, as when
  // every point is evaluated (test PlanarTargetFilter.LegEvidenceAndMomentsSkipOnlyPointsThatAddNothing).
  double lo = -core::kPi, step = 2.0 * core::kPi / 180.0;
  int count = 180;
  const double* table = log_prior_moments && log_prior_moments->size() == 180 ? log_prior_moments->data() : nullptr;
  thread_local std::vector<Point> grid;
  thread_local std::vector<double> quad, schurs, priors, bound;
  thread_local std::vector<unsigned char> skip;
  for (int level = 0; level < 6; ++level) {
    grid.resize(static_cast<std::size_t>(count));
    if (level == 0) {
      const SchurForm form(*this);
      const UnitGrid& unit = unitGrid(180, false);
      quad.resize(180);
      schurs.resize(180);
      priors.resize(180);
      form.at(*this, unit.cos.data(), unit.sin.data(), 180, schurs.data(), quad.data());
      for (std::size_t k = 0; k < 180; ++k) {
        priors[k] = table != nullptr ? table[k]
                                     : logPrior(lo + step * static_cast<double>(k), Eigen::Vector2d(unit.cos[k], unit.sin[k]));
      }
      const auto exact = [&](std::size_t k) {
        evaluate(grid[k], lo + step * static_cast<double>(k), table != nullptr ? table + k : nullptr);
        return grid[k].ll;
      };
      const std::size_t arg = skippable(form, schurs, quad, priors, 800.0, exact, bound, skip);  // (evaluates grid[arg])
      for (std::size_t k = 0; k < 180; ++k) {
        Point& pt = grid[k];
        if (skip[k]) {
          pt.th = lo + step * static_cast<double>(k);
          pt.ll = -std::numeric_limits<double>::infinity();
          pt.skipped = true;
        } else if (k != arg) {
          evaluate(pt, lo + step * static_cast<double>(k), table != nullptr ? table + k : nullptr);
        }
      }
    } else {
      for (int k = 0; k < count; ++k) evaluate(grid[static_cast<std::size_t>(k)], lo + step * k, nullptr);
    }
    const auto best = std::max_element(grid.begin(), grid.end(), [](const Point& a, const Point& b) { return a.ll < b.ll; });
    double total = 0.0;
    for (const Point& pt : grid) {
      if (!pt.skipped) total += std::exp(pt.ll - best->ll);
    }
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
    if (pt.skipped) continue;
    const double w = std::exp(pt.ll - top);
    if (w < 1e-12) continue;
    const Eigen::Vector2d& u = pt.u;
    Eigen::Matrix<double, 4, 3> J = Eigen::Matrix<double, 4, 3>::Zero();  // (p, v) = J β
    J.topLeftCorner<2, 2>() = Eigen::Matrix2d::Identity();
    J.block<2, 1>(0, 2) = tau * u;
    J.block<2, 1>(2, 2) = u;
    const Eigen::Vector4d x = J * pt.m;
    const Eigen::Matrix3d cov = pt.llt.solve(Eigen::Matrix3d::Identity());
    wsum += w;
    mean += w * x;
    second += w * (x * x.transpose() + J * cov * J.transpose());
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
  const UnitGrid& unit = unitGrid(points, evidence);
  const double step = 2.0 * core::kPi / points;
  for (int k = 0; k < points; ++k) {
    const auto kk = static_cast<std::size_t>(k);
    out[kk] = logPrior(evidence ? -core::kPi + 2.0 * core::kPi * k / points : -core::kPi + step * k,
                       Eigen::Vector2d(unit.cos[kk], unit.sin[kk]));
  }
  return out;
}

double ConstantSpeedLeg::logPriorNormalisation(int points) const {
  const UnitGrid& unit = unitGrid(points, true);
  double sum = 0.0;
  for (int k = 0; k < points; ++k) {
    const auto kk = static_cast<std::size_t>(k);
    sum += std::exp(logPrior(-core::kPi + 2.0 * core::kPi * k / points, Eigen::Vector2d(unit.cos[kk], unit.sin[kk])));
  }
  return -std::log(sum / points);
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
  // (LegBayesFactors::Candidate holds the sums; LegBayesFactors keeps them from one scan to the next.)
  LegBayesFactors::Candidate c(history[static_cast<std::size_t>(j)]);
  for (std::size_t i = static_cast<std::size_t>(j) + 1; i < history.size(); ++i) c.add(history[i]);
  return c.value(make, turn_prior_sigma_deg);
}

LegBayesFactors::Candidate::Candidate(const PlanarSnapshot& sj) : serial(sj.serial), last(sj.serial) {
  x = sj.state.x().head<4>();
  Eigen::Matrix4d P = sj.state.P().topLeftCorner<4, 4>();
  P.diagonal().array() += 1e-10;
  const auto llt_P = P.llt();
  P_inv = llt_P.solve(Eigen::Matrix4d::Identity());
  logdet_P = 2.0 * Eigen::Matrix4d(llt_P.matrixL()).diagonal().array().log().sum();
  P_pos = P.topLeftCorner<2, 2>();
  direction = velocityDirection(sj.state);
  L = P_inv;
  eta = P_inv * x;
  leg.t_c = sj.t;
}

void LegBayesFactors::Candidate::add(const PlanarSnapshot& si) {
  const Eigen::Matrix2d Ri = si.R.inverse();
  Eigen::Matrix<double, 2, 4> H;
  H << Eigen::Matrix2d::Identity(), (si.t - leg.t_c) * Eigen::Matrix2d::Identity();
  L += H.transpose() * Ri * H;
  eta += H.transpose() * (Ri * si.z);
  zz += si.z.dot(Ri * si.z);
  leg.add(si.t, si.z, si.R);
  last = si.serial;
}

double LegBayesFactors::Candidate::value(const LegFactory& make, double turn_prior_sigma_deg) const {
  ConstantSpeedLeg l = make(leg.t_c, x.head<2>(), P_pos, direction);
  l.copySums(leg);
  const auto llt_L = L.llt();
  const double logdet_L = 2.0 * Eigen::Matrix4d(llt_L.matrixL()).diagonal().array().log().sum();
  const double straight = -0.5 * (zz + x.dot(P_inv * x) - eta.dot(llt_L.solve(eta))) - 0.5 * logdet_L - 0.5 * logdet_P;
  const double logdet_P0 = -std::log(l.P0_inv.determinant());
  return l.logEvidence(legEvidencePoints(turn_prior_sigma_deg)) - 0.5 * logdet_P0 - straight;
}

void LegBayesFactors::sync(const PlanarHistory& history) {
  // Kept: the candidates whose corner and last summed measurement are both still in the history. The
  // history only grows at its end and loses its oldest measurements (or is made anew, with new serials),
  // so the measurements between the two are still the ones that were summed.
  const auto in_history = [&history](std::uint64_t serial) {
    const auto it = std::lower_bound(history.begin(), history.end(), serial,
                                     [](const PlanarSnapshot& s, std::uint64_t v) { return s.serial < v; });
    return it != history.end() && it->serial == serial;
  };
  candidates_.erase(std::remove_if(candidates_.begin(), candidates_.end(),
                                   [&](const Candidate& c) { return !in_history(c.serial) || !in_history(c.last); }),
                    candidates_.end());
}

double LegBayesFactors::operator()(const PlanarHistory& history, int j, const LegFactory& make,
                                   double turn_prior_sigma_deg) {
  const PlanarSnapshot& sj = history[static_cast<std::size_t>(j)];
  auto it = std::lower_bound(candidates_.begin(), candidates_.end(), sj.serial,
                             [](const Candidate& c, std::uint64_t v) { return c.serial < v; });
  if (it == candidates_.end() || it->serial != sj.serial) it = candidates_.insert(it, Candidate(sj));
  // The measurements after the last one summed (sync() keeps only candidates whose last one is in the history).
  const auto after = std::upper_bound(history.begin() + j, history.end(), it->last,
                                      [](std::uint64_t v, const PlanarSnapshot& s) { return v < s.serial; });
  for (auto s = after; s != history.end(); ++s) it->add(*s);
  return it->value(make, turn_prior_sigma_deg);
}

const ConstantSpeedLeg* LegBayesFactors::legSums(const PlanarHistory& history, int j) const {
  const std::uint64_t serial = history[static_cast<std::size_t>(j)].serial;
  const auto it = std::lower_bound(candidates_.begin(), candidates_.end(), serial,
                                   [](const Candidate& c, std::uint64_t v) { return c.serial < v; });
  if (it == candidates_.end() || it->serial != serial || it->last != history.back().serial) return nullptr;
  return &it->leg;
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
