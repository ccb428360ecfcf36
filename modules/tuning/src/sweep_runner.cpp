#include "viewline/tuning/sweep_runner.h"

#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <fstream>
#include <mutex>
#include <sstream>
#include <thread>
#ifdef _OPENMP
#include <omp.h>
#endif
#include <opencv2/core/utility.hpp>

#include "viewline/core/error.h"
#include "viewline/core/random.h"
#include "viewline/tuning/yaml_edit.h"

namespace viewline::tuning {

namespace {

nlohmann::json num(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); }

nlohmann::json yamlToJson(const YAML::Node& n) {
  if (!n.IsScalar()) return scalarText(n);
  const std::string& s = n.Scalar();
  try {
    std::size_t pos = 0;
    const double v = std::stod(s, &pos);
    if (pos == s.size()) return v;
  } catch (const std::exception&) {
  }
  if (s == "true") return true;
  if (s == "false") return false;
  return s;
}

nlohmann::json consistencyJson(const Consistency& c, double confidence) {
  const core::Interval b = c.bounds(confidence);
  return {{"mean", num(c.mean())},
          {"bounds", {num(b.lo), num(b.hi)}},
          {"dof", num(c.meanDof())},
          {"samples", c.count},
          {"verdict", c.verdict(confidence)}};
}

/// The runs are the unit of parallelism: while parallelFor runs, OpenCV's own pool (TBB in
/// Debian's build) is switched off (cv::setNumThreads(0): every OpenCV call runs sequentially in
/// the calling worker), so a run's image processing does not compete with the other workers for
/// the cores (oversubscription, and one worker's parallel_for_ waiting for threads busy with
/// another's). Restored afterwards. Every parallelFor does this, whatever its worker count, so a
/// 1-worker and an N-worker sweep run the libraries the same way (same results).
class SerialLibraryThreads {
public:
  SerialLibraryThreads() : previous_(cv::getNumThreads()) { cv::setNumThreads(0); }
  ~SerialLibraryThreads() { cv::setNumThreads(previous_); }
  SerialLibraryThreads(const SerialLibraryThreads&) = delete;
  SerialLibraryThreads& operator=(const SerialLibraryThreads&) = delete;

private:
  int previous_;
};

/// ViSP's targets compile with -fopenmp: an OpenMP region inside a run would start a team of
/// OMP_NUM_THREADS (= cores) threads per worker. The team size is a per-thread setting, so each
/// worker (and the caller, restored) uses one thread. (Eigen is already EIGEN_DONT_PARALLELIZE.)
class OpenMpSerialInThisThread {
public:
#ifdef _OPENMP
  OpenMpSerialInThisThread() : previous_(omp_get_max_threads()) { omp_set_num_threads(1); }
  ~OpenMpSerialInThisThread() { omp_set_num_threads(previous_); }
#else
  OpenMpSerialInThisThread() = default;
#endif
  OpenMpSerialInThisThread(const OpenMpSerialInThisThread&) = delete;
  OpenMpSerialInThisThread& operator=(const OpenMpSerialInThisThread&) = delete;

private:
#ifdef _OPENMP
  int previous_;
#endif
};

}  // namespace

double processCpuSeconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
         1e-6 * static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

void aggregate(SettingResult& r, double confidence) {
  r.metrics.clear();
  r.nees = {};
  r.nis = {};
  r.complete = !r.runs.empty();
  std::map<std::string, std::vector<double>> values;
  for (const RunResult& run : r.runs) {
    if (!run.error.empty()) {
      r.complete = false;
      if (r.error.empty()) r.error = run.error;
      continue;
    }
    for (const auto& [k, v] : run.metrics) values[k].push_back(v);
    r.nees.merge(run.nees);
    r.nis.merge(run.nis);
  }
  for (const auto& [k, v] : values) {
    MetricStats s;
    std::vector<double> finite;
    for (double x : v)
      if (std::isfinite(x)) finite.push_back(x);
    s.n = finite.size();
    if (s.n == 0) {
      s.mean = s.std = s.min = s.max = std::nan("");
    } else {
      double sum = 0.0;
      for (double x : finite) sum += x;
      s.mean = sum / static_cast<double>(s.n);
      double ss = 0.0;
      for (double x : finite) ss += (x - s.mean) * (x - s.mean);
      s.std = s.n > 1 ? std::sqrt(ss / static_cast<double>(s.n - 1)) : 0.0;
      s.min = *std::min_element(finite.begin(), finite.end());
      s.max = *std::max_element(finite.begin(), finite.end());
    }
    r.metrics[k] = s;
  }
  r.verdict = combinedVerdict(r.nees, r.nis, confidence);
}

