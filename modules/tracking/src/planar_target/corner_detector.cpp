// Corner detection and the corner settings: model in the header.
#include "viewline/tracking/planar_target/corner_detector.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>

#include "viewline/tracking/planar_target/config.h"

namespace viewline::tracking {

JumpScan scanForJump(const PlanarHistory& history, const JumpScanSettings& settings,
                     const std::function<double(int)>& leg_bayes_factor, const std::vector<double>& region_odds) {
  // Likelihood-ratio test for a step Δv in velocity at one of the recent measurement times t_j, the
  // position staying continuous (a corner of a polyline at constant speed). For a candidate j, the
  // measurements of the window are compared with the state x(j|j) run by the model to their times
  // (forwards and backwards), r_i = z_i − p̂_j(τ_i), τ_i = t_i − t_j. Per axis a, with weights
  // w_i = 1 / R_i,aa, the residuals are fitted by
  //   H0: r = α + β τ + γ τ²            (x(j|j)'s own position, velocity and turn-rate errors)
  //   H1: r = α + β τ + γ τ² + Δv_a τ₊  (τ₊ = max(τ, 0): a kink at t_j)
  // α, β free, γ with the prior N(0, (½ |v_j| σ_ω,j)²) of x(j|j)'s turn-rate error (CT/IMM state;
  // γ = 0 for CV/CA), by penalised least squares; ℓ_j, the drop of the penalised weighted residual
  // sum from H0 to H1 summed over both axes, is about χ² with 2 dof when there is no jump (for one
  // candidate; the scan over candidates and steps makes false jumps more frequent: at 15, 3 over
  // four straight 12 s tracks of 30 measurements/s with a 3 s window, in the unit test).
  // The largest ℓ_j above jump_threshold, with at least jump_min_samples measurements on each side
  // of t_j, declares a jump at t_j: the filter goes back
  // to x(j|j), its velocity (and turn rate or acceleration) prior is re-opened as at initialisation,
  // the position kept, and the measurements after t_j are processed again. x(k|k) stays a filtered
  // estimate (it uses measurements up to t_k only).
  JumpScan out;
  const int n = static_cast<int>(history.size());
  const int m = settings.min_samples;
  const bool soft = settings.soft;
  // Hard test: m <= j < n - m. Soft mixture: every j with m measurements before and, with the legs' Bayes
  // factors, up to the last one (a jump at or just before the last measurement is what a new corner first is:
  // leaving those out made the estimate's velocity sure of the old leg for the corner's first samples, the
  // random path's NEES 80-100); with the kinks' (before the speed is learnt), 2 after, as the restart a kink
  // hypothesis runs re-opens the velocity to init_velocity_sigma, not to the jump prior jump_prior_sigma: with
  // fewer measurements after t_j its velocity would be that restart prior's, not the jump model's.
  if (n < (soft ? m + 3 : 2 * m + 1)) return out;
  double best = settings.threshold;
  int best_j = -1;
  std::vector<double> tau(static_cast<std::size_t>(n));
  std::vector<Eigen::Vector2d> r(static_cast<std::size_t>(n));
  // w_i = 1 / R_i,aa per axis, the same for every candidate j (computed once).
  std::vector<Eigen::Vector2d> w(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    const Eigen::Matrix2d& R = history[static_cast<std::size_t>(i)].R;
    w[static_cast<std::size_t>(i)] = Eigen::Vector2d(1.0 / R(0, 0), 1.0 / R(1, 1));
  }
  std::vector<std::pair<double, int>>& log_odds = out.log_odds;  // soft: log(π_j BF_j), j
  const double prior_precision = soft ? 1.0 / (settings.prior_sigma * settings.prior_sigma) : 0.0;
  const bool leg_bf = soft && static_cast<bool>(leg_bayes_factor);  // the soft mixture's Bayes factors from legs, not kinks
  // What the candidates need: the test statistic l decides only without the posterior decision (with it the
  // posterior below picks the jump), and the kink fits' Bayes factor only without leg_bayes_factor. The fits
  // nothing reads are skipped (the shipped mixture: posterior decision and, once the speed is learnt, the
  // legs' Bayes factors, so no fit at all); the values that are computed are unchanged.
  const bool need_test = !(soft && settings.posterior_decision);
  const bool need_kink_bf = soft && !leg_bf;
  for (int j = m; j + (soft ? (leg_bf ? 0 : 2) : m) < n; ++j) {
    const PlanarSnapshot& sj = history[static_cast<std::size_t>(j)];
    const Eigen::VectorXd& xj = sj.state.x();
    for (int i = 0; i < n && (need_test || need_kink_bf); ++i) {
      const PlanarSnapshot& si = history[static_cast<std::size_t>(i)];
      const double ti = si.t - sj.t;
      tau[static_cast<std::size_t>(i)] = ti;
      if (xj.size() == 4) {  // extrapolatePosition's constant velocity, inline: p + τ v
        r[static_cast<std::size_t>(i)] = si.z - Eigen::Vector2d(xj(0) + ti * xj(2), xj(1) + ti * xj(3));
      } else {
        r[static_cast<std::size_t>(i)] = si.z - extrapolatePosition(xj, ti);
      }
    }
    // Prior std of γ: the turn-rate uncertainty of x(j|j) bends the extrapolation by ½ |v| δω τ².
    double sigma_gamma = 0.0;
    if (xj.size() == 5) sigma_gamma = 0.5 * xj.segment<2>(2).norm() * std::sqrt(std::max(sj.state.P()(4, 4), 0.0));
    const bool curved = sigma_gamma > 0.0;  // (CV/CA: no γ column)
    const double gamma_weight = curved ? 1.0 / (sigma_gamma * sigma_gamma) : 1.0;
    double l = 0.0, log_bf = 0.0;
    if (need_test || need_kink_bf) {
      // Penalised least squares (γ with its prior, α, β and Δv free) under H0 and H1, per axis a:
      // min ‖r − X θ‖²_W + θᵀ Λ θ = rᵀ W r − (Xᵀ W r)ᵀ (Xᵀ W X + Λ)⁻¹ Xᵀ W r.
      // M = Σ w_i x_i x_iᵀ, g = Σ w_i r_i x_i with x_i = (1, τ, c, p), c = τ² (curved) or 0, p = max(τ, 0).
      // Each entry is summed over i in order with the rounding of Eigen's `M += w * x * xᵀ` (entry (k, l) adds
      // x_l (w x_k)) and `g += w r x` ((w r) x_k), so M and g are the same to the last bit; the terms that
      // are ±0 (c = 0 when not curved, p = 0 for τ <= 0) are skipped: a sum that starts at +0 is not changed
      // by them. Only the distinct products are formed (x_0 = 1: (0, l) and (l, 0) are both w x_l; p = τ
      // where it is not skipped, so (1, 3), (3, 1) and (3, 3) all add τ (w τ)). Both axes run in one pass,
      // one per lane of a 2-vector: each lane does the scalar operations in the scalar order.
      using A2 = Eigen::Array2d;
      A2 s00 = A2::Zero(), s01 = A2::Zero(), s02 = A2::Zero(), s03 = A2::Zero(), s11 = A2::Zero(), s12 = A2::Zero(),
         s13 = A2::Zero(), s21 = A2::Zero(), s22 = A2::Zero(), s23 = A2::Zero(), s32 = A2::Zero();
      A2 h0 = A2::Zero(), h1 = A2::Zero(), h2 = A2::Zero(), h3 = A2::Zero();
      for (int i = 0; i < n; ++i) {
        const A2 wi = w[static_cast<std::size_t>(i)].array();
        const double ti = tau[static_cast<std::size_t>(i)];
        const A2 wr = wi * r[static_cast<std::size_t>(i)].array();
        const A2 wt = wi * ti;
        s00 += wi;
        s01 += wt;
        s11 += ti * wt;
        h0 += wr;
        h1 += wr * ti;
        A2 wc = A2::Zero();
        const double ci = curved ? ti * ti : 0.0;
        if (curved) {
          wc = wi * ci;
          s02 += wc;
          s12 += ci * wt;
          s21 += ti * wc;
          s22 += ci * wc;
          h2 += wr * ci;
        }
        if (ti > 0.0) {
          s03 += wt;  // w p, p = τ
          s13 += ti * wt;
          h3 += wr * ti;
          if (curved) {
            s23 += ti * wc;
            s32 += ci * wt;
          }
        }
      }
      for (int a = 0; a < 2; ++a) {
        Eigen::Matrix4d M;
        M << s00(a), s01(a), s02(a), s03(a),
             s01(a), s11(a), s12(a), s13(a),
             s02(a), s21(a), s22(a), s23(a),
             s03(a), s13(a), s32(a), s13(a);
        Eigen::Vector4d g(h0(a), h1(a), h2(a), h3(a));
        M(2, 2) += gamma_weight;
        const Eigen::Vector3d g0 = g.head<3>();
        const auto ldlt0 = M.topLeftCorner<3, 3>().ldlt();
        const double fit0 = g0.dot(ldlt0.solve(g0));
        if (need_test) {
          const double fit1 = g.dot(M.ldlt().solve(g));
          l += fit1 - fit0;
        }
        if (need_kink_bf) {
          // Bayes factor with Δv_a ~ N(0, jump_prior_sigma²) (α, β flat under both hypotheses):
          // log BF_a = ½ (fit1' − fit0) − ½ log(det M1' / det M0) − ½ log σ_Δ², M1' = M1 + diag(0, 0, 0, 1/σ_Δ²).
          Eigen::Matrix4d M1 = M;
          M1(3, 3) += prior_precision;
          const auto ldlt1 = M1.ldlt();
          const double fit1p = g.dot(ldlt1.solve(g));
          const double logdet1 = ldlt1.vectorD().array().log().sum(), logdet0 = ldlt0.vectorD().array().log().sum();
          log_bf += 0.5 * (fit1p - fit0) - 0.5 * (logdet1 - logdet0) + 0.5 * std::log(prior_precision);
        }
      }
    }
    if (j + m < n && l > best) {
      best = l;
      best_j = j;
    }
    if (soft) {
      if (leg_bf) log_bf = leg_bayes_factor(j);
      // Prior probability of a jump at t_j (and nowhere else in the window): rate × the interval it stands for.
      const double dt_j = sj.t - history[static_cast<std::size_t>(j - 1)].t;
      const double log_prior = region_odds.empty() ? std::log(std::max(settings.jump_rate * dt_j, 1e-300))
                                                   : region_odds[static_cast<std::size_t>(j)];
      log_odds.emplace_back(log_prior + log_bf, j);
    }
  }
  if (settings.posterior_decision && soft) {
    // Decide by the mixture's posterior instead of the test: a jump once the hypotheses "a jump at t_j"
    // with jump_min_samples measurements after t_j hold more than jump_posterior of the posterior mass
    // (against no jump and the later t_j), at the most probable of them. The prior odds (jump_rate or
    // the waypoint region) thus count: a corner is declared sooner where one is likely, and a run of
    // noise mid-leg needs more evidence.
    double top = 0.0;
    for (const auto& entry : log_odds) top = std::max(top, entry.first);
    double total = std::exp(-top);
    for (const auto& entry : log_odds) total += std::exp(entry.first - top);
    double mass = 0.0, best_p = 0.0;
    int arg = -1;
    for (const auto& [lo, j] : log_odds) {
      if (j + m >= n) continue;
      const double p = std::exp(lo - top) / total;
      mass += p;
      if (p > best_p) {
        best_p = p;
        arg = j;
      }
    }
    best_j = mass > settings.posterior_mass ? arg : -1;
  }
  out.jump = best_j;
  return out;
}

void CornerSettings::note(core::Timestamp t, const Eigen::Matrix2d& R) {
  last_R_ = R;
  if (std::isfinite(last_t_) && t > last_t_) {
    intervals_.push_back(t - last_t_);
    if (intervals_.size() > 16) intervals_.erase(intervals_.begin());
  }
  if (!std::isfinite(last_t_) || t > last_t_) last_t_ = t;
}

int CornerSettings::minSamples(double speed) const {
  if (min_samples_) return *min_samples_;
  // "auto": round(k ρ^(2/3)), ρ = σ / (ŝ Δt) (header, "Noise-scaled corner settings").
  const double sigma = noiseSigma();
  double dt = 0.0;
  if (!intervals_.empty()) {
    std::vector<double> sorted = intervals_;
    std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2), sorted.end());
    dt = sorted[sorted.size() / 2];
  }
  if (!(speed > 0.0) || !(dt > 0.0) || !(sigma > 0.0)) return kAutoJumpSamplesMax;
  const double m = std::round(kAutoJumpSamplesScale * std::cbrt(std::pow(sigma / (speed * dt), 2)));
  return static_cast<int>(std::clamp(m, 2.0, static_cast<double>(kAutoJumpSamplesMax)));
}

double CornerSettings::cornerSigma() const {
  if (corner_sigma_) return *corner_sigma_;
  return kAutoCornerSigmaPerNoise * noiseSigma();
}

double CornerSettings::noiseSigma() const { return std::sqrt(0.5 * std::max(last_R_.trace(), 0.0)); }

}  // namespace viewline::tracking
