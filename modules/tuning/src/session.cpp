#include "viewline/tuning/session.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>

#include "adapter_util.h"
#include "viewline/core/error.h"
#include "viewline/core/random.h"
#include "viewline/io/files.h"
#include "viewline/runtime/progress.h"
#include "viewline/tuning/autotune.h"
#include "viewline/tuning/report.h"
#include "viewline/tuning/sweep_runner.h"
#include "viewline/tuning/sweep_spec.h"
#include "viewline/tuning/yaml_edit.h"

namespace viewline::tuning {

namespace fs = std::filesystem;

namespace {

nlohmann::json num(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); }

std::string fmt(double v, int prec = 4) {
  if (!std::isfinite(v)) return "-";
  char b[64];
  std::snprintf(b, sizeof b, "%.*g", prec, v);
  return b;
}

/// The scenario config of a session, read once: `text` (with the --set edits) for the configs the
/// session writes, `node` for the adapter (each key read once, validated once), `tree` (the same
/// parsed nodes) where sweep settings and relocated paths start from (editedTree keeps its marks).
struct ScenarioFile {
  std::string path, text;
  io::ConfigNode node;
  YAML::Node tree;
};

ScenarioFile readScenarioFile(const std::string& path, const std::vector<std::string>& set) {
  if (!set.empty()) {  // the --set values written into the text (rewriteYamlText), then parsed
    std::string text = io::configTextWithValues(path, set);
    io::ConfigNode node = detail::scenarioConfig(text, path);
    YAML::Node tree = node.yaml();
    return {path, std::move(text), std::move(node), std::move(tree)};
  }
  io::ConfigNode node = io::ConfigNode::loadFile(path);  // names the file and line of its own errors
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  YAML::Node tree = node.yaml();
  return {path, text.str(), std::move(node), std::move(tree)};
}

// `kv` plus the config's relative paths (rig folders, ...) re-expressed for a copy of the config
// written into `out_dir`, so that the copy loads from there too (keys already in `kv` win).
void addRelocatedPaths(std::vector<std::pair<std::string, YAML::Node>>& kv, const ScenarioFile& file,
                       const std::string& out_dir) {
  for (auto& r : relocatedPaths(file.tree, fs::path(file.path).parent_path().string(), out_dir)) {
    const bool swept = std::any_of(kv.begin(), kv.end(), [&](const auto& e) { return e.first == r.first; });
    if (!swept) kv.push_back(std::move(r));
  }
}

nlohmann::json interval(const core::Interval& i) { return {num(i.lo), num(i.hi)}; }

nlohmann::json consistencyJson(const Consistency& c, double confidence) {
  return {{"mean", num(c.mean())}, {"bounds", interval(c.bounds(confidence))}, {"samples", c.count},
          {"verdict", c.verdict(confidence)}};
}

void say(bool quiet, const std::string& s) {
  if (!quiet) std::fprintf(stderr, "%s\n", s.c_str());
}

/// Runs `instance` on seeds deriveSeed(base, 0..n-1) in parallel; aggregated like a setting.
SettingResult evaluate(const ScenarioInstance& instance, std::uint64_t base_seed, int n, int workers, double confidence) {
  SettingResult r;
  r.runs.resize(static_cast<std::size_t>(n));
  parallelFor(static_cast<std::size_t>(n), workers, [&](std::size_t i) {
    const std::uint64_t seed = core::deriveSeed(base_seed, i);
    try {
      r.runs[i] = instance.run(seed, {});
    } catch (const std::exception& e) {
      r.runs[i].error = e.what();
    }
    r.runs[i].seed = seed;
  });
  aggregate(r, confidence);
  return r;
}

std::string consistencyCell(const Consistency& c, double confidence) {
  if (c.count == 0) return "-";
  const core::Interval b = c.bounds(confidence);
  return fmt(c.mean(), 4) + " [" + fmt(b.lo, 3) + ", " + fmt(b.hi, 3) + "]";
}

std::string verdictClass(const std::string& v) {
  if (v == "overconfident" || v == "inconsistent") return "over";
  if (v == "underconfident") return "under";
  return "";
}

std::string describeConsistency() {
  return "NEES (state error against P, where the simulation knows the truth) and NIS (innovation against S) with "
         "two-sided chi-square bands of their means. <b>overconfident</b>: the mean is above the band (errors larger "
         "than the filter claims: noise too small); <b>underconfident</b>: below the band (noise too large); "
         "<b>consistent</b>: inside.";
}

/// Metric against each swept parameter (error bars = spread over seeds).
void sweepPlots(HtmlReport& rep, const SweepSpec& spec, const SweepOutcome& out) {
  for (std::size_t k = 0; k < spec.parameters.size(); ++k) {
    const SweepParameter& p = spec.parameters[k];
    bool numeric = true;
    for (const auto& r : out.settings) numeric = numeric && std::isfinite(r.setting.numeric[k]);
    std::vector<std::string> labels;
    for (const auto& v : p.values) labels.push_back(scalarText(v));
    std::ostringstream data, best;
    data.precision(10);
    best.precision(10);
    std::map<std::string, std::pair<double, double>> best_at;  // label -> (x, best mean)
    for (const auto& r : out.settings) {
      const auto it = r.metrics.find(spec.metric);
      if (it == r.metrics.end() || !std::isfinite(it->second.mean) || r.runs.empty()) continue;
      const std::string label = scalarText(r.setting.values[k]);
      double x = r.setting.numeric[k];
      if (!numeric) {
        const auto li = std::find(labels.begin(), labels.end(), label);
        x = static_cast<double>(li - labels.begin());
      }
      data << x << ' ' << it->second.mean << ' ' << it->second.std << '\n';
      const auto bi = best_at.find(label);
      if (bi == best_at.end())
        best_at[label] = {x, it->second.mean};
      else if (spec.minimize ? it->second.mean < bi->second.second : it->second.mean > bi->second.second)
        bi->second = {x, it->second.mean};
    }
    std::vector<std::pair<double, double>> bl;
    for (const auto& [l, b] : best_at) bl.push_back(b);
    std::sort(bl.begin(), bl.end());
    for (const auto& b : bl) best << b.first << ' ' << b.second << '\n';
    const std::string name = "sweep_param" + std::to_string(k);
    rep.dataFile(name + ".dat", data.str());
    rep.dataFile(name + "_best.dat", best.str());
    std::ostringstream gp;
    gp << "set title 'sweep: " << spec.metric << " against " << p.key << "'\nset xlabel '" << p.key << "'\nset ylabel '"
       << spec.metric << " (mean +- std over " << spec.seeds << " seeds)'\n";
    if (numeric && p.log_scale) gp << "set logscale x\n";
    if (!numeric) {
      gp << "set xtics (";
      for (std::size_t i = 0; i < labels.size(); ++i) gp << (i ? ", " : "") << "'" << labels[i] << "' " << i;
      gp << ")\nset xrange [-0.5:" << labels.size() - 0.5 << "]\n";
    } else {
      gp << "set offsets graph 0.03, graph 0.03, 0, 0\n";
    }
    gp << "plot '" << name << ".dat' using 1:2:3 with yerrorbars pt 7 ps 0.6 lc rgb '#3070c0' title 'every setting', '"
       << name << "_best.dat' using 1:2 with lines lw 2 lc rgb '#d04000' title 'best over the other parameters'\n";
    rep.plot(name, gp.str(), spec.metric + " against " + p.key);
  }
}

void autotunePlots(HtmlReport& rep, const AutotuneResult& a, double confidence) {
  if (a.before.series) addRunPlots(rep, *a.before.series, "autotune_before", "replay at the start noise", confidence);
  if (a.after.series) addRunPlots(rep, *a.after.series, "autotune_after", "replay at the tuned noise", confidence);
  if (a.parameters.size() == 2 && !a.grid.empty()) {
    std::ostringstream os;
    os.precision(10);
    double mn = 1e300;
    for (const auto& e : a.grid) mn = std::min(mn, e.cost);
    double prev = std::nan("");
    for (const auto& e : a.grid) {
      if (std::isfinite(prev) && e.values[0] != prev) os << '\n';
      prev = e.values[0];
      os << std::log10(e.values[0]) << ' ' << std::log10(e.values[1]) << ' ' << std::log10(1.0 + e.cost - mn) << '\n';
    }
    rep.dataFile("autotune_cost.dat", os.str());
    std::ostringstream gp;
    gp << "set title 'innovation cost -2 log L (log10(1 + cost - min)) over the noise grid'\nset xlabel 'log10 "
       << a.parameters[0].symbol << " [" << a.parameters[0].unit << "]'\nset ylabel 'log10 " << a.parameters[1].symbol
       << " [" << a.parameters[1].unit << "]'\nset view map\nset pm3d map\nset palette rgb 33,13,10\n"
       << "set label 1 at " << std::log10(a.start[0]) << "," << std::log10(a.start[1])
       << " 'start' front point pt 6 ps 2 lc rgb 'white' offset 1,0 textcolor rgb 'white'\n"
       << "set label 2 at " << std::log10(a.tuned[0]) << "," << std::log10(a.tuned[1])
       << " 'tuned' front point pt 7 ps 1.5 lc rgb 'white' offset 1,0 textcolor rgb 'white'\n"
       << "splot 'autotune_cost.dat' using 1:2:3 with pm3d notitle\n";
    rep.plot("autotune_cost", gp.str(), "auto-tune cost surface, start and tuned noise");
  } else if (a.parameters.size() == 1 && !a.grid.empty()) {
    std::ostringstream os;
    os.precision(10);
    for (const auto& e : a.grid) os << e.values[0] << ' ' << e.cost << '\n';
    rep.dataFile("autotune_cost.dat", os.str());
    std::ostringstream gp;
    gp << "set title 'innovation cost -2 log L'\nset logscale x\nset xlabel '" << a.parameters[0].symbol
       << "'\nset ylabel 'cost'\nset arrow from " << a.tuned[0] << ", graph 0 to " << a.tuned[0]
       << ", graph 1 nohead lc rgb 'red'\nplot 'autotune_cost.dat' using 1:2 with linespoints title 'grid'\n";
    rep.plot("autotune_cost", gp.str(), "auto-tune cost");
  }
}

void autotuneTable(HtmlReport& rep, const AutotuneResult& a, double confidence) {
  std::vector<std::vector<std::string>> rows;
  for (std::size_t i = 0; i < a.parameters.size(); ++i)
    rows.push_back({a.parameters[i].name, a.parameters[i].symbol + " [" + a.parameters[i].unit + "]",
                    a.parameters[i].config_key.empty() ? "(not a config key)" : a.parameters[i].config_key,
                    fmt(a.start[i], 4), fmt(a.tuned[i], 4)});
  rep.table({"noise", "symbol", "config key", "start", "tuned"}, rows);
  rep.table({"replay", "cost -2 log L", "NIS mean [band]", "verdict"},
            {{"start", fmt(a.before.cost, 8), consistencyCell(a.before.nis, confidence), a.before.nis.verdict(confidence)},
             {"tuned", fmt(a.after.cost, 8), consistencyCell(a.after.nis, confidence), a.after.nis.verdict(confidence)}});
}

struct AutotuneOutcome {
  AutotuneResult result;
  SettingResult live_before, live_after;
  Consistency verify_nis;  // NIS of the fresh-seed recording at the tuned noise
  std::string config_file;
  nlohmann::json json;
};

AutotuneOutcome doAutotune(const ScenarioInstance& base, const ScenarioFile& file, const std::string& out_dir,
                           double start_scale, const ReplayData* given_data, std::uint64_t record_seed, int record_runs,
                           const AutotuneOptions& ao, std::uint64_t verify_seed, int verify_runs, bool quiet,
                           const std::string& source_name, const std::map<std::string, double>& start_values = {},
                           std::optional<std::uint64_t> live_seed = std::nullopt) {
  const std::uint64_t live = live_seed.value_or(verify_seed);
  if (given_data == nullptr && (verify_seed == record_seed || live == record_seed))
    throw core::InvalidInput(source_name + ": the verification seed " + std::to_string(verify_seed) +
                             " is the recording's seed: the fresh-seed NIS check needs another one");
  AutotuneOutcome o;
  const std::vector<NoiseParameter> params = base.noiseParameters();
  std::vector<double> start;
  for (const auto& [key, v] : start_values) {
    if (std::none_of(params.begin(), params.end(), [&](const NoiseParameter& p) { return p.config_key == key; }))
      throw core::InvalidInput("--start-value " + key + ": not a noise parameter of this scenario");
    if (!(v > 0.0) || !std::isfinite(v)) throw core::InvalidInput("--start-value " + key + ": expected a positive number");
  }
  for (const auto& p : params) {
    // A given start is used as it is; else the config's value times the scale.
    if (const auto it = start_values.find(p.config_key); it != start_values.end()) {
      start.push_back(it->second);
      continue;
    }
    if (!(p.value > 0.0))
      throw core::InvalidInput(source_name + ": noise parameter '" + p.config_key + "' is " + fmt(p.value) +
                               ": the log-space search needs a positive starting value (give one: --start-value " +
                               p.config_key + "=<value>)");
    start.push_back(p.value * start_scale);
  }
  const std::unique_ptr<ScenarioInstance> start_instance = base.withNoise(start);
  std::unique_ptr<ReplayData> recorded;
  if (given_data == nullptr) {
    say(quiet, "auto-tune: recording " + std::to_string(record_runs) + " run(s) with the start noise");
    recorded = start_instance->record(record_seed, record_runs);
    given_data = recorded.get();
  }
  o.result = autotuneNoise(*start_instance, *given_data, start, ao);
  const std::unique_ptr<ScenarioInstance> tuned_instance = base.withNoise(o.result.tuned);
  o.json = o.result.toJson(ao.confidence);
  // The NIS above comes from the data the noise was fitted on; the check that counts is on a fresh
  // seed: a new recording made with the tuned noise (so a closed loop aims its camera with the
  // tuned filter), replayed at the tuned noise.
  {
    say(quiet, "auto-tune: fresh-seed check, recording " + std::to_string(record_runs) + " run(s) from seed " +
                   std::to_string(verify_seed) + " with the tuned noise");
    const std::unique_ptr<ReplayData> fresh = tuned_instance->record(verify_seed, record_runs);
    const ReplayResult v = tuned_instance->replay(*fresh, o.result.tuned, ao.outlier_prior, false);
    o.verify_nis = v.nis;
    o.json["autotune_verify_seed"] = verify_seed;
    o.json["autotune_verify_data"] = fresh->describe();
    o.json["autotune_verify_nis_mean"] = num(v.nis.mean());
    o.json["autotune_verify_nis_bounds"] = interval(v.nis.bounds(ao.confidence));
    o.json["autotune_verify_nis_verdict"] = v.nis.verdict(ao.confidence);
    o.json["autotune_verify_nis_samples"] = v.nis.count;
  }
  if (verify_runs > 0) {
    say(quiet, "auto-tune: " + std::to_string(verify_runs) + " live runs with the start and the tuned noise");
    o.live_before = evaluate(*start_instance, live, verify_runs, ao.workers, ao.confidence);
    o.live_after = evaluate(*tuned_instance, live, verify_runs, ao.workers, ao.confidence);
    o.json["autotune_live_runs"] = verify_runs;
    o.json["autotune_live_seed"] = live;
    o.json["autotune_live_nees_before"] = consistencyJson(o.live_before.nees, ao.confidence);
    o.json["autotune_live_nis_before"] = consistencyJson(o.live_before.nis, ao.confidence);
    o.json["autotune_live_nees"] = consistencyJson(o.live_after.nees, ao.confidence);
    o.json["autotune_live_nis"] = consistencyJson(o.live_after.nis, ao.confidence);
    o.json["autotune_nees_mean"] = num(o.live_after.nees.mean());
    o.json["autotune_nees_bounds"] = interval(o.live_after.nees.bounds(ao.confidence));
    o.json["autotune_nees_inside"] = o.live_after.nees.count > 0 &&
                                     o.live_after.nees.bounds(ao.confidence).contains(o.live_after.nees.mean());
    o.json["autotune_verify_nees_mean"] = num(o.live_after.nees.mean());
    o.json["autotune_verify_nees_bounds"] = interval(o.live_after.nees.bounds(ao.confidence));
    o.json["autotune_verify_nees_verdict"] = o.live_after.nees.verdict(ao.confidence);
    o.json["autotune_verify_nees_samples"] = o.live_after.nees.count;
    o.json["autotune_live_verdict_before"] = o.live_before.verdict;
    o.json["autotune_live_verdict"] = o.live_after.verdict;
  }
  std::vector<std::pair<std::string, YAML::Node>> kv;
  for (std::size_t i = 0; i < params.size(); ++i) {
    if (params[i].config_key.empty()) continue;
    char b[64];
    std::snprintf(b, sizeof b, "%.6g", o.result.tuned[i]);
    kv.emplace_back(params[i].config_key, YAML::Node(std::string(b)));
  }
  std::string header = "viewline_tune auto-tuned noise (maximum likelihood of the innovations) for " + source_name + "\n";
  for (std::size_t i = 0; i < params.size(); ++i)
    header += params[i].name + " " + params[i].symbol + ": start " + fmt(start[i]) + " -> tuned " +
              fmt(o.result.tuned[i]) + " " + params[i].unit + (params[i].config_key.empty() ? " (not written: no config key)" : "") + "\n";
  addRelocatedPaths(kv, file, out_dir);
  o.config_file = (fs::path(out_dir) / "autotuned_config.yaml").string();
  io::writeTextFileAtomic(o.config_file, io::rewriteYamlText(file.text, kv, header));
  o.json["autotuned_config"] = o.config_file;
  return o;
}

/// Writes the report and the summary (naming the report and its plot count) into `out_dir`.
nlohmann::json writeOutputs(const HtmlReport& rep, nlohmann::json j, const std::string& out_dir) {
  const std::string report_path = (fs::path(out_dir) / "report.html").string();
  j["report"] = report_path;
  j["report_plots"] = rep.plotCount();
  rep.write(report_path);
  io::writeSummaryFile((fs::path(out_dir) / "summary.json").string(), j);
  return j;
}

/// The adapter's options with the command line's `--option name=value` values.
AdapterOptions withOptions(const ScenarioAdapter& adapter, const std::string& scenario, const AdapterOptions& given) {
  AdapterOptions ao = readAdapterOptions(adapter, nullptr);
  for (const auto& [k, v] : given) {
    if (!ao.count(k)) throw core::InvalidInput("--option " + k + ": not an option of scenario '" + scenario + "'");
    ao[k] = v;
  }
  return ao;
}

}  // namespace

