// Sweep files (tuning::sweepSpecFromString / loadSweepSpec, modules/tuning sweep_spec.h) against a
// registry of stub adapters named like this build's scenarios (their option names as in
// config/sweeps), then the settings are generated and applied to a small scenario tree. Only the
// tuning core is linked (scenario registry, sweep spec, YAML edits), no scenario code.

#include <memory>
#include <string>

#include "fuzz_util.h"
#include "viewline/io/config_edit.h"
#include "viewline/tuning/sweep_spec.h"

namespace {
namespace tuning = viewline::tuning;

class StubAdapter : public tuning::ScenarioAdapter {
public:
  explicit StubAdapter(std::string name, std::vector<tuning::AdapterOption> options)
      : name_(std::move(name)), options_(std::move(options)) {}
  std::string name() const override { return name_; }
  std::string description() const override { return "fuzz stub"; }
  std::string appCommand(const std::string& p) const override { return name_ + " " + p; }
  std::string defaultMetric() const override { return "rmse"; }
  std::vector<std::string> metricNames() const override { return {"rmse", "nis_mean", "rmse_position_m", "catch_rate"}; }
  std::vector<tuning::AdapterOption> options() const override { return options_; }
  std::unique_ptr<tuning::ScenarioInstance> load(const YAML::Node&, const std::string&,
                                                 const tuning::AdapterOptions&) const override {
    throw viewline::core::InvalidInput("fuzz stub: no scenario");
  }

private:
  std::string name_;
  std::vector<tuning::AdapterOption> options_;
};

const tuning::AdapterRegistry& registry() {
  static const tuning::AdapterRegistry r = [] {
    tuning::AdapterRegistry reg;
    const std::vector<tuning::AdapterOption> opts = {
        {"flights", "20", {}, ""},  {"throws", "20", {}, ""},   {"max_time", "60", {}, ""},
        {"duration", "0", {}, ""},  {"clock", "alternating", {"alternating", "free_running"}, ""},
        {"outliers", "none", {"none", "config"}, ""}};
    for (const char* n : {"dart", "pan_tilt", "table_ball", "ball_catching", "mobile_capture", "toy"})
      reg.add(std::make_unique<StubAdapter>(n, opts));
    return reg;
  }();
  return r;
}

const char* const kScenario = "filter:\n  q: 1\n  r: 2\ntracker:\n  accel_psd: 1\ncameras:\n  - sigma_px: 1\n";

void exercise(const tuning::SweepSpec& spec) {
  // The parser refuses more than 10,000 grid points per parameter and 10^6 settings (F2); a spec
  // it accepts is generated here only up to 10^5 settings, so that one input stays fast.
  double total = 1.0;
  for (const auto& p : spec.parameters) total *= static_cast<double>(p.values.size());
  if (spec.mode == tuning::SweepMode::Grid && total > 1e5) return;
  if (spec.mode != tuning::SweepMode::Grid && spec.samples > 100000) return;
  const std::vector<tuning::Setting> settings = tuning::generateSettings(spec);
  const YAML::Node scenario = YAML::Load(kScenario);
  for (std::size_t i = 0; i < settings.size() && i < 8; ++i) {
    tuning::settingLabel(spec, settings[i]);
    viewline::fuzz::rejectOk([&] { viewline::io::emitYaml(tuning::applySetting(scenario, spec, settings[i])); });
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text = viewline::fuzz::asText(data, size);
  viewline::fuzz::rejectOk([&] { exercise(tuning::sweepSpecFromString(text, "sweep.yaml", registry(), "/base")); });
  return 0;
}
