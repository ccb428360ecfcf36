#include "viewline/runtime/scheduler.h"

#include <gtest/gtest.h>

#include <chrono>
#include <string>
#include <vector>

#include "viewline/core/error.h"
#include "viewline/runtime/delay_line.h"

using namespace viewline;
using runtime::Scheduler;
namespace prio = runtime::priority;

TEST(Scheduler, RunsEventsInTimeThenPriorityThenInsertionOrder) {
  Scheduler s;
  std::vector<std::string> log;
  s.at(2.0, prio::Control, [&](double) { log.push_back("c2"); });
  s.at(1.0, prio::Capture, [&](double) { log.push_back("cap1"); });
  s.at(1.0, prio::Physics, [&](double) { log.push_back("phys1"); });
  s.at(1.0, prio::Capture, [&](double) { log.push_back("cap1b"); });
  s.at(0.5, prio::Telemetry, [&](double t) { log.push_back("tel" + std::to_string(t)); });
  EXPECT_EQ(s.runUntil(1.5), 4u);
  EXPECT_DOUBLE_EQ(s.now(), 1.5);
  s.runUntil(10.0);
  const std::vector<std::string> want{"tel0.500000", "phys1", "cap1", "cap1b", "c2"};
  EXPECT_EQ(log, want);
  EXPECT_EQ(s.pending(), 0u);
}

TEST(Scheduler, PeriodicTimesAccumulateExactlyLikeAHandWrittenLoop) {
  const double period = 0.001;  // not a binary fraction: accumulation differs from k * period
  Scheduler s;
  std::vector<double> got;
  s.every(0.0, period, prio::Control, [&](double t) { got.push_back(t); });
  s.runUntil(0.7);
  std::vector<double> want;
  for (double t = 0.0; t <= 0.7; t += period) want.push_back(t);
  ASSERT_EQ(got.size(), want.size());
  for (std::size_t i = 0; i < got.size(); ++i) EXPECT_EQ(got[i], want[i]) << i;  // bit for bit
}

TEST(Scheduler, EventsScheduledWhileRunningAreOrderedWithTheRest) {
  Scheduler s;
  std::vector<double> t_run;
  s.at(1.0, 0, [&](double t) {
    t_run.push_back(t);
    s.at(1.0, 0, [&](double u) { t_run.push_back(u + 0.5); });  // same time: after this one
    s.at(1.2, 0, [&](double u) { t_run.push_back(u); });
  });
  s.at(1.1, 0, [&](double t) { t_run.push_back(t); });
  s.runUntil(2.0);
  EXPECT_EQ(t_run, (std::vector<double>{1.0, 1.5, 1.1, 1.2}));
  EXPECT_THROW(s.at(1.9, 0, [](double) {}), core::InvalidInput);  // in the past
}

TEST(Scheduler, CancelStopsOneShotAndPeriodicEventsEvenFromTheirOwnAction) {
  Scheduler s;
  int a = 0, b = 0;
  const auto id_a = s.at(1.0, 0, [&](double) { ++a; });
  runtime::EventId id_b = 0;
  id_b = s.every(0.0, 0.25, 0, [&](double t) {
    ++b;
    if (t >= 0.5) s.cancel(id_b);
  });
  s.cancel(id_a);
  s.runUntil(5.0);
  EXPECT_EQ(a, 0);
  EXPECT_EQ(b, 3);  // 0, 0.25, 0.5
  EXPECT_EQ(s.pending(), 0u);
  EXPECT_FALSE(s.nextTime().has_value());
}

TEST(Scheduler, PeriodicEventEndsAtItsLimitInclusive) {
  Scheduler s;
  int n = 0;
  s.every(0.0, 0.5, 0, [&](double) { ++n; }, 2.0);
  s.runUntil(100.0);
  EXPECT_EQ(n, 5);
}

