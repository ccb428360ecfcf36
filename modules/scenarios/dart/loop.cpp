#include "viewline/scenarios/dart/loop.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "viewline/core/error.h"
#include "viewline/core/interrupt.h"
#include "viewline/core/random.h"
#include "viewline/estimation/consistency.h"
#include "viewline/runtime/scheduler.h"
#include "viewline/scenarios/dart/recording.h"
#include "viewline/tracking/image_ekf.h"

namespace viewline::scenarios {

using tracking::Fate;
using tracking::GateKind;
using tracking::Matrix6;
using tracking::Refusal;
using tracking::TrackerConfig;
using tracking::ViewlineTracker;

std::vector<std::string> dartLogColumns() {
  return {"experiment", "run",    "id",     "camera", "t",     "u",     "v",     "outlier", "fate",
          "true_x",     "true_y", "true_z", "est_x",  "est_y", "est_z", "est_vx", "est_vy", "est_vz"};
}

std::vector<std::string> dartLogRow(const DartLogRow& r) {
  const DartDetection& d = r.det;
  return {r.experiment,
          std::to_string(r.run),
          std::to_string(d.m.id),
          std::to_string(d.m.camera),
          std::to_string(d.m.t),
          std::to_string(d.m.uv.x()),
          std::to_string(d.m.uv.y()),
          d.outlier ? "1" : "0",
          tracking::toString(r.fate),
          std::to_string(d.truth[0]),
          std::to_string(d.truth[1]),
          std::to_string(d.truth[2]),
          std::to_string(r.estimate[0]),
          std::to_string(r.estimate[1]),
          std::to_string(r.estimate[2]),
          std::to_string(r.estimate[3]),
          std::to_string(r.estimate[4]),
          std::to_string(r.estimate[5])};
}

runtime::InnovationRecord innovationRecord(const tracking::ImageUpdate& u, const std::string& channel) {
  runtime::InnovationRecord r;
  r.channel = channel;
  r.t = u.m.t;
  r.id = u.m.id;
  r.source = u.m.camera;
  r.rows = 2;
  r.innovation = u.innovation;
  r.S = u.S;
  r.nis = u.nis;
  r.decision = u.decision;
  return r;
}

namespace {

Eigen::Vector3d randomDirection(core::Rng& rng) {
  Eigen::Vector3d v(core::gaussian(rng), core::gaussian(rng), core::gaussian(rng));
  return v.normalized();
}

/// What the experiments pool over the runs.
struct Pools {
  estimation::ConsistencyStats nees6, nees3;
  PooledError a_settled, a_final, b_dir, b_mah, b_ekf, c_exact, c_offset, c_ekf, d_scenario;
  double update_time = 0.0;
  std::size_t update_count = 0, measurements = 0;
  std::vector<double> convergence, convergence_bound;
};

/// One run's experiments; the tracker configurations are derived once per call of the loop.
class DartRun {
public:
  DartRun(const DartScenarioConfig& cfg, const std::vector<core::Camera>& cams, const TrackerConfig& exact,
          const TrackerConfig& offset, const DartRunCallbacks& cb, Pools& pools, DartSummary& sum, DartFlights& flights)
      : cfg_(cfg), cams_(cams), exact_(exact), offset_(offset), cb_(cb), p_(pools), sum_(sum), flights_(flights) {}

  void run(int run, std::uint64_t run_seed) {
    run_ = run;
    flights_.beginRun(run);  // simulated, recorded or replayed flights (recording.h)
    consistency(core::deriveSeed(run_seed, 1));
    gates(core::deriveSeed(run_seed, 2));
    async(core::deriveSeed(run_seed, 3));
    scenario(core::deriveSeed(run_seed, 5));
    singleCamera(core::deriveSeed(run_seed, 4));
    flights_.endRun();
  }

private:
  // A settled measurement counts in the RMSE when the tracker reports an estimate (a confirmed
  // track, tracker.h's robust start); otherwise it is counted as unreported.
  void settled(PooledError& p, std::size_t i, const estimation::StateEstimate& s, const DartDetection& d,
               bool reported = true) const {
    if (i < cfg_.settled_index) return;
    if (reported)
      p.add(s, d.truth);
    else
      ++p.unreported;
  }
  void log(const char* exp, const DartDetection& d, Fate fate, const estimation::StateEstimate& s) const {
    if (!cb_.log || s.dim() != 6) return;
    cb_.log(DartLogRow{exp, run_, d, fate, s.x()});
  }