std::string loadAverage() {
  std::ifstream in("/proc/loadavg");
  double a = 0, b = 0, c = 0;
  if (!(in >> a >> b >> c)) return "";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.2f %.2f %.2f", a, b, c);
  return buf;
}

nlohmann::json runSweepSession(const AdapterRegistry& registry, const std::string& sweep_file,
                               const SessionOptions& opt) {
  const auto t_session = std::chrono::steady_clock::now();
  SweepSpec spec = loadSweepSpec(sweep_file, registry);
  if (opt.seeds_override > 0) spec.seeds = opt.seeds_override;
  const ScenarioAdapter& adapter = registry.get(spec.scenario);
  const std::string config_path = !opt.config_override.empty() ? opt.config_override : spec.config_path;
  if (config_path.empty())
    throw core::InvalidInput(sweep_file + ": no scenario config (give 'config:' in the sweep file or --config)");
  const ScenarioFile file = readScenarioFile(config_path, opt.set);
  const YAML::Node& tree = file.tree;
  const std::unique_ptr<ScenarioInstance> base = adapter.loadConfig(file.node, spec.adapter_options);
  if (spec.autotune.enabled && !opt.skip_autotune) {
    try {
      base->requireAutotune(spec.scenario);
    } catch (const core::InvalidInput& e) {
      throw core::InvalidInput(sweep_file + ": section 'autotune': " + e.what() + " (remove the section or run with --no-autotune)");
    }
  }

  // Every setting must give a config the scenario accepts: errors name the sweep file's line and key.
  const std::vector<Setting> settings = generateSettings(spec);
  for (const SweepParameter& p : spec.parameters) {
    if (!io::findKey(tree, p.key)) {
      // Not in the file: accept it only when the scenario's loader knows it.
      try {
        adapter.load(editedTree(tree, {{p.key, p.values.empty() ? YAML::Node("0") : p.values.front()}}), config_path,
                     spec.adapter_options);
      } catch (const core::InvalidInput& e) {
        throw core::InvalidInput(p.location + ": parameter '" + p.key + "': not a key of the " + spec.scenario +
                                 " scenario config " + config_path + " (" + e.what() + ")");
      }
    }
  }
  std::vector<std::unique_ptr<ScenarioInstance>> instances;
  for (const Setting& s : settings) {
    try {
      instances.push_back(adapter.load(applySetting(tree, spec, s), config_path, spec.adapter_options));
    } catch (const core::InvalidInput& e) {
      // Name the parameter whose value the scenario refuses (try them one at a time).
      for (std::size_t k = 0; k < spec.parameters.size(); ++k) {
        try {
          adapter.load(editedTree(tree, {{spec.parameters[k].key, s.values[k]}}), config_path, spec.adapter_options);
        } catch (const core::InvalidInput& e1) {
          throw core::InvalidInput(spec.parameters[k].location + ": parameter '" + spec.parameters[k].key +
                                   "': value '" + scalarText(s.values[k]) + "' refused by the " + spec.scenario +
                                   " scenario: " + e1.what());
        }
      }
      throw core::InvalidInput(sweep_file + ": setting " + settingLabel(spec, s) + " refused by the scenario: " + e.what());
    }
  }

  fs::create_directories(opt.out_dir);
  const std::string jsonl = (fs::path(opt.out_dir) / "results.jsonl").string();
  fs::remove(jsonl);
  say(opt.quiet, "viewline_tune: " + std::to_string(settings.size()) + " settings x " + std::to_string(spec.seeds) +
                     " seeds of scenario '" + spec.scenario + "' (" + config_path + "), optimising " + spec.metric +
                     (spec.minimize ? " (minimize)" : " (maximize)"));
  SweepOptions so;
  so.workers = opt.workers;
  so.stop = opt.stop;
  so.results_jsonl = jsonl;
  so.series_for_first_seed = true;  // the report's run plots come from the best setting's first run
  if (!opt.quiet) so.progress = [](const SweepProgress& p) { std::fprintf(stderr, "%s\n", formatProgress(p).c_str()); };
  const std::string load_before = loadAverage();
  SweepOutcome out = runSweep(spec, settings, instances, so);
  const std::string load_after = loadAverage();

  nlohmann::json j;
  j["scenario"] = spec.scenario;
  j["sweep_file"] = sweep_file;
  j["config"] = config_path;
  if (!opt.set.empty()) j["config_set"] = opt.set;
  j["metric"] = spec.metric;
  j["direction"] = spec.minimize ? "minimize" : "maximize";
  j["settings"] = settings.size();
  j["seeds"] = spec.seeds;
  j["seed_rule"] = "run j of every setting uses deriveSeed(base_seed, j) (common random numbers)";
  j["base_seed"] = spec.base_seed;
  j["confidence"] = spec.confidence;
  j["jobs_done"] = out.jobs_done;
  j["jobs_total"] = out.jobs_total;
  j["interrupted"] = out.interrupted;
  j["workers"] = out.workers;
  j["sweep_wall_s"] = out.wall_s;
  j["sweep_cpu_s"] = out.cpu_s;
  j["cpu_utilisation"] = out.wall_s > 0 ? out.cpu_s / out.wall_s : 0.0;
  j["load_average_before"] = load_before;
  j["load_average_after"] = load_after;
  j["results_jsonl"] = jsonl;
  std::size_t over = 0, under = 0, consistent = 0;
  for (const auto& r : out.settings) {
    over += r.verdict == "overconfident";
    under += r.verdict == "underconfident";
    consistent += r.verdict == "consistent";
  }
  j["verdict_counts"] = {{"overconfident", over}, {"underconfident", under}, {"consistent", consistent}};

  // Parallel speedup: the same sweep on one worker.
  if (opt.measure_speedup && !out.interrupted) {
    say(opt.quiet, "viewline_tune: the same sweep on one worker (parallel_speedup)");
    SweepOptions s1 = so;
    s1.workers = 1;
    s1.results_jsonl.clear();
    const std::string l0 = loadAverage();
    const SweepOutcome one = runSweep(spec, settings, instances, s1);
    if (!one.interrupted) {
      std::string diff;
      const bool same = sameResults(out, one, &diff);
      j["parallel_speedup"] = one.wall_s / out.wall_s;
      j["parallel_workers"] = out.workers;
      j["single_worker_wall_s"] = one.wall_s;
      j["single_worker_cpu_s"] = one.cpu_s;
      j["parallel_same_results"] = same;
      if (!same) j["parallel_first_difference"] = diff;
      j["load_average_single_worker"] = l0 + " -> " + loadAverage();
    }
  }

  // Best setting and its config.
  std::string best_config;
  double best_metric = std::nan("");
  if (out.best) {
    const SettingResult& b = out.settings[*out.best];
    best_metric = b.metrics.at(spec.metric).mean;
    std::vector<std::pair<std::string, YAML::Node>> kv;
    for (std::size_t k = 0; k < spec.parameters.size(); ++k) kv.emplace_back(spec.parameters[k].key, b.setting.values[k]);
    addRelocatedPaths(kv, file, opt.out_dir);
    best_config = (fs::path(opt.out_dir) / "best_config.yaml").string();
    const std::string header = "viewline_tune: best setting of " + sweep_file + " (" + spec.metric + " " +
                               (spec.minimize ? "minimised" : "maximised") + ": " + fmt(best_metric, 6) + " over " +
                               std::to_string(spec.seeds) + " seeds)\n" + settingLabel(spec, b.setting) +
                               "\nbased on " + config_path;
    const std::string best_text = io::rewriteYamlText(file.text, kv, header);
    io::writeTextFileAtomic(best_config, best_text);
    bool verified = true;
    try {  // its values, relative paths resolved from its folder, load (the app will read them)
      adapter.load(editedTree(tree, kv), best_config, spec.adapter_options);
    } catch (const core::InvalidInput&) {
      verified = false;
    }
    j["best"] = b.toJson(spec);
    j["best_metric"] = best_metric;
    j["best_label"] = settingLabel(spec, b.setting);
    j["best_config"] = best_config;
    j["best_config_loads"] = verified;
    j["best_config_command"] = adapter.appCommand(best_config);
  }

  // Noise auto-tuning in the same session.
  std::optional<AutotuneOutcome> at;
  if (spec.autotune.enabled && !opt.skip_autotune && !out.interrupted) {
    AutotuneOptions ao;
    ao.outlier_prior = spec.autotune.outlier_prior;
    ao.span_decades = spec.autotune.span_decades;
    ao.grid_points = spec.autotune.grid_points;
    ao.workers = opt.workers;
    ao.confidence = spec.confidence;
    if (!opt.quiet) ao.progress = [](const std::string& s) { std::fprintf(stderr, "%s\n", s.c_str()); };
    at = doAutotune(*base, file, opt.out_dir, spec.autotune.start_scale, nullptr, spec.autotune.record_seed,
                    spec.autotune.record_runs, ao, spec.base_seed, spec.seeds, opt.quiet, config_path);
    nlohmann::json aj = at->json;
    aj["start_scale"] = spec.autotune.start_scale;
    const auto it = at->live_after.metrics.find(spec.metric);
    const auto itb = at->live_before.metrics.find(spec.metric);
    if (it != at->live_after.metrics.end()) {
      aj["autotune_metric"] = num(it->second.mean);
      aj["autotune_metric_std"] = num(it->second.std);
      if (itb != at->live_before.metrics.end()) aj["autotune_metric_before"] = num(itb->second.mean);
      if (std::isfinite(best_metric)) {
        const double ratio = spec.minimize ? it->second.mean / best_metric : best_metric / it->second.mean;
        aj["autotune_metric_ratio_to_best_grid"] = num(ratio);
        aj["autotune_metric_ratio_convention"] =
            "tuned-config metric over the best grid setting's, on the same seeds (>1 = worse than the grid's best)";
      }
    }
    for (auto& [k, v] : aj.items())
      if (k.rfind("autotune", 0) == 0) j[k] = v;
    j["autotune"] = at->json;
  }

  // Report.
  HtmlReport rep("viewline_tune: " + spec.scenario + " sweep", opt.out_dir);
  rep.paragraph("Sweep file <code>" + htmlEscape(sweep_file) + "</code>, scenario <b>" + htmlEscape(spec.scenario) +
                "</b> (" + htmlEscape(adapter.description()) + "), config <code>" + htmlEscape(config_path) + "</code>. " +
                std::to_string(settings.size()) + " settings x " + std::to_string(spec.seeds) + " seeds, metric <b>" +
                htmlEscape(spec.metric) + "</b> (" + (spec.minimize ? "minimize" : "maximize") + "). " +
                std::to_string(out.jobs_done) + "/" + std::to_string(out.jobs_total) + " runs in " + fmt(out.wall_s, 3) +
                " s on " + std::to_string(out.workers) + " workers (CPU " + fmt(out.cpu_s, 3) + " s; load average " +
                htmlEscape(load_before) + ")." + (out.interrupted ? " <b class=\"warn\">Interrupted: the results below are "
                                                                     "those finished before the stop.</b>" : ""));
  if (out.best) {
    const SettingResult& b = out.settings[*out.best];
    rep.heading("Best setting");
    rep.paragraph("<b>" + htmlEscape(settingLabel(spec, b.setting)) + "</b>: " + htmlEscape(spec.metric) + " = " +
                  fmt(best_metric, 5) + " &plusmn; " + fmt(b.metrics.at(spec.metric).std, 3) + " (std over seeds), NEES " +
                  htmlEscape(consistencyCell(b.nees, spec.confidence)) + ", NIS " +
                  htmlEscape(consistencyCell(b.nis, spec.confidence)) + ": <b>" + htmlEscape(b.verdict) + "</b>.");
    rep.paragraph("Config written ready to use: <code>" + htmlEscape(best_config) + "</code>; run it with");
    rep.preformatted(adapter.appCommand(best_config));
  } else {
    rep.heading("Best setting");
    rep.paragraph("<b class=\"warn\">No complete setting.</b>");
  }
  if (j.contains("parallel_speedup"))
    rep.paragraph("Parallel speedup against one worker: <b>" + fmt(j["parallel_speedup"].get<double>(), 3) + "</b> (" +
                  std::to_string(out.workers) + " workers, " + fmt(out.wall_s, 3) + " s vs " +
                  fmt(j["single_worker_wall_s"].get<double>(), 3) + " s), results identical: " +
                  (j["parallel_same_results"].get<bool>() ? "yes" : "<b class=\"warn\">no</b>") + ".");
  rep.heading("Every setting");
  rep.paragraph(describeConsistency());
  {
    std::vector<std::string> header{"#"};
    for (const auto& p : spec.parameters) header.push_back(p.key);
    header.insert(header.end(), {spec.metric + " mean", "std", "NEES mean [band]", "NIS mean [band]", "verdict", "runs"});
    std::vector<std::vector<std::string>> rows;
    std::vector<std::string> classes;
    for (const auto& r : out.settings) {
      std::vector<std::string> row{std::to_string(r.setting.index)};
      for (const auto& v : r.setting.values) row.push_back(scalarText(v));
      const auto it = r.metrics.find(spec.metric);
      row.push_back(it != r.metrics.end() ? fmt(it->second.mean, 5) : "-");
      row.push_back(it != r.metrics.end() ? fmt(it->second.std, 3) : "-");
      row.push_back(consistencyCell(r.nees, spec.confidence));
      row.push_back(consistencyCell(r.nis, spec.confidence));
      row.push_back(r.complete ? r.verdict : (r.error.empty() ? "incomplete" : "failed: " + r.error));
      row.push_back(std::to_string(r.runs.size()));
      rows.push_back(row);
      classes.push_back(out.best && *out.best == r.setting.index ? "best"
                                                                 : (!r.complete ? "incomplete" : verdictClass(r.verdict)));
    }
    rep.table(header, rows, classes);
  }
  rep.heading("Metric against each swept parameter");
  sweepPlots(rep, spec, out);
  if (out.best) {
    rep.heading("Best setting, first seed: error, NIS, trajectories");
    const SettingResult& b = out.settings[*out.best];
    if (!b.runs.empty() && b.runs.front().series)
      addRunPlots(rep, *b.runs.front().series, "best_run", "best setting, seed 0", spec.confidence);
  }
  if (at) {
    rep.heading("Noise auto-tuning");
    rep.paragraph(htmlEscape(at->json["method"].get<std::string>()) + ". Data: " + htmlEscape(at->result.data_description) +
                  ". Start = the config's noise x " + fmt(spec.autotune.start_scale) + ". Tuned config: <code>" +
                  htmlEscape(at->config_file) + "</code>.");
    autotuneTable(rep, at->result, spec.confidence);
    if (!at->live_after.runs.empty()) {
      const auto it = at->live_after.metrics.find(spec.metric);
      const auto itb = at->live_before.metrics.find(spec.metric);
      rep.table({"live runs (sweep seeds)", spec.metric, "NEES mean [band]", "NIS mean [band]", "verdict"},
                {{"start noise", itb != at->live_before.metrics.end() ? fmt(itb->second.mean, 5) : "-",
                  consistencyCell(at->live_before.nees, spec.confidence), consistencyCell(at->live_before.nis, spec.confidence),
                  at->live_before.verdict},
                 {"tuned noise", it != at->live_after.metrics.end() ? fmt(it->second.mean, 5) : "-",
                  consistencyCell(at->live_after.nees, spec.confidence), consistencyCell(at->live_after.nis, spec.confidence),
                  at->live_after.verdict},
                 {"best grid setting", fmt(best_metric, 5), "", "", ""}});
    }
    autotunePlots(rep, at->result, spec.confidence);
  }
  rep.heading("Files");
  rep.preformatted("results (one JSON line per finished setting): " + jsonl + "\nsummary: " +
                   (fs::path(opt.out_dir) / "summary.json").string() + "\nplot data and gnuplot scripts: " +
                   (fs::path(opt.out_dir) / "plots").string());
  j["session_wall_s"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_session).count();
  nlohmann::json all = nlohmann::json::array();
  for (const auto& r : out.settings) all.push_back(r.toJson(spec));
  j["all_settings"] = all;
  return writeOutputs(rep, std::move(j), opt.out_dir);
}