nlohmann::json SettingResult::toJson(const SweepSpec& spec) const {
  nlohmann::json j;
  j["index"] = setting.index;
  nlohmann::json values = nlohmann::json::object();
  for (std::size_t k = 0; k < spec.parameters.size() && k < setting.values.size(); ++k)
    values[spec.parameters[k].key] = yamlToJson(setting.values[k]);
  j["values"] = values;
  j["complete"] = complete;
  if (!error.empty()) j["error"] = error;
  j["runs"] = runs.size();
  nlohmann::json m = nlohmann::json::object();
  for (const auto& [k, s] : metrics)
    m[k] = {{"mean", num(s.mean)}, {"std", num(s.std)}, {"min", num(s.min)}, {"max", num(s.max)}, {"n", s.n}};
  j["metrics"] = m;
  j["nees"] = consistencyJson(nees, spec.confidence);
  j["nis"] = consistencyJson(nis, spec.confidence);
  j["verdict"] = verdict;
  nlohmann::json per_run = nlohmann::json::array();
  for (const RunResult& r : runs) {
    nlohmann::json pr{{"seed", r.seed}, {"verdict", r.verdict}, {"nees_mean", num(r.nees.mean())},
                      {"nis_mean", num(r.nis.mean())}, {"wall_s", r.wall_s}};
    auto it = r.metrics.find(spec.metric);
    pr[spec.metric] = it != r.metrics.end() ? num(it->second) : nlohmann::json();
    if (!r.error.empty()) pr["error"] = r.error;
    per_run.push_back(pr);
  }
  j["per_run"] = per_run;
  return j;
}

std::string formatProgress(const SweepProgress& p) {
  char buf[160];
  if (p.done == 0 || p.done == p.total)
    std::snprintf(buf, sizeof buf, "[%zu/%zu] %.1f s elapsed", p.done, p.total, p.elapsed_s);
  else
    std::snprintf(buf, sizeof buf, "[%zu/%zu] %.1f s elapsed, ETA %.0f s", p.done, p.total, p.elapsed_s, p.eta_s);
  return buf;
}

std::size_t parallelFor(std::size_t n, int workers, const std::function<void(std::size_t)>& job,
                        const std::atomic<bool>* stop, const std::function<void(std::size_t)>& after) {
  if (workers <= 0) workers = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  workers = static_cast<int>(std::min<std::size_t>(static_cast<std::size_t>(workers), std::max<std::size_t>(n, 1)));
  const SerialLibraryThreads serial_libraries;
  std::atomic<std::size_t> next{0};
  std::atomic<std::size_t> ran{0};
  std::mutex after_mutex;
  // An exception thrown by a job (or `after`) on a worker thread would end the process
  // (std::terminate): the first one is kept, the other workers stop taking jobs, and it is
  // rethrown to the caller once every worker has joined.
  std::mutex error_mutex;
  std::exception_ptr error;
  std::atomic<bool> failed{false};
  auto loop = [&]() {
    const OpenMpSerialInThisThread omp_serial;
    try {
      for (;;) {
        if (failed.load() || (stop != nullptr && stop->load())) return;
        const std::size_t i = next.fetch_add(1);
        if (i >= n) return;
        job(i);
        ran.fetch_add(1);
        if (after) {
          std::lock_guard<std::mutex> lock(after_mutex);
          after(i);
        }
      }
    } catch (...) {
      std::lock_guard<std::mutex> lock(error_mutex);
      if (!error) error = std::current_exception();
      failed.store(true);
    }
  };
  if (workers == 1) {
    loop();
  } else {
    std::vector<std::thread> threads;
    for (int w = 0; w < workers; ++w) threads.emplace_back(loop);
    for (auto& t : threads) t.join();
  }
  if (error) std::rethrow_exception(error);
  return ran.load();
}

