#include <gtest/gtest.h>

#include <cmath>

#include "toy_scenario.h"
#include "viewline/tuning/autotune.h"

using namespace viewline;
using namespace viewline::tuning;

TEST(Autotune, NelderMeadFindsAQuadraticMinimum) {
  const auto x = nelderMead([](const std::vector<double>& v) { return std::pow(v[0] - 1.5, 2) + 3.0 * std::pow(v[1] + 0.5, 2); },
                            {0.0, 0.0}, 0.5, 1e-6, 500);
  EXPECT_NEAR(x[0], 1.5, 1e-4);
  EXPECT_NEAR(x[1], -0.5, 1e-4);
}

TEST(Autotune, RecoversProcessAndMeasurementNoiseFrom10xOff) {
  toy::Config c;
  c.q_true = 0.02;
  c.r_true = 0.5;
  c.steps = 2000;
  c.q = 0.2;  // 10x off
  c.r = 5.0;  // 10x off
  const toy::Instance inst(c);
  const auto data = inst.record(11, 2);
  AutotuneOptions o;
  o.workers = 2;
  const AutotuneResult r = autotuneNoise(inst, *data, {c.q, c.r}, o);
  EXPECT_NEAR(std::log(r.tuned[0] / c.q_true), 0.0, std::log(1.5)) << r.tuned[0];
  EXPECT_NEAR(std::log(r.tuned[1] / c.r_true), 0.0, std::log(1.2)) << r.tuned[1];
  EXPECT_EQ(r.before.nis.verdict(0.99), "underconfident");
  EXPECT_EQ(r.after.nis.verdict(0.99), "consistent") << r.after.nis.mean();
  EXPECT_LT(r.after.cost, r.before.cost);
}
