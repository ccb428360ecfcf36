#include "viewline/scenarios/ball_catching/metrics.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

#include "viewline/core/error.h"
#include "viewline/core/statistics.h"
#include "viewline/estimation/consistency.h"
#include "viewline/planning/catch_planner.h"

namespace viewline::scenarios {

namespace {
constexpr const char* kMissReasons[] = {"late", "off_target", "lost_track", "not_reachable"};
}  // namespace

void scoreThrow(ThrowResult& res, const BallCatchingConfig& cfg, const robots::SimulatedCartesianRobot& robot,
                const planning::CatchPlanner& planner, const std::optional<Eigen::Vector3d>& lead_prediction) {
  const Eigen::Vector3d& n = cfg.box_normal;
  const Eigen::Vector3d& home = cfg.robot.home;
  const double clearance = cfg.hole_radius - cfg.throws.body.reference_radius;
  const robots::CartesianState hole = robot.read(res.t_cross);
  res.hole_at_cross = hole.p;
  if (std::abs(n.dot(hole.p - home)) > 1e-9)
    throw core::NumericalError("runThrow: the hole left the box plane (planner bug)");
  Eigen::Vector3d off = res.cross_true - hole.p;
  off -= n * n.dot(off);
  res.miss_distance = off.norm();
  res.caught = res.miss_distance <= clearance;
  res.limit_violations = robot.velocityViolations() + robot.accelerationViolations();
  res.refused_setpoints = robot.refusedSetpoints();
  res.max_speed = robot.maxSpeedSeen();
  res.max_acceleration = robot.maxAccelerationSeen();
  // Oracle.
  res.oracle_time = planning::minimumDuration(robot.limits(), home, Eigen::Vector3d::Zero(), res.cross_true);
  res.reachable = res.t_first_visible >= 0.0 && robot.reachable(res.cross_true) &&
                  res.t_first_visible + robot.commandLatency() + res.oracle_time <= res.t_cross;
  // Planner.
  res.had_target = planner.target().has_value();
  res.committed = planner.committed();
  res.gave_up = planner.giveUpTime().has_value();
  if (planner.firstMoveTime()) res.t_first_move = *planner.firstMoveTime();
  if (lead_prediction) res.prediction_error_lead = (*lead_prediction - res.cross_true).norm();
  if (planner.giveUpTime()) res.give_up_lead = res.t_cross - *planner.giveUpTime();
  if (planner.commitTime() && planner.firstUpdateTime())
    res.decision_time = *planner.commitTime() - *planner.firstUpdateTime();
  if (res.had_target) {
    res.target = planner.target()->p;
    res.prediction_error = (res.target - res.cross_true).norm();
  }
  if (!res.caught) {
    if (!res.reachable) res.miss_reason = "not_reachable";
    else if (!res.had_target) res.miss_reason = "lost_track";
    else if ((hole.p - res.target).norm() > clearance) res.miss_reason = "late";
    else res.miss_reason = "off_target";
  }
}

CatchSummary summarise(std::vector<ThrowResult> results, std::uint64_t seed,
                       std::optional<RegistrationResult> registration) {
  CatchSummary s;
  s.seed = seed;
  s.registration = std::move(registration);
  s.results = std::move(results);
  s.throws = static_cast<int>(s.results.size());
  for (const char* r : kMissReasons) s.miss_reasons[r] = 0;
  if (s.results.empty()) return s;
  std::vector<double> pred_lead, pred_err, decision, miss_reach, speeds, elev, flight, give_up_lead;
  double frame_time = 0.0, det_sq = 0.0, told_sq = 0.0;
  int det_axes = 0;
  estimation::ConsistencyStats nis, nees;
  for (const ThrowResult& r : s.results) {
    s.reachable_throws += r.reachable;
    s.caught += r.caught;
    s.caught_reachable += r.caught && r.reachable;
    if (!r.caught) ++s.miss_reasons[r.miss_reason];
    if (r.prediction_error >= 0.0) pred_err.push_back(1e3 * r.prediction_error);
    if (r.prediction_error_lead >= 0.0) pred_lead.push_back(1e3 * r.prediction_error_lead);
    if (r.decision_time >= 0.0) decision.push_back(r.decision_time);
    if (r.gave_up && !r.reachable) {
      ++s.gave_up_unreachable;
      give_up_lead.push_back(r.give_up_lead);
    }
    if (r.gave_up && r.reachable) ++s.gave_up_reachable;
    if (r.reachable) miss_reach.push_back(1e3 * r.miss_distance);
    s.limit_violations += r.limit_violations;
    s.faults.add(r.faults);
    s.refused_setpoints += r.refused_setpoints;
    s.max_speed = std::max(s.max_speed, r.max_speed);
    s.max_acceleration = std::max(s.max_acceleration, r.max_acceleration);
    s.frames += r.frames;
    s.detections += r.detections;
    det_sq += r.detection_sq_error_px2;
    told_sq += r.told_variance_px2;
    det_axes += 2 * r.detection_errors;
    for (double v : r.nis) nis.add(v, 2.0);
    if (r.nees >= 0.0) nees.add(r.nees, 6.0);
    speeds.push_back(r.launch_speed);
    elev.push_back(r.launch_elevation_deg);
    flight.push_back(r.t_cross);
    frame_time += r.wall_s;
  }
  using core::percentile;
  s.catch_rate_all = static_cast<double>(s.caught) / s.throws;
  // Over no reachable throw the rate is not scored (NaN: null in the summary, "not scored" in the text).
  s.catch_rate_reachable = s.reachable_throws > 0 ? static_cast<double>(s.caught_reachable) / s.reachable_throws
                                                  : std::numeric_limits<double>::quiet_NaN();
  s.prediction_error_mm_median = percentile(pred_err, 0.5);
  s.prediction_error_mm_p95 = percentile(pred_err, 0.95);
  s.prediction_error_lead_mm_median = percentile(pred_lead, 0.5);
  s.prediction_error_lead_mm_p95 = percentile(pred_lead, 0.95);
  s.predictions_at_lead = static_cast<int>(pred_lead.size());
  s.decisions = static_cast<int>(decision.size());
  s.decision_time_s_median = percentile(decision, 0.5);
  s.decision_time_s_p95 = percentile(decision, 0.95);
  s.miss_distance_mm_median_reachable = percentile(miss_reach, 0.5);
  s.give_up_lead_s_median = percentile(give_up_lead, 0.5);
  s.detection_rate = s.frames > 0 ? static_cast<double>(s.detections) / s.frames : 0.0;
  s.detection_error_px_rms = det_axes > 0 ? std::sqrt(det_sq / det_axes) : 0.0;
  s.told_sigma_px_rms = det_axes > 0 ? std::sqrt(told_sq / det_axes) : 0.0;
  // Samples counted as independent (one NEES per throw; NIS of successive images of a track are
  // nearly so for a filter whose innovations are white, which is what the test is about).
  s.nis_mean = nis.mean();
  s.nis_samples = static_cast<int>(nis.count());
  s.nees_mean = nees.mean();
  s.nees_samples = static_cast<int>(nees.count());
  if (nis.count() > 0) {
    const core::Interval b = nis.bounds(0.99);
    s.nis_band_lo = b.lo;
    s.nis_band_hi = b.hi;
  }
  if (nees.count() > 0) {
    const core::Interval b = nees.bounds(0.99);
    s.nees_band_lo = b.lo;
    s.nees_band_hi = b.hi;
  }
  s.launch_speed_min = *std::min_element(speeds.begin(), speeds.end());
  s.launch_speed_max = *std::max_element(speeds.begin(), speeds.end());
  s.launch_speed_mean = 0.0;
  for (double v : speeds) s.launch_speed_mean += v / static_cast<double>(speeds.size());
  s.elevation_deg_min = *std::min_element(elev.begin(), elev.end());
  s.elevation_deg_max = *std::max_element(elev.begin(), elev.end());
  s.flight_time_min = *std::min_element(flight.begin(), flight.end());
  s.flight_time_max = *std::max_element(flight.begin(), flight.end());
  s.ms_per_frame = s.frames > 0 ? 1e3 * frame_time / s.frames : 0.0;
  return s;
}

nlohmann::json summaryJson(const CatchSummary& s, const BallCatchingConfig& cfg) {
  auto num = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); };
  nlohmann::json j;
  j["scenario"] = cfg.name;
  j["object"] = cfg.object;
  j["seed"] = s.seed;
  j["throws"] = s.throws;
  j["reachable_throws"] = s.reachable_throws;
  j["caught"] = s.caught;
  j["catch_rate_all"] = s.catch_rate_all;
  j["catch_rate_reachable"] = num(s.catch_rate_reachable);
  j["miss_reasons"] = s.miss_reasons;
  j["prediction_error_mm_at_catch"] = {{"median", num(s.prediction_error_mm_median)},
                                       {"p95", num(s.prediction_error_mm_p95)}};
  j["prediction_error_mm_at_lead"] = {{"lead_s", cfg.prediction_lead_s},
                                      {"median", num(s.prediction_error_lead_mm_median)},
                                      {"p95", num(s.prediction_error_lead_mm_p95)},
                                      {"throws", s.predictions_at_lead}};
  j["decision_time_s"] = {{"median", num(s.decision_time_s_median)}, {"p95", num(s.decision_time_s_p95)},
                          {"throws_with_decision", s.decisions}};
  j["miss_distance_mm_median_reachable"] = num(s.miss_distance_mm_median_reachable);
  j["early_give_up"] = {{"not_reachable_throws_given_up", s.gave_up_unreachable},
                        {"reachable_throws_given_up", s.gave_up_reachable},
                        {"lead_before_crossing_s_median", num(s.give_up_lead_s_median)}};
  j["robot"] = {{"kind", robots::toString(cfg.robot.kind)},
                {"v_max", cfg.robot.limits.v_max.x()},
                {"a_max", cfg.robot.limits.a_max.x()},
                {"latency_s", cfg.robot.latency},
                {"limit_norm", robots::toString(cfg.robot.limits.norm)},
                {"limit_violations", s.limit_violations},
                {"max_speed", s.max_speed},
                {"max_acceleration", s.max_acceleration},
                {"refused_setpoints", s.refused_setpoints}};
  j["cameras"] = cfg.activeCameras();
  j["rate_hz"] = cfg.rate_override_hz > 0.0 ? cfg.rate_override_hz : cfg.cameras.front().rate_hz;
  j["pixel_noise_grey"] = cfg.cameras.front().noise_sigma;
  j["detection_noise_px"] = cfg.pixel_noise_px;
  j["rig"] = cfg.rig.empty() ? nlohmann::json("inline cameras (estimator = render cameras)") : nlohmann::json(cfg.rig);
  j["planner_model"] = planning::toString(cfg.planner.model.kind);
  j["hole_radius_m"] = cfg.hole_radius;
  j["ball_radius_m"] = cfg.throws.body.reference_radius;
  j["drag_k_per_m"] = cfg.throws.body.dragPerMass();
  j["frames"] = s.frames;
  j["detection_rate"] = s.detection_rate;
  j["detection_error_px_rms"] = s.detection_error_px_rms;
  j["told_sigma_px_rms"] = s.told_sigma_px_rms;
  j["tracker_consistency"] = {{"nis_mean", s.nis_mean}, {"nis_samples", s.nis_samples},
                              {"nis_band_99", {s.nis_band_lo, s.nis_band_hi}},
                              {"nees_mean", s.nees_mean}, {"nees_samples", s.nees_samples},
                              {"nees_band_99", {s.nees_band_lo, s.nees_band_hi}}};
  j["throw_distribution"] = {{"launch_speed_mps", {{"min", s.launch_speed_min}, {"mean", s.launch_speed_mean},
                                                   {"max", s.launch_speed_max}}},
                             {"elevation_deg", {{"min", s.elevation_deg_min}, {"max", s.elevation_deg_max}}},
                             {"flight_time_s", {{"min", s.flight_time_min}, {"max", s.flight_time_max}}},
                             {"aim_radius_m", cfg.throws.aim_radius},
                             {"mean_horizontal_speed_mps", {cfg.throws.speed_min, cfg.throws.speed_max}},
                             {"spin", "none"}};
  if (s.registration)
    j["registration"] = {{"poses", s.registration->poses},
                         {"points_per_camera", s.registration->points_per_camera},
                         {"cameras_registered", s.registration->cameras_registered},
                         {"cameras_refused", s.registration->cameras_refused},
                         {"reprojection_px_before", s.registration->reprojection_px_before},
                         {"reprojection_px_after", s.registration->reprojection_px_after},
                         {"centre_shift_mm", s.registration->centre_shift_mm},
                         {"rotation_deg", s.registration->rotation_deg}};
  else
    j["registration"] = "off";
  j["reachability_start"] = "first capture with the ball inside a camera image (truth), robot at home at rest";
  j["wall_time_s"] = s.wall_s;
  j["ms_per_frame_per_thread"] = s.ms_per_frame;
  if (!cfg.faults.faults.empty()) j["faults"] = runtime::toJson(s.faults);
  return j;
}