nlohmann::json runSingleSession(const AdapterRegistry& registry, const SingleRunOptions& o) {
  const ScenarioAdapter& adapter = registry.get(o.scenario);
  const AdapterOptions ao = withOptions(adapter, o.scenario, o.adapter_options);
  const std::unique_ptr<ScenarioInstance> inst = adapter.loadConfig(readScenarioFile(o.config, o.set).node, ao);
  fs::create_directories(o.out_dir);
  io::LogDirectory log(o.log_dir);
  RunOptions ro;
  ro.series = true;
  ro.log = &log;
  ro.display = o.display;
  if (o.display) {
    if (o.live_view) ro.live = o.live_view("viewline_tune: " + o.scenario, inst->confidence());
    if (!ro.live) say(o.quiet, "viewline_tune: --display: no live curves (no X display)");
  }
  runtime::Progress progress = o.quiet ? runtime::Progress::quiet() : runtime::Progress("run (%)", 100);
  ro.progress = [&progress](double f) { progress.update(static_cast<long>(100.0 * f)); };
  const RunResult r = inst->run(o.seed, ro);
  progress.finish();
  log.flush();
  const double c = inst->confidence();
  nlohmann::json j;
  j["scenario"] = o.scenario;
  j["config"] = o.config;
  if (!o.set.empty()) j["config_set"] = o.set;
  j["seed"] = o.seed;
  nlohmann::json m = nlohmann::json::object();
  for (const auto& [k, v] : r.metrics) m[k] = num(v);
  j["metrics"] = m;
  j["nees"] = consistencyJson(r.nees, c);
  j["nis"] = consistencyJson(r.nis, c);
  j["verdict"] = r.verdict;
  HtmlReport rep("viewline_tune: single " + o.scenario + " run", o.out_dir);
  rep.paragraph("Config <code>" + htmlEscape(o.config) + "</code>, seed " + std::to_string(o.seed) + ". " + describeConsistency());
  std::vector<std::vector<std::string>> rows;
  for (const auto& [k, v] : r.metrics) rows.push_back({k, fmt(v, 5)});
  rep.table({"metric", "value"}, rows);
  rep.table({"statistic", "mean", "band", "samples", "verdict"},
            {{"NEES", fmt(r.nees.mean()), consistencyCell(r.nees, c), std::to_string(r.nees.count), r.nees.verdict(c)},
             {"NIS", fmt(r.nis.mean()), consistencyCell(r.nis, c), std::to_string(r.nis.count), r.nis.verdict(c)}});
  rep.paragraph("Run verdict: <b>" + htmlEscape(r.verdict) + "</b>");
  if (r.series) addRunPlots(rep, *r.series, "run", o.scenario + " seed " + std::to_string(o.seed), c);
  return writeOutputs(rep, std::move(j), o.out_dir);
}

