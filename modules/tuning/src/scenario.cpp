#include "viewline/tuning/scenario.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <sstream>

#include "viewline/core/error.h"

namespace viewline::tuning {

void Consistency::add(double value, double dof) {
  sum += value;
  dof_sum += dof;
  ++count;
}

void Consistency::merge(const Consistency& o) {
  sum += o.sum;
  dof_sum += o.dof_sum;
  count += o.count;
}

double Consistency::mean() const { return count ? sum / static_cast<double>(count) : std::nan(""); }
double Consistency::meanDof() const { return count ? dof_sum / static_cast<double>(count) : std::nan(""); }

core::Interval Consistency::bounds(double confidence) const {
  if (count == 0) return {std::nan(""), std::nan("")};
  return core::averagedChiSquareInterval(meanDof(), static_cast<double>(count), confidence);
}

std::string Consistency::verdict(double confidence) const {
  if (count == 0) return "n/a";
  const core::Interval b = bounds(confidence);
  const double m = mean();
  if (m > b.hi) return "overconfident";
  if (m < b.lo) return "underconfident";
  return "consistent";
}

std::string combinedVerdict(const Consistency& nees, const Consistency& nis, double confidence) {
  const std::string a = nees.verdict(confidence), b = nis.verdict(confidence);
  const bool over = a == "overconfident" || b == "overconfident";
  const bool under = a == "underconfident" || b == "underconfident";
  if (over && under) return "inconsistent";
  if (over) return "overconfident";
  if (under) return "underconfident";
  if (a == "n/a" && b == "n/a") return "n/a";
  return "consistent";
}

namespace {
[[noreturn]] void unsupported(const ScenarioInstance& i) {
  const std::string why = i.autotuneUnsupported();
  throw core::InvalidInput("noise auto-tuning is not supported by this scenario adapter" +
                           (why.empty() ? std::string(" (no replay implemented)") : ": " + why));
}
}  // namespace

std::vector<NoiseParameter> ScenarioInstance::noiseParameters() const { unsupported(*this); }
std::unique_ptr<ReplayData> ScenarioInstance::record(std::uint64_t, int) const { unsupported(*this); }
std::unique_ptr<ReplayData> ScenarioInstance::loadLog(const std::string&) const { unsupported(*this); }
std::unique_ptr<ReplayData> ScenarioInstance::loadRecording(const std::string& dir) const {
  requireAutotune("this scenario");
  throw core::InvalidInput(dir + ": this scenario's tuning adapter does not read recordings (pan_tilt does)");
}
ReplayResult ScenarioInstance::replay(const ReplayData&, const std::vector<double>&, double, bool) const {
  unsupported(*this);
}
std::unique_ptr<ScenarioInstance> ScenarioInstance::withNoise(const std::vector<double>&) const { unsupported(*this); }

void ScenarioInstance::requireAutotune(const std::string& scenario) const {
  const std::string why = autotuneUnsupported();
  if (!why.empty()) throw core::InvalidInput(scenario + ": noise auto-tuning is not supported by this adapter: " + why);
}

std::unique_ptr<ScenarioInstance> ScenarioAdapter::loadConfig(const io::ConfigNode& config,
                                                               const AdapterOptions& options) const {
  return load(config.yaml(), config.fileName(), options);
}

void AdapterRegistry::add(std::unique_ptr<ScenarioAdapter> adapter) {
  if (has(adapter->name())) throw core::InvalidInput("adapter '" + adapter->name() + "' registered twice");
  adapters_.push_back(std::move(adapter));
}

bool AdapterRegistry::has(const std::string& name) const {
  return std::any_of(adapters_.begin(), adapters_.end(), [&](const auto& a) { return a->name() == name; });
}

const ScenarioAdapter& AdapterRegistry::get(const std::string& name) const {
  for (const auto& a : adapters_)
    if (a->name() == name) return *a;
  std::string list;
  for (const auto& a : adapters_) list += (list.empty() ? "" : ", ") + a->name();
  throw core::InvalidInput("unknown scenario '" + name + "' (this build has: " + (list.empty() ? "none" : list) + ")");
}

std::vector<std::string> AdapterRegistry::names() const {
  std::vector<std::string> n;
  for (const auto& a : adapters_) n.push_back(a->name());
  return n;
}

namespace {
std::string numberText(double v) {
  std::ostringstream os;
  os << v;
  return os.str();
}
}  // namespace

std::string AdapterOption::expected() const {
  if (!choices.empty()) {
    std::string list;
    for (const auto& c : choices) list += (list.empty() ? "" : ", ") + c;
    return "one of: " + list;
  }
  const std::string what = integer ? "an integer" : "a number";
  const bool lo = std::isfinite(min), hi = std::isfinite(max);
  if (lo && hi) return what + " in [" + numberText(min) + ", " + numberText(max) + "]";
  if (lo) return what + " >= " + numberText(min);
  if (hi) return what + " <= " + numberText(max);
  return integer ? what : "a finite number";
}

bool AdapterOption::accepts(const std::string& text) const {
  if (!choices.empty()) return std::find(choices.begin(), choices.end(), text) != choices.end();
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || end == text.c_str() || *end != '\0' || !std::isfinite(v)) return false;
  if (integer && v != std::floor(v)) return false;
  return v >= min && v <= max;
}

AdapterOptions readAdapterOptions(const ScenarioAdapter& adapter, const io::ConfigNode* node) {
  AdapterOptions out;
  for (const AdapterOption& o : adapter.options()) {
    out[o.name] = o.default_value;
    if (node == nullptr || !node->has(o.name)) continue;
    const std::string text = node->get<std::string>(o.name);
    if (!o.accepts(text)) node->fail(o.name, o.expected());
    out[o.name] = text;
  }
  return out;
}

AdapterOptions checkedOptions(const std::vector<AdapterOption>& declared, const AdapterOptions& given,
                              const std::string& adapter) {
  AdapterOptions out;
  for (const AdapterOption& o : declared) out[o.name] = o.default_value;
  for (const auto& [name, text] : given) {
    const std::string& key = name;  // a structured binding cannot be captured in C++17 (clang refuses it)
    const auto it = std::find_if(declared.begin(), declared.end(), [&](const AdapterOption& o) { return o.name == key; });
    if (it == declared.end()) throw core::InvalidInput(adapter + ": '" + name + "' is not an option of this adapter");
    if (!it->accepts(text))
      throw core::InvalidInput(adapter + " adapter option '" + name + "': expected " + it->expected() + ", got '" + text + "'");
    out[name] = text;
  }
  return out;
}

double optionNumber(const AdapterOptions& o, const std::string& name) {
  const auto it = o.find(name);
  if (it == o.end()) throw core::InvalidInput("adapter option '" + name + "' missing");
  char* end = nullptr;
  const double v = std::strtod(it->second.c_str(), &end);
  if (end == it->second.c_str() || *end != '\0' || !std::isfinite(v))
    throw core::InvalidInput("adapter option '" + name + "': expected a number, got '" + it->second + "'");
  return v;
}

std::string optionText(const AdapterOptions& o, const std::string& name) {
  const auto it = o.find(name);
  if (it == o.end()) throw core::InvalidInput("adapter option '" + name + "' missing");
  return it->second;
}

}  // namespace viewline::tuning