  // A: alternating cameras, no outliers: NEES and RMSE / PCRLB.
  void consistency(std::uint64_t seed) {
    core::Rng rng = core::makeRng(seed);
    const DartFlight f = flights_.flight("A_alternating", cfg_, cams_, DartClockMode::Alternating, 0.0, rng);
    const std::vector<double> bound = positionPcrlb(cfg_, cams_, f);
    ViewlineTracker tr(cams_, exact_);
    p_.measurements += f.detections.size();
    for (std::size_t i = 0; i < f.detections.size(); ++i) {
      const DartDetection& d = f.detections[i];
      tr.submit(d.m);
      const auto& s = tr.state();
      log("A_alternating", d, tr.outcome(d.m.id) ? tr.outcome(d.m.id)->fate : Fate::Gated, s);
      const double se = (s.x().head<3>() - d.truth.head<3>()).squaredNorm();
      if (i >= cfg_.settled_index && !tr.confirmed()) ++p_.a_settled.unreported;
      if (!tr.confirmed()) continue;
      if (i >= cfg_.settled_index) {
        p_.a_settled.se += se;
        p_.a_settled.bound += bound[i];
        ++p_.a_settled.n;
      }
      if (i == cfg_.nees_index) {
        p_.nees6.add(estimation::nees(s, d.truth), 6.0);
        p_.nees3.add(estimation::nees(s, d.truth, {0, 1, 2}), 3.0);
      }
      if (i + 1 == f.detections.size()) {
        p_.a_final.se += se;
        p_.a_final.bound += bound[i];
        ++p_.a_final.n;
      }
    }
  }

  // B: alternating cameras with outliers: both gates, image EKF.
  void gates(std::uint64_t seed) {
    core::Rng rng = core::makeRng(seed);
    const DartFlight f = flights_.flight("B_gates", cfg_, cams_, DartClockMode::Alternating, cfg_.outlier_rate, rng);
    for (GateKind kind : {GateKind::Directional, GateKind::Mahalanobis}) {
      TrackerConfig tc = exact_;
      tc.gate.kind = kind;
      ViewlineTracker tr(cams_, tc);
      PooledError& p = kind == GateKind::Directional ? p_.b_dir : p_.b_mah;
      for (std::size_t i = 0; i < f.detections.size(); ++i) {
        tr.submit(f.detections[i].m);
        settled(p, i, tr.state(), f.detections[i], tr.confirmed());
      }
      (kind == GateKind::Directional ? sum_.gate_directional : sum_.gate_mahalanobis).restarts +=
          static_cast<std::size_t>(tr.trackState().restarts);
      countGate(kind == GateKind::Directional ? sum_.gate_directional : sum_.gate_mahalanobis, tr, f);
    }
    tracking::ImageSpaceEkf ekf(cams_, exact_);
    for (std::size_t i = 0; i < f.detections.size(); ++i) {
      ekf.submit(f.detections[i].m);
      settled(p_.b_ekf, i, ekf.state(), f.detections[i]);
    }
  }

  // C: free-running clocks with jitter, no outliers: exact vs Δt-offset vs image EKF.
  void async(std::uint64_t seed) {
    core::Rng rng = core::makeRng(seed);
    const DartFlight f = flights_.flight("C_async", cfg_, cams_, DartClockMode::FreeRunning, 0.0, rng);
    ViewlineTracker tr_exact(cams_, exact_), tr_offset(cams_, offset_);
    tracking::ImageSpaceEkf ekf(cams_, exact_);
    for (std::size_t i = 0; i < f.detections.size(); ++i) {
      const DartDetection& d = f.detections[i];
      const auto t0 = std::chrono::steady_clock::now();
      tr_exact.submit(d.m);
      p_.update_time += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      ++p_.update_count;
      tr_offset.submit(d.m);
      ekf.submit(d.m);
      settled(p_.c_exact, i, tr_exact.state(), d, tr_exact.confirmed());
      // The Δt-offset estimate lives at a grid instant: compare with the truth at the capture time.
      settled(p_.c_offset, i, tr_offset.predictAt(d.m.t), d, tr_offset.confirmed());
      settled(p_.c_ekf, i, ekf.state(), d);
    }
  }

