#include "viewline/tuning/autotune.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "viewline/core/error.h"
#include "viewline/tuning/sweep_runner.h"

namespace viewline::tuning {

std::vector<double> nelderMead(const std::function<double(const std::vector<double>&)>& f, std::vector<double> x0,
                               double step, double tolerance, int max_evaluations, std::size_t* evaluations) {
  const std::size_t n = x0.size();
  std::vector<std::vector<double>> p(n + 1, x0);
  for (std::size_t i = 0; i < n; ++i) p[i + 1][i] += step;
  std::vector<double> fv(n + 1);
  int evals = 0;
  auto eval = [&](const std::vector<double>& x) {
    ++evals;
    const double v = f(x);
    return std::isfinite(v) ? v : std::numeric_limits<double>::infinity();
  };
  for (std::size_t i = 0; i <= n; ++i) fv[i] = eval(p[i]);
  while (evals < max_evaluations) {
    std::vector<std::size_t> order(n + 1);
    for (std::size_t i = 0; i <= n; ++i) order[i] = i;
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return fv[a] < fv[b]; });
    std::vector<std::vector<double>> ps;
    std::vector<double> fs;
    for (std::size_t i : order) {
      ps.push_back(p[i]);
      fs.push_back(fv[i]);
    }
    p = ps;
    fv = fs;
    double size = 0.0;
    for (std::size_t i = 1; i <= n; ++i)
      for (std::size_t k = 0; k < n; ++k) size = std::max(size, std::abs(p[i][k] - p[0][k]));
    if (size < tolerance) break;
    std::vector<double> c(n, 0.0);
    for (std::size_t i = 0; i < n; ++i)
      for (std::size_t k = 0; k < n; ++k) c[k] += p[i][k] / static_cast<double>(n);
    auto along = [&](double t) {
      std::vector<double> x(n);
      for (std::size_t k = 0; k < n; ++k) x[k] = c[k] + t * (p[n][k] - c[k]);
      return x;
    };
    const std::vector<double> xr = along(-1.0);
    const double fr = eval(xr);
    if (fr < fv[0]) {
      const std::vector<double> xe = along(-2.0);
      const double fe = eval(xe);
      if (fe < fr) {
        p[n] = xe;
        fv[n] = fe;
      } else {
        p[n] = xr;
        fv[n] = fr;
      }
    } else if (fr < fv[n - 1]) {
      p[n] = xr;
      fv[n] = fr;
    } else {
      const bool outside = fr < fv[n];
      const std::vector<double> xc = along(outside ? -0.5 : 0.5);
      const double fc = eval(xc);
      if (fc < std::min(fr, fv[n])) {
        p[n] = xc;
        fv[n] = fc;
      } else {
        for (std::size_t i = 1; i <= n; ++i) {
          for (std::size_t k = 0; k < n; ++k) p[i][k] = p[0][k] + 0.5 * (p[i][k] - p[0][k]);
          fv[i] = eval(p[i]);
        }
      }
    }
  }
  const std::size_t best = static_cast<std::size_t>(std::min_element(fv.begin(), fv.end()) - fv.begin());
  if (evaluations != nullptr) *evaluations = static_cast<std::size_t>(evals);
  return p[best];
}