void writeThrowsCsv(io::LogDirectory& log, const std::vector<ThrowResult>& results) {
  if (!log.enabled()) return;
  io::CsvWriter& w = log.stream("throws", {"throw", "seed", "t_cross", "cross_x", "cross_y", "cross_z", "target_y",
                                           "target_z", "miss_mm", "caught", "reachable", "decision_time",
                                           "t_first_visible", "t_first_detection", "t_first_move", "oracle_time",
                                           "gave_up", "reason"});
  for (const ThrowResult& r : results)
    w.rowText({std::to_string(r.index), std::to_string(r.seed), std::to_string(r.t_cross),
               std::to_string(r.cross_true.x()), std::to_string(r.cross_true.y()), std::to_string(r.cross_true.z()),
               std::to_string(r.target.y()), std::to_string(r.target.z()), std::to_string(1e3 * r.miss_distance),
               r.caught ? "1" : "0", r.reachable ? "1" : "0", std::to_string(r.decision_time),
               std::to_string(r.t_first_visible), std::to_string(r.t_first_detection), std::to_string(r.t_first_move),
               std::to_string(r.oracle_time), r.gave_up ? "1" : "0", r.miss_reason});
}

std::string summaryText(const CatchSummary& s, const BallCatchingConfig& cfg) {
  std::string out;
  char line[512];
  std::snprintf(line, sizeof line, "ball_catching: %d throws, seed %llu, %zu cameras, %s robot (%.2f m/s, %.1f m/s², %s), planner %s, %.1f s wall\n",
                s.throws, static_cast<unsigned long long>(s.seed), cfg.activeCameras(), robots::toString(cfg.robot.kind),
                cfg.robot.limits.v_max.x(), cfg.robot.limits.a_max.x(), robots::toString(cfg.robot.limits.norm),
                planning::toString(cfg.planner.model.kind), s.wall_s);
  out += line;
  if (s.reachable_throws > 0) {
    std::snprintf(line, sizeof line, "  caught %d: catch rate %.3f of all, %.3f of the %d reachable throws\n", s.caught,
                  s.catch_rate_all, s.catch_rate_reachable, s.reachable_throws);
  } else {
    std::snprintf(line, sizeof line, "  caught %d: catch rate %.3f of all; of the reachable throws not scored (none was reachable)\n",
                  s.caught, s.catch_rate_all);
  }
  out += line;
  std::snprintf(line, sizeof line, "  misses: late %d, off target %d, lost track %d, not reachable %d\n", s.miss_reasons.at("late"),
                s.miss_reasons.at("off_target"), s.miss_reasons.at("lost_track"), s.miss_reasons.at("not_reachable"));
  out += line;
  if (std::isfinite(s.prediction_error_mm_median)) {
    std::snprintf(line, sizeof line, "  prediction error at the crossing: median %.1f mm, p95 %.1f mm; ", s.prediction_error_mm_median,
                  s.prediction_error_mm_p95);
  } else {
    std::snprintf(line, sizeof line, "  prediction error at the crossing: not scored (no throw was predicted); ");
  }
  out += line;
  if (s.decisions > 0) {
    std::snprintf(line, sizeof line, "decision time median %.3f s, p95 %.3f s\n", s.decision_time_s_median, s.decision_time_s_p95);
  } else {
    std::snprintf(line, sizeof line, "decision time not scored (no decision)\n");
  }
  out += line;
  std::snprintf(line, sizeof line,
                "  %d frames, detection rate %.3f, %.2f ms per frame (render + detect + track + plan); "
                "robot limit violations %zu\n",
                s.frames, s.detection_rate, s.ms_per_frame, s.limit_violations);
  out += line;
  if (!cfg.faults.faults.empty()) out += "  " + runtime::summaryLine(s.faults) + "\n";
  return out;
}

}  // namespace viewline::scenarios
