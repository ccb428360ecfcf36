#include "viewline/scenarios/dart/recording.h"

#include <filesystem>

#include "viewline/core/error.h"
#include "viewline/io/files.h"
#include "viewline/runtime/recording.h"

namespace viewline::scenarios {

namespace fs = std::filesystem;

namespace {

constexpr const char* kScenario = "dart_tracking";
constexpr std::size_t kFields = 13;  // id, camera, t, u, v, sigma_px, outlier, x, y, z, vx, vy, vz

nlohmann::json rowOf(const DartDetection& d) {
  return {d.m.id, d.m.camera, d.m.t, d.m.uv.x(), d.m.uv.y(), d.m.sigma_px, d.outlier ? 1 : 0,
          d.truth[0], d.truth[1], d.truth[2], d.truth[3], d.truth[4], d.truth[5]};
}

DartDetection detectionOf(const nlohmann::json& row, std::size_t cameras, const std::string& where) {
  if (!row.is_array() || row.size() != kFields)
    throw core::InvalidInput(where + ": expected [id, camera, t, u, v, sigma_px, outlier, x, y, z, vx, vy, vz]");
  for (const auto& v : row)
    if (!v.is_number()) throw core::InvalidInput(where + ": every field must be a number");
  if (!row[0].is_number_unsigned() || !row[1].is_number_unsigned() || row[1].get<std::size_t>() >= cameras)
    throw core::InvalidInput(where + ": id and camera must be unsigned integers, camera < " + std::to_string(cameras));
  DartDetection d;
  d.m.id = row[0].get<std::uint64_t>();
  d.m.camera = row[1].get<std::size_t>();
  d.m.t = row[2].get<double>();
  d.m.uv = Eigen::Vector2d(row[3].get<double>(), row[4].get<double>());
  d.m.sigma_px = row[5].get<double>();
  d.outlier = row[6].get<double>() != 0.0;
  for (int k = 0; k < 6; ++k) d.truth[k] = row[static_cast<std::size_t>(7 + k)].get<double>();
  if (!std::isfinite(d.m.t) || !d.m.uv.allFinite() || !(d.m.sigma_px > 0.0) || !d.truth.allFinite())
    throw core::InvalidInput(where + ": expected finite numbers and sigma_px > 0");
  return d;
}

}  // namespace

DartFlights::DartFlights(const std::string& record_dir, const std::string& replay_dir, std::uint64_t seed, int runs,
                         const std::string& config_text)
    : record_dir_(record_dir), replay_dir_(replay_dir) {
  if (!replay_dir_.empty()) runtime::checkSessionReplay(replay_dir_, kScenario, seed, runs);
  if (!record_dir_.empty()) runtime::beginSessionRecording(record_dir_, {kScenario, seed, runs, "run"}, config_text);
}

void DartFlights::beginRun(int run) {
  next_draw_.clear();
  run_ = nlohmann::json::object();
  if (!replay_dir_.empty()) {
    file_ = runtime::sessionUnitDir(replay_dir_, "run", run) + ".json";
    if (!fs::is_regular_file(file_))
      throw core::InvalidInput(file_ + ": missing (run " + std::to_string(run) + " of a dart_tracking recording)");
    run_ = io::readJsonFile(file_);
    if (!run_.is_object()) throw core::InvalidInput(file_ + ": expected an object of experiments");
  } else if (!record_dir_.empty()) {
    file_ = runtime::sessionUnitDir(record_dir_, "run", run) + ".json";
  }
}

nlohmann::json& DartFlights::experimentOf(const std::string& experiment) {
  if (!replay_dir_.empty() && (!run_.contains(experiment) || !run_[experiment].is_object()))
    throw core::InvalidInput(file_ + ": no experiment '" + experiment + "'");
  return run_[experiment];
}

DartFlight DartFlights::flight(const std::string& experiment, const DartScenarioConfig& cfg,
                               const std::vector<core::Camera>& cameras, DartClockMode mode, double outlier_rate,
                               core::Rng& rng) {
  if (replay_dir_.empty()) {
    DartFlight f = simulateDartFlight(cfg, cameras, mode, outlier_rate, rng);
    if (!record_dir_.empty()) {
      nlohmann::json rows = nlohmann::json::array();
      for (const DartDetection& d : f.detections) rows.push_back(rowOf(d));
      nlohmann::json& e = experimentOf(experiment);
      e["duration_s"] = f.duration;
      e["detections"] = std::move(rows);
      e["draws"] = nlohmann::json::array();
    }
    return f;
  }
  const nlohmann::json& e = experimentOf(experiment);
  const std::string where = file_ + ": " + experiment;
  if (!e.contains("duration_s") || !e["duration_s"].is_number() || !e.contains("detections") ||
      !e["detections"].is_array())
    throw core::InvalidInput(where + ": expected \"duration_s\" and \"detections\"");
  DartFlight f;
  f.duration = e["duration_s"].get<double>();
  for (std::size_t i = 0; i < e["detections"].size(); ++i)
    f.detections.push_back(detectionOf(e["detections"][i], cameras.size(), where + ": detection " + std::to_string(i)));
  return f;
}

double DartFlights::draw(const std::string& experiment, const std::function<double()>& draw) {
  if (replay_dir_.empty()) {
    const double v = draw();
    if (!record_dir_.empty()) experimentOf(experiment)["draws"].push_back(v);
    return v;
  }
  const nlohmann::json& e = experimentOf(experiment);
  std::size_t& k = next_draw_[experiment];
  if (!e.contains("draws") || !e["draws"].is_array() || k >= e["draws"].size() || !e["draws"][k].is_number())
    throw core::InvalidInput(file_ + ": " + experiment + ": draw " + std::to_string(k) +
                             " missing (the recording was made with other settings)");
  return e["draws"][k++].get<double>();
}

Eigen::Vector3d DartFlights::draw3(const std::string& experiment, const std::function<Eigen::Vector3d()>& draw) {
  if (replay_dir_.empty()) {
    const Eigen::Vector3d v = draw();
    if (!record_dir_.empty())
      for (int i = 0; i < 3; ++i) experimentOf(experiment)["draws"].push_back(v[i]);
    return v;
  }
  Eigen::Vector3d v;
  for (int i = 0; i < 3; ++i) v[i] = this->draw(experiment, [] { return 0.0; });
  return v;
}

void DartFlights::endRun() {
  if (!record_dir_.empty()) {
    io::writeJsonFile(file_, run_, -1);  // compact: a run holds a few thousand numbers
  } else if (!replay_dir_.empty()) {
    for (const auto& [name, e] : run_.items()) {
      const std::size_t used = next_draw_.count(name) ? next_draw_.at(name) : 0;
      if (e.contains("draws") && e["draws"].is_array() && e["draws"].size() != used)
        throw core::InvalidInput(file_ + ": " + name + ": " + std::to_string(e["draws"].size()) + " draws recorded, " +
                                 std::to_string(used) + " used (the recording was made with other settings)");
    }
  }
}

}  // namespace viewline::scenarios
