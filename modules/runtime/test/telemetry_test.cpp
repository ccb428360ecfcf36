#include "viewline/runtime/telemetry.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "viewline/io/log.h"

using namespace viewline;
using runtime::InnovationRecord;
using tracking::GateDecision;

namespace {
InnovationRecord innov(const std::string& ch, double t, GateDecision d, double nis) {
  InnovationRecord r;
  r.channel = ch;
  r.t = t;
  r.rows = 2;
  r.decision = d;
  r.nis = nis;
  if (d != GateDecision::Start) {
    r.innovation = Eigen::Vector2d(0.1, -0.2);
    r.S = Eigen::Matrix2d::Identity();
  }
  return r;
}
std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}
}  // namespace

TEST(MemorySink, CountsDecisionsPerChannel) {
  runtime::MemorySink m;
  runtime::FanoutSink fan;
  fan.add(&m);
  fan.add(nullptr);
  fan.innovation(innov("a", 0.0, GateDecision::Start, 0.0));
  fan.innovation(innov("a", 0.1, GateDecision::Accept, 1.0));
  fan.innovation(innov("b", 0.1, GateDecision::Reject, 30.0));
  fan.innovation(innov("a", 0.2, GateDecision::Accept, 0.5));
  EXPECT_EQ(m.count(GateDecision::Accept), 2u);
  EXPECT_EQ(m.count(GateDecision::Accept, "b"), 0u);
  EXPECT_EQ(m.count(GateDecision::Reject, "b"), 1u);
  EXPECT_EQ(m.innovationsOf("a").size(), 3u);
  EXPECT_EQ(m.innovationsOf("").size(), 4u);
  m.clear();
  EXPECT_TRUE(m.innovations.empty());
}

TEST(CsvSink, WritesOneFilePerKindAndChannelWithStartRowsMissing) {
  const auto dir = std::filesystem::temp_directory_path() / ("viewline_csvsink_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  {
    io::LogDirectory log(dir.string());
    runtime::CsvSink sink(log);
    sink.innovation(innov("ball", 0.0, GateDecision::Start, 0.0));
    sink.innovation(innov("ball", 0.1, GateDecision::Accept, 1.25));
    runtime::EstimateRecord e;
    e.channel = "ball";
    e.t = 0.1;
    e.x = Eigen::Vector3d(1, 2, 3);
    sink.estimate(e);
    runtime::CommandRecord c;
    c.channel = "ptu";
    c.t = 0.2;
    c.u = Eigen::Vector2d(0.5, -0.5);
    sink.command(c);
    sink.flush();
  }
  const std::string in = slurp(dir / "innovations_ball.csv");
  EXPECT_NE(in.find("t,id,source,decision,nis,d0,d1,S0,S1,S2,S3"), std::string::npos) << in;
  EXPECT_NE(in.find("0,0,0,0,0,nan,nan,nan,nan,nan,nan"), std::string::npos) << in;
  EXPECT_NE(in.find("0.10000000000000001,0,0,1,1.25,0.10000000000000001,-0.20000000000000001,1,0,0,1"),
            std::string::npos)
      << in;
  EXPECT_NE(slurp(dir / "estimates_ball.csv").find("t,x0,x1,x2\n"), std::string::npos);
  EXPECT_NE(slurp(dir / "commands_ptu.csv").find("0.20000000000000001,0.5,-0.5"), std::string::npos);
  std::filesystem::remove_all(dir);
}

TEST(CsvSink, DisabledLogWritesNothing) {
  io::LogDirectory off;
  runtime::CsvSink sink(off);
  EXPECT_NO_THROW(sink.innovation(innov("x", 0.0, GateDecision::Accept, 1.0)));
}
