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
  // A grid of many parameters multiplies out; the sweep runner would run every setting, so a
  // spec that passes the parser is expected to generate them in bounded memory. Cap what we touch.
  double total = 1.0;  // F2 again: the grid's product of value counts is not bounded either
  for (const auto& p : spec.parameters) total *= static_cast<double>(p.values.size());
  if (spec.mode == tuning::SweepMode::Grid && total > 1e5) return;
  const std::vector<tuning::Setting> settings = tuning::generateSettings(spec);
  const YAML::Node scenario = YAML::Load(kScenario);
  for (std::size_t i = 0; i < settings.size() && i < 8; ++i) {
    tuning::settingLabel(spec, settings[i]);
    viewline::fuzz::rejectOk([&] { viewline::io::emitYaml(tuning::applySetting(scenario, spec, settings[i])); });
  }
}

// Known finding (fuzz/README.md, F2): a grid `count` or random `samples` in the int range but huge
// (count: 1000000000) passes the sweep parser, which then generates that many values (memory and
// time without bound). It is reported to modules/tuning; such inputs are skipped here so that the
// fuzzer keeps exploring instead of stopping at its first out-of-memory.
bool hugeCount(const YAML::Node& n, int depth) {
  if (depth > 16) return false;
  if (n.IsMap()) {
    for (auto it = n.begin(); it != n.end(); ++it) {
      if (it->first.IsScalar() && (it->first.Scalar() == "count" || it->first.Scalar() == "samples") &&
          it->second.IsScalar()) {
        try {
          if (it->second.as<double>() > 1e5) return true;
        } catch (const YAML::Exception&) {
        }
      }
      if (hugeCount(it->second, depth + 1)) return true;
    }
  } else if (n.IsSequence()) {
    for (const auto& e : n)
      if (hugeCount(e, depth + 1)) return true;
  }
  return false;
}

bool skip(const std::string& text) {
  try {
    return hugeCount(YAML::Load(text), 0);
  } catch (const YAML::Exception&) {
    return false;
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text = viewline::fuzz::asText(data, size);
  if (skip(text)) return 0;
  viewline::fuzz::rejectOk([&] { exercise(tuning::sweepSpecFromString(text, "sweep.yaml", registry(), "/base")); });
  return 0;
}