TEST(Scheduler, StopRequestReturnsBeforeTheNextEvent) {
  Scheduler s;
  int n = 0;
  s.every(0.0, 1.0, 0, [&](double t) {
    ++n;
    if (t == 2.0) s.requestStop();
  });
  s.runUntil(10.0);
  EXPECT_EQ(n, 3);
  EXPECT_TRUE(s.stopRequested());
  EXPECT_DOUBLE_EQ(s.now(), 2.0);
  s.clearStop();
  s.runUntil(4.0);
  EXPECT_EQ(n, 5);
}

TEST(Scheduler, BadInputIsRefused) {
  Scheduler s;
  EXPECT_THROW(s.every(0.0, 0.0, 0, [](double) {}), core::InvalidInput);
  EXPECT_THROW(s.every(0.0, -1.0, 0, [](double) {}), core::InvalidInput);
  EXPECT_THROW(s.at(std::numeric_limits<double>::quiet_NaN(), 0, [](double) {}), core::InvalidInput);
  EXPECT_THROW(s.at(1.0, 0, Scheduler::Action{}), core::InvalidInput);
  EXPECT_THROW(s.setPacing({-1.0}), core::InvalidInput);
  EXPECT_THROW(Scheduler(std::numeric_limits<double>::infinity()), core::InvalidInput);
}

TEST(Scheduler, PacedRunFollowsTheWallClockAndRunsTheSameEvents) {
  auto run = [](double factor, double* wall_s) {
    Scheduler s;
    s.setPacing({factor});
    std::vector<double> got;
    s.every(0.0, 0.01, 0, [&](double t) { got.push_back(t); });
    s.at(0.055, 1, [&](double t) { got.push_back(-t); });
    const auto w0 = std::chrono::steady_clock::now();
    s.runUntil(1.0);
    *wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count();
    return got;
  };
  double fast_s = 0.0, paced_s = 0.0;
  const auto fast = run(0.0, &fast_s);
  const auto paced = run(10.0, &paced_s);  // 1 s simulated in 0.1 s of wall time
  EXPECT_EQ(fast, paced);
  EXPECT_GE(paced_s, 0.099);  // never early
  EXPECT_LT(fast_s, 0.05);
}

TEST(DelayLine, DeliversInOrderOnceAvailable) {
  runtime::DelayLine<int> line;
  line.send(0.3, 1);
  line.send(0.2, 2);  // sent later, available earlier: FIFO keeps it behind 1
  line.send(0.5, 3);
  std::vector<std::pair<double, int>> got;
  auto take = [&](double t, int v) { got.emplace_back(t, v); };
  EXPECT_EQ(line.receive(0.25, take), 0u);
  EXPECT_EQ(line.receive(0.3, take), 2u);
  EXPECT_EQ(line.size(), 1u);
  EXPECT_DOUBLE_EQ(line.nextAvailable(), 0.5);
  EXPECT_EQ(got, (std::vector<std::pair<double, int>>{{0.3, 1}, {0.2, 2}}));
  EXPECT_THROW(line.send(std::numeric_limits<double>::quiet_NaN(), 4), core::InvalidInput);
}

TEST(Scheduler, ASignalsStopRequestEndsTheRunBeforeTheNextEvent) {
  Scheduler s;
  int runs = 0;
  s.every(0.0, 0.1, prio::Control, [&](double t) {
    ++runs;
    if (t >= 0.25) core::noteInterrupt(2);  // what the apps' SIGINT handler records
  });
  s.runUntil(10.0);
  const bool stopped = s.stopRequested();
  s.clearStop();  // the process-wide request is not the scheduler's to forget
  const bool still = s.stopRequested();
  core::clearInterrupt();
  EXPECT_EQ(runs, 4);  // 0, 0.1, 0.2, 0.3: nothing after the request
  EXPECT_NEAR(s.now(), 0.3, 1e-12);
  EXPECT_TRUE(stopped);
  EXPECT_TRUE(still);
  EXPECT_FALSE(s.stopRequested());
  s.runUntil(0.45);
  EXPECT_EQ(runs, 5);  // goes on once the request is cleared
}
