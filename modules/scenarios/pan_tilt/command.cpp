#include "viewline/scenarios/pan_tilt/command.h"

#include <cmath>
#include <filesystem>
#include <memory>

#include "viewline/io/config_edit.h"
#include "viewline/io/files.h"
#include "viewline/io/log.h"
#include "viewline/runtime/progress.h"
#include "viewline/runtime/telemetry.h"
#include "viewline/scenarios/pan_tilt/loop.h"

namespace viewline::scenarios::pan_tilt {

namespace {

// " (auto)" when filter.jump_min_samples or jump_corner_sigma is "auto" (then chosen by the filter from
// the noise and the target's step), else "".
std::string cornerSettingsOrigin(const PanTiltScenarioConfig& cfg) {
  const auto& f = cfg.control.filter;
  const bool m = !f.jump_min_samples, c = !f.jump_corner_sigma;
  return m && c ? " (auto)" : m ? " (min samples auto)" : c ? " (corner sigma auto)" : "";
}

void printRegionWarning(std::FILE* out) {
  std::fprintf(out, "  WARNING: the target left filter.region (measurements outside it): the region was dropped; "
                    "check its center and size\n");
}

int runReplay(const CommandOptions& o, const PanTiltScenarioConfig& cfg, std::FILE* out) {
  io::LogDirectory log(o.log_dir);
  const PanTiltReplayMetrics r =
      replayPanTiltFilter(cfg, o.seed, o.replay, o.estimator, log.enabled() ? &log : nullptr, o.particles);
  log.flush();
  nlohmann::json rj = r.toJson();
  if (!o.sets.empty()) rj["config_set"] = o.sets;
  if (!o.summary_path.empty()) io::writeSummaryFile(o.summary_path, rj);
  const auto seed = static_cast<unsigned long long>(o.seed);
  if (o.estimator == PanTiltReplayEstimator::OracleCorners)
    std::fprintf(out, "replay of %s (seed %llu, oracle: constant-speed legs at the %zu true corners): %zu measurements\n",
                 o.replay.c_str(), seed, r.jumps, r.measurements);
  else if (o.estimator == PanTiltReplayEstimator::WaypointParticles)
    std::fprintf(out, "replay of %s (seed %llu, reference: waypoint particle filter, %zu particles): %zu measurements\n",
                 o.replay.c_str(), seed, o.particles, r.measurements);
  else
    std::fprintf(out, "replay of %s (seed %llu, filter %s): %zu measurements, %zu velocity jumps detected\n",
                 o.replay.c_str(), seed, tracking::toString(cfg.control.filter.model), r.measurements, r.jumps);
  std::fprintf(out, "  rmse measured (cm)          x %.4f  y %.4f\n", r.rmse_measured_cm.x(), r.rmse_measured_cm.y());
  std::fprintf(out, "  rmse filtered (cm)          x %.4f  y %.4f\n", r.rmse_filtered_cm.x(), r.rmse_filtered_cm.y());
  std::fprintf(out, "  rmse predicted %.4f s ahead (cm)  x %.4f  y %.4f  (%.2f px)\n", r.horizon_s,
               r.rmse_predicted_cm.x(), r.rmse_predicted_cm.y(), r.predicted_error_px);
  std::fprintf(out, "  predicted %.4f s ahead, what the frames see (px)  %.2f\n", r.frame_horizon_s,
               r.frame_predicted_error_px);
  if (r.min_samples > 0)
    std::fprintf(out, "  corner settings%s at the end: %d measurements, %.4f m\n", cornerSettingsOrigin(cfg).c_str(),
                 r.min_samples, r.corner_sigma);
  if (r.region_dropped) printRegionWarning(out);
  return 0;
}

void printSummary(const PanTiltScenarioConfig& cfg, const PanTiltComparison& result, std::uint64_t seed,
                  std::FILE* out) {
  const auto& o = result.ours;
  std::fprintf(out, "pan-tilt %s, seed %llu, %.0f s at %.0f fps (%ux%u, fx %.0f fy %.0f), filter %s, gain %.2f (ours %.2f)\n",
               result.path.c_str(), static_cast<unsigned long long>(seed), cfg.duration, cfg.fps, cfg.image_width,
               cfg.image_height, cfg.fx, cfg.fy, tracking::toString(cfg.control.filter.model), cfg.control.servo.gain,
               cfg.control.gain > 0.0 ? cfg.control.gain : cfg.control.servo.gain);
  if (o.stopped) std::fprintf(out, "  (ended early by the viewer: the figures cover the frames run)\n");
  if (!cfg.rig_folder.empty() && cfg.source.simulated())
    std::fprintf(out, "  rig %s: renders with truth.yaml, controls with rig.yaml + e_M_c.yaml\n", cfg.rig_folder.c_str());
  else if (!cfg.rig_folder.empty())  // nothing is rendered: truth.yaml, if the rig has one, is not used
    std::fprintf(out, "  rig %s: frames from source %s, controls with rig.yaml + e_M_c.yaml\n", cfg.rig_folder.c_str(),
                 runtime::toString(cfg.source.kind));
  std::fprintf(out, "  [T] noise sigma (cm)        x %.3f  y %.3f\n", o.noise_sigma_cm.x(), o.noise_sigma_cm.y());
  if (!o.scored)
    std::fprintf(out, "  source %s has no truth: rmse, Table 1 and image error not scored\n",
                 runtime::toString(cfg.source.kind));
  else
    std::fprintf(out, "  rmse measured (cm)          x %.4f  y %.4f\n", o.rmse_measured_cm.x(), o.rmse_measured_cm.y());
  if (o.scored)
    std::fprintf(out, "  rmse filtered (cm)          x %.4f  y %.4f\n", o.rmse_filtered_cm.x(), o.rmse_filtered_cm.y());
  const TTable1Row t = tTable1(cfg.path.shape);
  if (t.available && o.scored) {
    const bool met = o.rmse_filtered_cm.x() <= 0.5 * t.kalman.x() && o.rmse_filtered_cm.y() <= 0.5 * t.kalman.y();
    std::fprintf(out, "  [T] Table 1 measured / KF   x %.4f / %.4f  y %.4f / %.4f  (target: filtered <= %.4f, %.4f): %s\n",
                 t.measured.x(), t.kalman.x(), t.measured.y(), t.kalman.y(), 0.5 * t.kalman.x(), 0.5 * t.kalman.y(),
                 metText(met));
  }
  if (o.scored) std::fprintf(out, "  image error rms (px)        ours %.2f", o.image_error_rms_px);
  if (result.has_baseline && o.scored)
    std::fprintf(out, "  baseline %.2f  ratio %.3f", result.baseline.image_error_rms_px,
                 o.image_error_rms_px / result.baseline.image_error_rms_px);
  if (o.scored) std::fprintf(out, "\n");
  std::fprintf(out, "  limits: unsafe commands %zu, rate violations %zu, hard-stop hits %zu (ours)", o.unsafe_commands,
               o.rate_violations, o.limit_hits);
  std::size_t outside = o.unsafe_commands + o.rate_violations + o.limit_hits;
  if (result.has_baseline) {
    const auto& b = result.baseline;
    std::fprintf(out, "; %zu, %zu, %zu (baseline)", b.unsafe_commands, b.rate_violations, b.limit_hits);
    outside += b.unsafe_commands + b.rate_violations + b.limit_hits;
  }
  std::fprintf(out, "  (target: 0): %s\n", metText(outside == 0));
  std::fprintf(out, "  pan %.1f..%.1f deg, tilt %.1f..%.1f deg\n", o.pan_range_deg.x(), o.pan_range_deg.y(),
               o.tilt_range_deg.x(), o.tilt_range_deg.y());
  if (o.occlusion) {
    std::fprintf(out, "  occlusion %.1f s at %.1f s: %s", cfg.occlusion_duration, cfg.occlusion_start,
                 o.reacquired ? "reacquired" : "NOT reacquired");
    if (o.reacquired) std::fprintf(out, " %.3f s after it ended", o.reacquisition_delay_s);
    std::fprintf(out, "  (target: reacquired): %s\n", metText(o.reacquired));
  }
  std::fprintf(out, "  filter: %zu velocity jumps (corners) detected", o.filter_jumps);
  if (o.filter_min_samples > 0)
    std::fprintf(out, "; corner settings%s: %d measurements, %.4f m", cornerSettingsOrigin(cfg).c_str(),
                 o.filter_min_samples, o.filter_corner_sigma);
  std::fprintf(out, "\n");
  if (o.filter_region_dropped) printRegionWarning(out);
  std::fprintf(out, "  %.1f ms per frame (render + detect + control)\n", o.wall_ms_per_frame);
  if (!o.faults.empty()) std::fprintf(out, "  %s (ours)\n", runtime::summaryLine(o.faults).c_str());
  const auto printLive = [&](const PanTiltRunMetrics& m) {
    if (!m.live) return;
    std::fprintf(out, "  %s (%s)\n", runtime::summaryLine(*m.live).c_str(), m.controller.c_str());
    std::fprintf(out, "    %s\n", runtime::processingLine(*m.live).c_str());
  };
  printLive(o);
  if (result.has_baseline) printLive(result.baseline);
}

}  // namespace

int runCommand(const CommandOptions& o, FrameSink* view, std::FILE* out) {
  std::vector<std::string> edits = o.sets;
  edits.insert(edits.end(), o.shorthands.begin(), o.shorthands.end());
  const io::ConfigNode root = io::loadConfigWithValues(o.config_path, edits);
  const PanTiltScenarioConfig cfg = loadPanTiltScenarioConfig(root);
  const bool replay_recording = !o.replay.empty() && std::filesystem::is_directory(o.replay);
  if (!o.replay.empty() && !replay_recording) return runReplay(o, cfg, out);

  io::LogDirectory log(o.log_dir);
  runtime::CsvSink csv(log);        // measurements, innovations, estimates, commands
  FrameCsvSink frames_csv(log);     // <controller>_frames.csv (what --replay reads)
  FrameFanout frames;
  if (log.enabled()) frames.add(&frames_csv);
  frames.add(view);
  const auto per_run = static_cast<long>(std::floor(cfg.duration * cfg.fps));
  const long total = per_run * (cfg.run_baseline ? 2 : 1);
  runtime::Progress progress = o.quiet ? runtime::Progress::quiet() : runtime::Progress("frames", total);
  PanTiltRunIo io;
  io.telemetry = log.enabled() ? &csv : nullptr;
  io.frames = frames.empty() ? nullptr : &frames;
  io.pacing = o.pacing;
  io.progress = [&](double f) { progress.update(std::lround(f * static_cast<double>(total))); };
  io.record_dir = o.record;
  if (replay_recording) io.replay_dir = o.replay;
  if (!o.record.empty()) {
    YAML::Emitter yaml;
    yaml << root.yaml();
    io.config_text = std::string(yaml.c_str()) + "\n";
  }
  const PanTiltComparison result = runPanTiltComparison(cfg, o.seed, io);
  progress.finish();
  csv.flush();
  log.flush();
  nlohmann::json j = result.toJson(cfg);
  if (!o.sets.empty()) j["config_set"] = o.sets;
  if (!o.summary_path.empty()) io::writeSummaryFile(o.summary_path, j);
  printSummary(cfg, result, o.seed, out);
  return 0;
}

}  // namespace viewline::scenarios::pan_tilt