SweepOutcome runSweep(const SweepSpec& spec, const std::vector<Setting>& settings,
                      const std::vector<std::unique_ptr<ScenarioInstance>>& instances, const SweepOptions& options) {
  if (instances.size() != settings.size()) throw core::InvalidInput("runSweep: one scenario instance per setting");
  SweepOutcome out;
  out.workers = options.workers > 0 ? options.workers
                                    : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  const std::size_t seeds = static_cast<std::size_t>(spec.seeds);
  out.jobs_total = settings.size() * seeds;
  out.settings.resize(settings.size());
  for (std::size_t i = 0; i < settings.size(); ++i) {
    out.settings[i].setting = settings[i];
    out.settings[i].runs.resize(seeds);
  }
  std::vector<int> has_result(out.jobs_total, 0);
  std::vector<std::size_t> remaining(settings.size(), seeds);
  std::ofstream jsonl;
  if (!options.results_jsonl.empty()) {
    jsonl.open(options.results_jsonl, std::ios::app);
    if (!jsonl) throw core::InvalidInput(options.results_jsonl + ": cannot open for appending");
  }
  const auto t0 = std::chrono::steady_clock::now();
  const double cpu0 = processCpuSeconds();
  std::size_t done = 0;
  double last_report = -1.0;

  auto job = [&](std::size_t j) {
    const std::size_t si = j / seeds, ri = j % seeds;
    RunResult& slot = out.settings[si].runs[ri];
    const std::uint64_t seed = core::deriveSeed(spec.base_seed, ri);
    RunOptions ro;
    ro.series = options.series_for_first_seed && ri == 0;
    const auto w0 = std::chrono::steady_clock::now();
    try {
      slot = instances[si]->run(seed, ro);
    } catch (const std::exception& e) {
      slot = RunResult{};
      slot.error = e.what();
    }
    slot.seed = seed;
    slot.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count();
    has_result[j] = 1;
  };
  auto after = [&](std::size_t j) {  // serialised by parallelFor
    ++done;
    const std::size_t si = j / seeds;
    if (--remaining[si] == 0) {
      aggregate(out.settings[si], spec.confidence);
      if (jsonl.is_open()) {
        jsonl << out.settings[si].toJson(spec).dump() << "\n";
        jsonl.flush();
      }
    }
    const double el = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (options.progress && (el - last_report >= options.progress_interval_s || done == out.jobs_total)) {
      last_report = el;
      SweepProgress p;
      p.done = done;
      p.total = out.jobs_total;
      p.elapsed_s = el;
      p.eta_s = el / static_cast<double>(done) * static_cast<double>(out.jobs_total - done);
      options.progress(p);
    }
  };
  parallelFor(out.jobs_total, out.workers, job, options.stop, after);
  out.jobs_done = done;
  out.interrupted = done < out.jobs_total;
  for (std::size_t si = 0; si < settings.size(); ++si) {
    SettingResult& r = out.settings[si];
    if (remaining[si] != 0) {
      // Incomplete (interrupted): keep only the runs that finished.
      std::vector<RunResult> kept;
      for (std::size_t ri = 0; ri < seeds; ++ri)
        if (has_result[si * seeds + ri]) kept.push_back(r.runs[ri]);
      r.runs = kept;
      aggregate(r, spec.confidence);
      r.complete = false;
    }
  }
  out.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  out.cpu_s = processCpuSeconds() - cpu0;
  out.best = bestSetting(spec, out.settings);
  return out;
}

std::optional<std::size_t> bestSetting(const SweepSpec& spec, const std::vector<SettingResult>& settings) {
  std::optional<std::size_t> best;
  double best_v = 0.0;
  for (std::size_t i = 0; i < settings.size(); ++i) {
    const SettingResult& r = settings[i];
    if (!r.complete) continue;
    const auto it = r.metrics.find(spec.metric);
    if (it == r.metrics.end() || !std::isfinite(it->second.mean)) continue;
    const double v = it->second.mean;
    if (!best || (spec.minimize ? v < best_v : v > best_v)) {
      best = i;
      best_v = v;
    }
  }
  return best;
}

bool sameResults(const SweepOutcome& a, const SweepOutcome& b, std::string* first_difference) {
  auto differ = [&](const std::string& what) {
    if (first_difference != nullptr) *first_difference = what;
    return false;
  };
  if (a.settings.size() != b.settings.size()) return differ("number of settings");
  for (std::size_t i = 0; i < a.settings.size(); ++i) {
    const auto& ra = a.settings[i].runs;
    const auto& rb = b.settings[i].runs;
    if (ra.size() != rb.size()) return differ("runs of setting " + std::to_string(i));
    for (std::size_t k = 0; k < ra.size(); ++k) {
      auto same = [](double x, double y) { return x == y || (std::isnan(x) && std::isnan(y)); };
      bool eq = ra[k].metrics.size() == rb[k].metrics.size();
      for (auto ia = ra[k].metrics.begin(), ib = rb[k].metrics.begin(); eq && ia != ra[k].metrics.end(); ++ia, ++ib)
        eq = ia->first == ib->first && same(ia->second, ib->second);
      if (!eq) return differ("metrics of setting " + std::to_string(i) + " run " + std::to_string(k));
      if (ra[k].nees.sum != rb[k].nees.sum || ra[k].nis.sum != rb[k].nis.sum || ra[k].nis.count != rb[k].nis.count)
        return differ("consistency of setting " + std::to_string(i) + " run " + std::to_string(k));
    }
  }
  return true;
}

}  // namespace viewline::tuning