AutotuneResult autotuneNoise(const ScenarioInstance& instance, const ReplayData& data, const std::vector<double>& start,
                             const AutotuneOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  AutotuneResult r;
  r.parameters = instance.noiseParameters();
  const std::size_t n = r.parameters.size();
  if (start.size() != n) throw core::InvalidInput("autotune: expected " + std::to_string(n) + " start values");
  for (std::size_t i = 0; i < n; ++i)
    if (!(start[i] > 0.0 && std::isfinite(start[i])))
      throw core::InvalidInput("autotune: start value of '" + r.parameters[i].name + "' must be positive (log search)");
  if (n == 0 || n > 3) throw core::InvalidInput("autotune: 1 to 3 noise parameters");
  r.start = start;
  r.data_description = data.describe();
  auto toValues = [&](const std::vector<double>& lg) {
    std::vector<double> v(n);
    for (std::size_t i = 0; i < n; ++i) v[i] = std::pow(10.0, lg[i]);
    return v;
  };
  std::vector<double> lg0(n);
  for (std::size_t i = 0; i < n; ++i) lg0[i] = std::log10(start[i]);

  // Grid stage.
  const int g = options.grid_points;
  std::size_t total = 1;
  for (std::size_t i = 0; i < n; ++i) total *= static_cast<std::size_t>(g);
  r.grid.resize(total);
  const double spacing = 2.0 * options.span_decades / (g - 1);
  if (options.progress) options.progress("auto-tune: grid of " + std::to_string(total) + " replays on " + r.data_description);
  parallelFor(total, options.workers, [&](std::size_t j) {
    std::vector<double> lg(n);
    std::size_t rem = j;
    for (std::size_t i = n; i-- > 0;) {
      lg[i] = lg0[i] - options.span_decades + spacing * static_cast<double>(rem % static_cast<std::size_t>(g));
      rem /= static_cast<std::size_t>(g);
    }
    const std::vector<double> v = toValues(lg);
    const ReplayResult rr = instance.replay(data, v, options.outlier_prior, false);
    r.grid[j] = {v, rr.cost, rr.nis.mean()};
  });
  std::size_t best = 0;
  for (std::size_t j = 1; j < total; ++j)
    if (r.grid[j].cost < r.grid[best].cost) best = j;
  std::vector<double> lgb(n);
  for (std::size_t i = 0; i < n; ++i) lgb[i] = std::log10(r.grid[best].values[i]);

  // Simplex refinement.
  if (options.progress) options.progress("auto-tune: simplex refinement");
  std::size_t simplex_evals = 0;
  const std::vector<double> lgt = nelderMead(
      [&](const std::vector<double>& lg) { return instance.replay(data, toValues(lg), options.outlier_prior, false).cost; },
      lgb, spacing, 0.002, options.max_simplex_evaluations, &simplex_evals);
  r.tuned = toValues(lgt);
  r.evaluations = total + simplex_evals;
  r.before = instance.replay(data, r.start, options.outlier_prior, true);
  r.after = instance.replay(data, r.tuned, options.outlier_prior, true);
  r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

nlohmann::json AutotuneResult::toJson(double confidence) const {
  auto num = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); };
  nlohmann::json params = nlohmann::json::object();
  for (std::size_t i = 0; i < parameters.size(); ++i) {
    params[parameters[i].name] = {{"symbol", parameters[i].symbol},
                                  {"unit", parameters[i].unit},
                                  {"config_key", parameters[i].config_key},
                                  {"start", start[i]},
                                  {"tuned", tuned[i]},
                                  {"description", parameters[i].description}};
  }
  const core::Interval bb = before.nis.bounds(confidence), ba = after.nis.bounds(confidence);
  return {{"method",
           "maximum likelihood of the innovations (sum of log|S| + d'S^-1 d, outlier mixture), grid in log10 space "
           "then Nelder-Mead; the filter re-run on the recorded measurements"},
          {"data", data_description},
          {"parameters", params},
          {"evaluations", evaluations},
          {"cost_before", num(before.cost)},
          {"cost_after", num(after.cost)},
          {"innovations", after.terms},
          {"autotune_nis_mean_before", num(before.nis.mean())},
          {"autotune_nis_bounds_before", {num(bb.lo), num(bb.hi)}},
          {"autotune_nis_verdict_before", before.nis.verdict(confidence)},
          {"autotune_nis_mean", num(after.nis.mean())},
          {"autotune_nis_bounds", {num(ba.lo), num(ba.hi)}},
          {"autotune_nis_verdict", after.nis.verdict(confidence)},
          {"autotune_nis_dof", num(after.nis.meanDof())},
          {"autotune_nis_samples", after.nis.count},
          {"autotune_wall_s", wall_s}};
}

}  // namespace viewline::tuning