nlohmann::json runAutotuneSession(const AdapterRegistry& registry, const AutotuneSessionOptions& o) {
  const ScenarioAdapter& adapter = registry.get(o.scenario);
  const ScenarioFile file = readScenarioFile(o.config, o.set);
  const std::unique_ptr<ScenarioInstance> base =
      adapter.loadConfig(file.node, withOptions(adapter, o.scenario, o.adapter_options));
  base->requireAutotune(o.scenario);
  fs::create_directories(o.out_dir);
  std::unique_ptr<ReplayData> data;
  if (!o.log_dir.empty()) data = base->loadLog(o.log_dir);
  AutotuneOptions ao;
  ao.outlier_prior = o.outlier_prior;
  ao.span_decades = o.span_decades;
  ao.grid_points = o.grid_points;
  ao.workers = o.workers;
  ao.confidence = base->confidence();
  if (!o.quiet) ao.progress = [](const std::string& s) { std::fprintf(stderr, "%s\n", s.c_str()); };
  const std::uint64_t verify_seed = o.verify_seed != 0 ? o.verify_seed : o.record_seed + 1;
  // The live runs keep base seed 1 unless a verification seed is given (seed 1 differs from the
  // default recording seed, 1000, too).
  const std::uint64_t live_seed = o.verify_seed != 0 ? o.verify_seed : 1;
  const AutotuneOutcome at = doAutotune(*base, file, o.out_dir, o.start_scale, data.get(), o.record_seed, o.record_runs, ao,
                                        verify_seed, o.verify_runs, o.quiet, o.config, o.start_values, live_seed);
  nlohmann::json j = at.json;
  j["scenario"] = o.scenario;
  j["config"] = o.config;
  if (!o.set.empty()) j["config_set"] = o.set;
  j["log_dir"] = o.log_dir;
  j["start_scale"] = o.start_scale;
  HtmlReport rep("viewline_tune: " + o.scenario + " noise auto-tuning", o.out_dir);
  rep.paragraph(htmlEscape(at.json["method"].get<std::string>()) + ". Data: " + htmlEscape(at.result.data_description) +
                ". Tuned config: <code>" + htmlEscape(at.config_file) + "</code>. " + describeConsistency());
  autotuneTable(rep, at.result, ao.confidence);
  rep.table({"fresh-seed check (seed " + std::to_string(verify_seed) + ", tuned noise)", "NIS mean [band]", "samples",
             "verdict"},
            {{htmlEscape(j["autotune_verify_data"].get<std::string>()), consistencyCell(at.verify_nis, ao.confidence),
              std::to_string(at.verify_nis.count), at.verify_nis.verdict(ao.confidence)}});
  if (!at.live_after.runs.empty()) {
    rep.table({"live runs (seed " + std::to_string(live_seed) + ")", "NEES mean [band]", "NIS mean [band]", "verdict"},
              {{"start noise", consistencyCell(at.live_before.nees, ao.confidence),
                consistencyCell(at.live_before.nis, ao.confidence), at.live_before.verdict},
               {"tuned noise", consistencyCell(at.live_after.nees, ao.confidence),
                consistencyCell(at.live_after.nis, ao.confidence), at.live_after.verdict}});
  }
  autotunePlots(rep, at.result, ao.confidence);
  return writeOutputs(rep, std::move(j), o.out_dir);
}