  // D: the full scenario (free-running clocks, jitter, outliers) in capture order and in arrival
  // order (capture + U(0, late_max_delay)).
  void scenario(std::uint64_t seed) {
    core::Rng rng = core::makeRng(seed);
    const DartFlight f = flights_.flight("D_scenario", cfg_, cams_, DartClockMode::FreeRunning, cfg_.outlier_rate, rng);
    ViewlineTracker tr_exact(cams_, exact_);
    for (std::size_t i = 0; i < f.detections.size(); ++i) {
      const DartDetection& d = f.detections[i];
      tr_exact.submit(d.m);
      settled(p_.d_scenario, i, tr_exact.state(), d, tr_exact.confirmed());
      const auto o = tr_exact.outcome(d.m.id);
      log("D_scenario", d, o ? o->fate : Fate::Gated, tr_exact.state());
      if (cb_.telemetry != nullptr) publish(*cb_.telemetry, tr_exact, d);
    }
    sum_.scenario_gate.restarts += static_cast<std::size_t>(tr_exact.trackState().restarts);
    countGate(sum_.scenario_gate, tr_exact, f);
    // The same detections as a network delivers them: each arrives U(0, late_max_delay) after its
    // capture, and the clock hands them to the tracker in arrival order (ties: capture order).
    ViewlineTracker tr_late(cams_, exact_);
    runtime::Scheduler clock(0.0);
    clock.setPacing(cb_.pacing);
    double last_arrival = 0.0;
    for (std::size_t i = 0; i < f.detections.size(); ++i) {
      const double arrival =
          f.detections[i].m.t + flights_.draw("D_scenario", [&] { return core::uniform(rng, 0.0, cfg_.late_max_delay); });
      last_arrival = std::max(last_arrival, arrival);
      clock.at(arrival, runtime::priority::Delivery, [this, &tr_late, &d = f.detections[i]](double) {
        if (tr_late.submit(d.m) != Refusal::None) ++sum_.late_refused;
      });
    }
    clock.runUntil(last_arrival);
    sum_.late_inserted += tr_late.lateInserted();
    if (tr_exact.initialised() && tr_late.initialised()) {
      const double dx = (tr_exact.state().x() - tr_late.state().x()).cwiseAbs().maxCoeff();
      const double dP = (tr_exact.state().P() - tr_late.state().P()).cwiseAbs().maxCoeff();
      const double dt = std::abs(tr_exact.state().t() - tr_late.state().t());
      sum_.late_vs_inorder_max_diff = std::max({sum_.late_vs_inorder_max_diff, dx, dP, dt});
    }
    for (const DartDetection& d : f.detections) {
      const auto a = tr_exact.outcome(d.m.id), b = tr_late.outcome(d.m.id);
      if (a.has_value() != b.has_value() || (a && a->fate != b->fate)) ++sum_.late_outcome_mismatches;
    }
  }

  void publish(runtime::TelemetrySink& sink, const ViewlineTracker& tr, const DartDetection& d) const {
    const std::string camera = "camera" + std::to_string(d.m.camera);
    sink.measurement({camera, d.m.t, d.m.id, d.m.uv, Eigen::VectorXd::Constant(2, d.m.sigma_px)});
    if (!tr.lastUpdate()) return;  // refused
    sink.innovation(innovationRecord(*tr.lastUpdate(), "dart"));
    sink.estimate({"dart", tr.state().t(), tr.state().x(), tr.state().P()});
  }

  // E: one camera, prior far off, against a filter started at the truth.
  void singleCamera(std::uint64_t seed) {
    core::Rng rng = core::makeRng(seed);
    const DartFlight f = flights_.flight("E_single", cfg_, cams_, DartClockMode::SingleCamera, 0.0, rng);
    if (f.detections.empty()) return;
    TrackerConfig ref = exact_, off = exact_;
    ref.prior_mean = f.detections.front().truth;
    ref.prior_cov = cfg_.single_prior_std * cfg_.single_prior_std * Matrix6::Identity();
    off.prior_cov = ref.prior_cov;
    off.prior_mean = ref.prior_mean;
    const auto offset = [&] {
      return Eigen::Vector3d(core::uniform(rng, 0.0, cfg_.single_offset_max) * randomDirection(rng));
    };
    off.prior_mean.head<3>() += flights_.draw3("E_single", offset);
    off.prior_mean.tail<3>() += flights_.draw3("E_single", offset);
    ViewlineTracker tr_ref(cams_, ref), tr_off(cams_, off);
    std::size_t converged_after = 0;  // number of measurements after which it stays within tolerance
    for (std::size_t i = 0; i < f.detections.size(); ++i) {
      tr_ref.submit(f.detections[i].m);
      tr_off.submit(f.detections[i].m);
      const double diff = (tr_ref.state().x().head<3>() - tr_off.state().x().head<3>()).norm();
      if (diff > cfg_.single_tolerance) converged_after = i + 2;
    }
    if (converged_after > f.detections.size()) ++sum_.single_camera_not_converged;
    p_.convergence_bound.push_back(static_cast<double>(std::max<std::size_t>(idealConvergence(f, ref, off), 1)));
    p_.convergence.push_back(static_cast<double>(std::max<std::size_t>(converged_after, 1)));
  }

