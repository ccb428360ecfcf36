#pragma once
// A test scenario: a scalar random walk x(k+1) = x(k) + w, w ~ N(0, q_true), measured as
// y = x + e, e ~ N(0, r_true), tracked by a scalar Kalman filter with (filter.q, filter.r).
// Keys: q_true, r_true, steps, filter: {q, r}. Strict (io::ConfigNode).

#include <cmath>
#include <memory>

#include "viewline/core/error.h"
#include "viewline/core/random.h"
#include "viewline/io/config_edit.h"
#include "viewline/tuning/scenario.h"

namespace toy {

using namespace viewline;
using namespace viewline::tuning;

struct Config {
  double q_true = 0.01, r_true = 1.0, q = 0.01, r = 1.0;
  int steps = 400;
};

struct Data : ReplayData {
  std::vector<double> y;
  std::size_t measurements() const override { return y.size(); }
  std::string describe() const override { return std::to_string(y.size()) + " toy samples"; }
};

class Instance : public ScenarioInstance {
public:
  explicit Instance(Config c) : c_(c) {}
  static void filter(const std::vector<double>& y, const std::vector<double>* truth, double q, double r, Consistency& nis,
                     Consistency& nees, double& cost, double& sq) {
    double x = y.empty() ? 0.0 : y[0], P = r;
    for (std::size_t k = 1; k < y.size(); ++k) {
      P += q;
      const double S = P + r, d = y[k] - x;
      if (k > 5) {
        nis.add(d * d / S, 1.0);
        cost += std::log(S) + d * d / S;
      }
      const double K = P / S;
      x += K * d;
      P *= 1.0 - K;
      if (truth) {
        const double e = x - (*truth)[k];
        sq += e * e;
        if (k % 50 == 0) nees.add(e * e / P, 1.0);
      }
    }
  }
  void simulate(std::uint64_t seed, std::vector<double>& y, std::vector<double>& truth) const {
    core::Rng rng = core::makeRng(seed);
    double x = 0.0;
    for (int k = 0; k < c_.steps; ++k) {
      x += core::gaussian(rng, std::sqrt(c_.q_true));
      truth.push_back(x);
      y.push_back(x + core::gaussian(rng, std::sqrt(c_.r_true)));
    }
  }
  RunResult run(std::uint64_t seed, const RunOptions& o) const override {
    std::vector<double> y, t;
    simulate(seed, y, t);
    RunResult r;
    double cost = 0, sq = 0;
    filter(y, &t, c_.q, c_.r, r.nis, r.nees, cost, sq);
    r.metrics["rmse"] = std::sqrt(sq / static_cast<double>(y.size() - 1));
    r.metrics["nis_mean"] = r.nis.mean();
    r.verdict = combinedVerdict(r.nees, r.nis, 0.99);
    if (o.series) {
      r.series = std::make_shared<RunSeries>();
      r.series->nis_dof = 1.0;
      for (std::size_t k = 0; k < y.size(); ++k) {
        r.series->nis_t.push_back(static_cast<double>(k));
        r.series->nis.push_back(1.0);
      }
    }
    return r;
  }
  std::vector<NoiseParameter> noiseParameters() const override {
    return {{"process", "q", "1", "filter.q", "", c_.q}, {"measurement", "r", "1", "filter.r", "", c_.r}};
  }
  std::unique_ptr<ReplayData> record(std::uint64_t seed, int runs) const override {
    auto d = std::make_unique<Data>();
    std::vector<double> t;
    for (int i = 0; i < runs; ++i) simulate(core::deriveSeed(seed, static_cast<std::uint64_t>(i)), d->y, t);
    return d;
  }
  std::unique_ptr<ReplayData> loadLog(const std::string&) const override { throw core::InvalidInput("toy: no logs"); }
  ReplayResult replay(const ReplayData& data, const std::vector<double>& noise, double, bool) const override {
    const auto& d = dynamic_cast<const Data&>(data);
    ReplayResult r;
    Consistency nees;
    double sq = 0;
    filter(d.y, nullptr, noise[0], noise[1], r.nis, nees, r.cost, sq);
    r.terms = r.nis.count;
    return r;
  }
  std::unique_ptr<ScenarioInstance> withNoise(const std::vector<double>& n) const override {
    Config c = c_;
    c.q = n[0];
    c.r = n[1];
    return std::make_unique<Instance>(c);
  }

private:
  Config c_;
};

class Adapter : public ScenarioAdapter {
public:
  std::string name() const override { return "toy"; }
  std::string description() const override { return "scalar random walk"; }
  std::string appCommand(const std::string& p) const override { return "toy " + p; }
  std::string defaultMetric() const override { return "rmse"; }
  std::vector<std::string> metricNames() const override { return {"rmse", "nis_mean"}; }
  std::vector<AdapterOption> options() const override { return {{"scale", "1", {}, "unused"}}; }
  std::unique_ptr<ScenarioInstance> load(const YAML::Node& n, const std::string& name,
                                         const AdapterOptions&) const override {
    const io::ConfigNode root = io::ConfigNode::fromTree(n, name);  // the tree as edited, read once
    Config c;
    c.q_true = root.getOr<double>("q_true", c.q_true);
    c.r_true = root.getOr<double>("r_true", c.r_true);
    c.steps = root.getOr<int>("steps", c.steps);
    if (root.has("filter")) {
      const auto f = root.child("filter");
      c.q = f.getOr<double>("q", c.q);
      c.r = f.getOr<double>("r", c.r);
      if (!(c.q > 0)) f.fail("q", "a positive number");
    }
    root.finish();
    return std::make_unique<Instance>(c);
  }
};

inline AdapterRegistry registry() {
  AdapterRegistry r;
  r.add(std::make_unique<Adapter>());
  return r;
}

}  // namespace toy
