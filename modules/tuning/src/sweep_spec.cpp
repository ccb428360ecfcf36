#include "viewline/tuning/sweep_spec.h"

#include <cmath>
#include <filesystem>
#include <set>
#include <sstream>

#include "viewline/core/error.h"
#include "viewline/core/random.h"
#include "viewline/tuning/yaml_edit.h"

namespace viewline::tuning {

namespace {
// Bounds that keep a sweep file from asking for unbounded memory or time (each setting is a run).
constexpr int kMaxGridPoints = 10000;
constexpr int kMaxSettings = 1000000;
}  // namespace

namespace {

std::string numberText(double v, bool integer) {
  if (integer) return std::to_string(static_cast<long long>(std::llround(v)));
  std::ostringstream os;
  os.precision(6);
  os << v;
  return os.str();
}

YAML::Node numberNode(double v, bool integer) { return YAML::Node(numberText(v, integer)); }

double numericOf(const YAML::Node& n) {
  if (!n.IsScalar()) return std::nan("");
  try {
    return n.as<double>();
  } catch (const YAML::Exception&) {
    return std::nan("");
  }
}

SweepParameter readParameter(const io::ConfigNode& p, SweepMode mode) {
  SweepParameter sp;
  sp.key = p.get<std::string>("key");
  sp.location = p.location("key");
  try {
    io::parseDottedKey(sp.key);
  } catch (const core::InvalidInput& e) {
    p.fail("key", std::string("a dotted scenario key (") + e.what() + ")");
  }
  const bool has_values = p.has("values");
  sp.has_range = p.has("range");
  if (has_values == sp.has_range) p.fail("", "exactly one of 'values' (a list) or 'range' ([lo, hi])");
  const std::string type = p.getChoiceOr("type", {"double", "int"}, "double");
  sp.integer = type == "int";
  sp.log_scale = p.getChoiceOr("scale", {"linear", "log"}, "linear") == "log";
  if (has_values) {
    const YAML::Node v = p.yaml()["values"];
    p.ignore("values");
    if (!v.IsSequence() || v.size() == 0) p.fail("values", "a non-empty list of values");
    for (std::size_t i = 0; i < v.size(); ++i) {
      if (!v[i].IsScalar()) p.fail("values", "a list of plain values (item " + std::to_string(i) + " is not)");
      if (sp.integer && !std::isfinite(numericOf(v[i]))) p.fail("values", "integers (type: int)");
      sp.values.push_back(YAML::Clone(v[i]));
    }
    if (p.has("count")) p.fail("count", "no 'count' with explicit 'values'");
  } else {
    const std::vector<double> r = p.get<std::vector<double>>("range");
    if (r.size() != 2) p.fail("range", "[lo, hi] (two numbers)");
    sp.lo = r[0];
    sp.hi = r[1];
    if (!std::isfinite(sp.lo) || !std::isfinite(sp.hi)) p.fail("range", "finite numbers");
    if (sp.hi < sp.lo) p.fail("range", "lo <= hi (empty range)");
    if (sp.log_scale && !(sp.lo > 0.0)) p.fail("range", "lo > 0 with scale: log");
    if (mode == SweepMode::Grid) {
      sp.count = p.get<int>("count");
      if (sp.count < 1 || sp.count > kMaxGridPoints)
        p.fail("count", "from 1 to " + std::to_string(kMaxGridPoints) + " grid points");
      if (sp.count > 1 && sp.hi == sp.lo) p.fail("range", "lo < hi for more than one grid point (empty range)");
      for (int i = 0; i < sp.count; ++i) {
        const double f = sp.count == 1 ? 0.0 : static_cast<double>(i) / (sp.count - 1);
        const double v = sp.log_scale ? std::exp(std::log(sp.lo) + f * (std::log(sp.hi) - std::log(sp.lo)))
                                      : sp.lo + f * (sp.hi - sp.lo);
        const YAML::Node node = numberNode(v, sp.integer);
        if (!sp.values.empty() && sp.values.back().Scalar() == node.Scalar()) continue;  // int rounding
        sp.values.push_back(node);
      }
    } else if (p.has("count")) {
      p.fail("count", "no 'count' in random mode (use 'samples' at the top level)");
    }
  }
  return sp;
}

SweepSpec fromNode(const io::ConfigNode& root, const AdapterRegistry& registry, const std::string& base_dir) {
  SweepSpec s;
  s.file = root.fileName();
  s.scenario = root.get<std::string>("scenario");
  const ScenarioAdapter* adapter = nullptr;
  try {
    adapter = &registry.get(s.scenario);
  } catch (const core::InvalidInput& e) {
    root.fail("scenario", std::string("a scenario of this build (") + e.what() + ")");
  }
  if (root.has("config")) {
    const std::string c = root.get<std::string>("config");
    if (c.empty()) root.fail("config", "a file path");
    s.config_path = std::filesystem::path(c).is_absolute() ? c : (std::filesystem::path(base_dir) / c).lexically_normal().string();
  }
  s.seeds = root.getOr<int>("seeds", s.seeds);
  if (s.seeds < 1) root.fail("seeds", "at least 1");
  s.base_seed = root.getOr<std::uint64_t>("base_seed", s.base_seed);
  s.metric = root.getOr<std::string>("metric", adapter->defaultMetric());
  {
    const auto names = adapter->metricNames();
    if (std::find(names.begin(), names.end(), s.metric) == names.end()) {
      std::string list;
      for (const auto& n : names) list += (list.empty() ? "" : ", ") + n;
      root.fail("metric", "a metric of scenario '" + s.scenario + "' (" + list + ")");
    }
  }
  s.minimize = root.getChoiceOr("direction", {"minimize", "maximize"}, adapter->defaultMinimize() ? "minimize" : "maximize") ==
               "minimize";
  s.mode = root.getChoiceOr("mode", {"grid", "random"}, "grid") == "grid" ? SweepMode::Grid : SweepMode::Random;
  if (s.mode == SweepMode::Random) {
    s.samples = root.get<int>("samples");
    if (s.samples < 1 || s.samples > kMaxSettings) root.fail("samples", "from 1 to " + std::to_string(kMaxSettings));
    s.sample_seed = root.getOr<std::uint64_t>("sample_seed", s.sample_seed);
  } else if (root.has("samples")) {
    root.fail("samples", "no 'samples' in grid mode");
  }
  s.confidence = root.getOr<double>("confidence", s.confidence);
  if (!(s.confidence > 0.0 && s.confidence < 1.0)) root.fail("confidence", "a probability in (0, 1)");
  const std::vector<io::ConfigNode> params = root.childList("parameters");
  if (params.empty()) root.fail("parameters", "at least one parameter");
  std::set<std::string> keys;
  for (const io::ConfigNode& p : params) {
    SweepParameter sp = readParameter(p, s.mode);
    if (!keys.insert(sp.key).second) p.fail("key", "a key not already swept ('" + sp.key + "' is listed twice)");
    s.parameters.push_back(std::move(sp));
  }
  if (s.mode == SweepMode::Grid) {
    // Every setting of a grid is run: refuse a product no session could finish before generating it.
    double settings = 1.0;
    for (const SweepParameter& sp : s.parameters) settings *= static_cast<double>(sp.values.size());
    if (settings > kMaxSettings)
      root.fail("parameters", "a grid of at most " + std::to_string(kMaxSettings) + " settings (this one has " +
                                  std::to_string(settings) + ")");
  }
  if (root.has("adapter")) {
    const io::ConfigNode a = root.child("adapter");
    s.adapter_options = readAdapterOptions(*adapter, &a);
  } else {
    s.adapter_options = readAdapterOptions(*adapter, nullptr);
  }
  if (root.has("autotune")) {
    const io::ConfigNode a = root.child("autotune");
    AutotuneSpec& t = s.autotune;
    t.enabled = a.getOr<bool>("enabled", true);
    t.start_scale = a.getOr<double>("start_scale", t.start_scale);
    if (!(t.start_scale > 0.0)) a.fail("start_scale", "a positive factor");
    t.record_seed = a.getOr<std::uint64_t>("record_seed", t.record_seed);
    t.record_runs = a.getOr<int>("record_runs", t.record_runs);
    if (t.record_runs < 1) a.fail("record_runs", "at least 1");
    t.outlier_prior = a.getOr<double>("outlier_prior", t.outlier_prior);
    if (!(t.outlier_prior >= 0.0 && t.outlier_prior < 1.0)) a.fail("outlier_prior", "a probability in [0, 1)");
    t.span_decades = a.getOr<double>("span_decades", t.span_decades);
    if (!(t.span_decades > 0.0 && t.span_decades <= 6.0)) a.fail("span_decades", "in (0, 6]");
    t.grid_points = a.getOr<int>("grid_points", t.grid_points);
    if (t.grid_points < 3 || t.grid_points > 101) a.fail("grid_points", "3 to 101");
  }
  root.finish();
  return s;
}

}  // namespace

SweepSpec loadSweepSpec(const std::string& path, const AdapterRegistry& registry) {
  const std::string dir = std::filesystem::path(path).parent_path().string();
  return fromNode(io::ConfigNode::loadFile(path), registry, dir.empty() ? "." : dir);
}

SweepSpec sweepSpecFromString(const std::string& yaml, const std::string& name, const AdapterRegistry& registry,
                              const std::string& base_dir) {
  return fromNode(io::ConfigNode::fromString(yaml, name), registry, base_dir);
}

std::vector<Setting> generateSettings(const SweepSpec& spec) {
  std::vector<Setting> out;
  const std::size_t np = spec.parameters.size();
  if (spec.mode == SweepMode::Grid) {
    std::size_t total = 1;
    for (const auto& p : spec.parameters) total *= p.values.size();
    for (std::size_t i = 0; i < total; ++i) {
      Setting s;
      s.index = i;
      std::size_t rem = i;
      std::vector<std::size_t> idx(np);
      for (std::size_t k = np; k-- > 0;) {
        idx[k] = rem % spec.parameters[k].values.size();
        rem /= spec.parameters[k].values.size();
      }
      for (std::size_t k = 0; k < np; ++k) {
        s.values.push_back(spec.parameters[k].values[idx[k]]);
        s.numeric.push_back(numericOf(s.values.back()));
      }
      out.push_back(std::move(s));
    }
    return out;
  }
  core::Rng rng = core::makeRng(spec.sample_seed);
  for (int i = 0; i < spec.samples; ++i) {
    Setting s;
    s.index = static_cast<std::size_t>(i);
    for (const SweepParameter& p : spec.parameters) {
      YAML::Node v;
      if (!p.has_range) {
        const double u = core::uniform(rng, 0.0, static_cast<double>(p.values.size()));
        v = p.values[std::min(p.values.size() - 1, static_cast<std::size_t>(u))];
      } else if (p.log_scale) {
        v = numberNode(std::exp(core::uniform(rng, std::log(p.lo), std::log(p.hi))), p.integer);
      } else {
        v = numberNode(core::uniform(rng, p.lo, p.hi), p.integer);
      }
      s.values.push_back(v);
      s.numeric.push_back(numericOf(v));
    }
    out.push_back(std::move(s));
  }
  return out;
}

std::string settingLabel(const SweepSpec& spec, const Setting& s) {
  std::string out;
  for (std::size_t k = 0; k < spec.parameters.size(); ++k)
    out += (k ? ", " : "") + spec.parameters[k].key + "=" + scalarText(s.values[k]);
  return out;
}

std::string Setting::label() const {
  std::string out;
  for (std::size_t k = 0; k < values.size(); ++k) out += (k ? " " : "") + scalarText(values[k]);
  return out;
}

YAML::Node applySetting(const YAML::Node& scenario, const SweepSpec& spec, const Setting& s) {
  std::vector<std::pair<std::string, YAML::Node>> kv;
  for (std::size_t k = 0; k < spec.parameters.size(); ++k) kv.emplace_back(spec.parameters[k].key, s.values[k]);
  return editedTree(scenario, kv);
}

}  // namespace viewline::tuning