  // The information limit of experiment E's criterion. Two Bayes filters given the same images
  // and priors N(x0, P0), N(x0 + Δx0, P0) differ, for a linear-Gaussian model, by exactly
  // M_n Δx0 with M_n = Π (I − K_k C_k) Φ_k: the prior's remaining weight, whatever the images
  // say. Here both filters take every row's E[Z²] from the TRUE depth (the one part of the
  // viewline model that is not linear), so the count below is what the information in the
  // images allows, without gates, restarts or depth guesses: the tracker cannot do better
  // without under-weighting its prior.
  std::size_t idealConvergence(const DartFlight& f, const TrackerConfig& ref, const TrackerConfig& off) const {
    const double t0 = f.detections.front().m.t;
    estimation::StateEstimate a(ref.prior_mean, ref.prior_cov, t0), b(off.prior_mean, off.prior_cov, t0);
    std::size_t converged_after = 0;
    for (std::size_t i = 0; i < f.detections.size(); ++i) {
      const DartDetection& d = f.detections[i];
      const core::Camera& cam = cams_[d.m.camera];
      const double z = cam.toCamera(d.truth.head<3>()).z();
      const tracking::ViewlineRows rows =
          tracking::viewlineRowsWithDepth(cam, d.m.uv, d.m.sigma_px, 0.0, ref.model, z * z);
      for (estimation::StateEstimate* s : {&a, &b}) {
        if (d.m.t > s->t()) {
          estimation::predict(*s, ref.model.transition(d.m.t - s->t()));
          s->setTime(d.m.t);
        }
        estimation::update(*s, estimation::LinearMeasurement{rows.C, rows.y, rows.R});
      }
      if ((a.x().head<3>() - b.x().head<3>()).norm() > cfg_.single_tolerance) converged_after = i + 2;
    }
    return converged_after;
  }