nlohmann::json runCheckSession(const AdapterRegistry& registry, const CheckOptions& o) {
  if (o.seeds < 1) throw core::InvalidInput("check: --seeds must be >= 1");
  const ScenarioAdapter& adapter = registry.get(o.scenario);
  const ScenarioFile file = readScenarioFile(o.config, o.set);
  const std::unique_ptr<ScenarioInstance> inst =
      adapter.loadConfig(file.node, withOptions(adapter, o.scenario, o.adapter_options));
  const double c = inst->confidence();
  say(o.quiet, "check: " + std::to_string(o.seeds) + " run(s) of " + o.config + " from seed " + std::to_string(o.seed));
  const SettingResult r = evaluate(*inst, o.seed, o.seeds, o.workers, c);
  if (!r.error.empty()) throw std::runtime_error("check: a run failed: " + r.error);
  nlohmann::json j;
  j["scenario"] = o.scenario;
  j["config"] = o.config;
  if (!o.set.empty()) j["config_set"] = o.set;
  j["base_seed"] = o.seed;
  j["seeds"] = o.seeds;
  j["seed_rule"] = "run i uses deriveSeed(base_seed, i)";
  j["confidence"] = c;
  j["check_nis"] = consistencyJson(r.nis, c);
  j["check_nis"]["dof"] = num(r.nis.meanDof());
  j["check_nees"] = consistencyJson(r.nees, c);
  j["check_nees"]["dof"] = num(r.nees.meanDof());
  j["check_verdict"] = r.verdict;
  nlohmann::json m = nlohmann::json::object();
  for (const auto& [k, v] : r.metrics) m[k] = {{"mean", num(v.mean)}, {"std", num(v.std)}};
  j["metrics"] = m;
  if (!o.out_dir.empty()) {
    fs::create_directories(o.out_dir);
    io::writeSummaryFile((fs::path(o.out_dir) / "summary.json").string(), j);
  }
  return j;
}

}  // namespace viewline::tuning