  const DartScenarioConfig& cfg_;
  const std::vector<core::Camera>& cams_;
  const TrackerConfig& exact_;
  const TrackerConfig& offset_;
  const DartRunCallbacks& cb_;
  Pools& p_;
  DartSummary& sum_;
  DartFlights& flights_;
  int run_ = 0;
};

double sqrtMean(double sum, std::size_t n) { return n ? std::sqrt(sum / static_cast<double>(n)) : 0.0; }

void finish(DartSummary& sum, const Pools& p, const DartScenarioConfig& cfg, int runs) {
  sum.nees_samples = p.nees6.count();
  if (p.nees6.count() > 0) {
    sum.nees_mean = p.nees6.mean();
    sum.nees_bounds = p.nees6.bounds(cfg.confidence);
    sum.nees_position_mean = p.nees3.mean();
    sum.nees_position_bounds = p.nees3.bounds(cfg.confidence);
  }
  sum.rmse_position = p.a_settled.rmse();
  const std::size_t a_settled = p.a_settled.n + p.a_settled.unreported;
  sum.reported_fraction = a_settled ? static_cast<double>(p.a_settled.n) / static_cast<double>(a_settled) : 1.0;
  sum.pcrlb_position = sqrtMean(p.a_settled.bound, p.a_settled.n);
  sum.rmse_to_pcrlb = sum.pcrlb_position > 0 ? sum.rmse_position / sum.pcrlb_position : 0.0;
  const double final_bound = sqrtMean(p.a_final.bound, p.a_final.n);
  sum.rmse_to_pcrlb_final = final_bound > 0 ? p.a_final.rmse() / final_bound : 0.0;
  sum.measurements_per_flight = static_cast<double>(p.measurements) / runs;
  finishGate(sum.gate_directional, p.b_dir);
  finishGate(sum.gate_mahalanobis, p.b_mah);
  // The better gate: fewest errors of both kinds (outliers let through + inliers rejected).
  auto errors = [](const GateFigures& g) { return (1.0 - g.outlier_rejected_fraction) + g.inlier_rejected_fraction; };
  const GateFigures& better =
      errors(sum.gate_mahalanobis) <= errors(sum.gate_directional) ? sum.gate_mahalanobis : sum.gate_directional;
  sum.better_gate = better.gate;
  sum.outlier_rejected_fraction = better.outlier_rejected_fraction;
  sum.inlier_rejected_fraction = better.inlier_rejected_fraction;
  sum.rmse_image_ekf_alternating = p.b_ekf.rmse();
  sum.rmse_outliers_to_outlier_free = sum.rmse_position > 0 ? better.rmse_position / sum.rmse_position : 0.0;
  sum.rmse_async_exact = p.c_exact.rmse();
  sum.rmse_async_dt_offset = p.c_offset.rmse();
  sum.rmse_async_image_ekf = p.c_ekf.rmse();
  sum.nees_async_exact = p.c_exact.n ? p.c_exact.nees / static_cast<double>(p.c_exact.n) : 0.0;
  sum.nees_async_dt_offset = p.c_offset.n ? p.c_offset.nees / static_cast<double>(p.c_offset.n) : 0.0;
  finishGate(sum.scenario_gate, p.d_scenario);
  sum.update_time_us = p.update_count ? 1e6 * p.update_time / static_cast<double>(p.update_count) : 0.0;
  // Nearest rank: "p95 of the convergence counts" stays a count; 0 when no run had a flight.
  const bool any = !p.convergence.empty();
  sum.single_camera_convergence_p95 = any ? core::percentileNearestRank(p.convergence, 0.95) : 0.0;
  sum.single_camera_convergence_median = any ? core::percentileNearestRank(p.convergence, 0.5) : 0.0;
  sum.single_camera_convergence_bound_p95 = any ? core::percentileNearestRank(p.convergence_bound, 0.95) : 0.0;
  sum.single_camera_convergence_bound_median = any ? core::percentileNearestRank(p.convergence_bound, 0.5) : 0.0;
}

}  // namespace

DartSummary runDartExperiments(const DartScenarioConfig& cfg, std::uint64_t seed, int runs, const DartRunCallbacks& cb) {
  if (runs < 1) throw core::InvalidInput("dart scenario: runs: expected >= 1");
  if (cfg.onFootage())
    throw core::InvalidInput("dart scenario: cameras[].source: footage runs as one session without truth "
                             "(runDartFootage), not as the experiments");
  const auto t_start = std::chrono::steady_clock::now();
  const std::vector<core::Camera> cams = makeDartCameras(cfg);

  TrackerConfig exact = cfg.trackerConfig();
  exact.time_mode = tracking::TimeMode::Exact;
  exact.late_horizon = cfg.late_horizon;
  TrackerConfig offset = exact;
  offset.time_mode = tracking::TimeMode::DtOffset;
  offset.sample_period = cfg.dt_offset_period;

  DartSummary sum;
  sum.seed = seed;
  sum.runs = runs;
  sum.gate_directional.gate = "directional";
  sum.gate_mahalanobis.gate = "mahalanobis";
  sum.scenario_gate.gate = tracking::toString(cfg.tracker.gate.kind);
  Pools pools;
  const std::string replay =
      !cb.replay_dir.empty() ? cb.replay_dir
                             : cfg.source.kind == runtime::SourceKind::Recording ? cfg.source.recording : std::string();
  DartFlights flights(cb.record_dir, replay, seed, runs, cb.config_text);
  DartRun one(cfg, cams, exact, offset, cb, pools, sum, flights);
  int done = 0;
  for (int run = 0; run < runs; ++run) {
    one.run(run, core::deriveSeed(seed, static_cast<std::uint64_t>(run)));
    done = run + 1;
    if (cb.progress) cb.progress(done, runs);
    if (core::interruptRequested()) break;  // Ctrl-C / SIGTERM: summarise the runs so far (the last one cut short)
  }
  sum.runs = done;
  finish(sum, pools, cfg, done);
  sum.runtime_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  return sum;
}

}  // namespace viewline::scenarios
