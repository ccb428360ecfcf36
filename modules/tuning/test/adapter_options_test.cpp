// The adapters' options: declared once with type, range and default (AdapterOption, OptionTable),
// checked in one place whichever way they are given (sweep file, --option, a direct load).

#include <gtest/gtest.h>

#include <limits>

#include "adapter_util.h"
#include "toy_scenario.h"
#include "viewline/core/error.h"
#include "viewline/tuning/scenario.h"

using namespace viewline;
using namespace viewline::tuning;

namespace {

template <class F>
std::string errorOf(F&& f) {
  try {
    f();
  } catch (const core::InvalidInput& e) {
    return e.what();
  }
  ADD_FAILURE() << "no InvalidInput thrown";
  return {};
}

enum class Clock { Free, Alternating };

struct Opts {
  double duration;
  int burn_in;
  std::uint64_t seed;
  Clock clock;
  bool outliers;
};

detail::OptionTable<Opts> table() {
  detail::OptionTable<Opts> t;
  t.number("duration", &Opts::duration, "0", 0.0, std::numeric_limits<double>::infinity(), "s (0: the config's)")
      .integer("burn_in", &Opts::burn_in, "5", 1, 1000, "measurements")
      .integer("seed", &Opts::seed, "7", 0, 1e15, "seed")
      .choice<Clock>("clock", &Opts::clock, "free", {{"free", Clock::Free}, {"alternating", Clock::Alternating}}, "clock")
      .choice<bool>("outliers", &Opts::outliers, "config", {{"config", true}, {"none", false}}, "outliers");
  return t;
}

}  // namespace

TEST(AdapterOptions, TypeAndRangeAreChecked) {
  const std::vector<AdapterOption> o = table().options();
  ASSERT_EQ(o.size(), 5u);
  struct Case {
    std::size_t option;
    const char* text;
    bool accepted;
  };
  const Case cases[] = {{0, "0", true},    {0, "2.5", true},  {0, "-0.1", false}, {0, "inf", false},
                        {0, "nan", false}, {0, "2s", false},  {0, "", false},     {1, "1", true},
                        {1, "1000", true}, {1, "0", false},   {1, "1001", false}, {1, "2.5", false},
                        {3, "alternating", true}, {3, "Alternating", false}, {4, "none", true}};
  for (const Case& c : cases) EXPECT_EQ(o[c.option].accepts(c.text), c.accepted) << o[c.option].name << " '" << c.text << "'";
  EXPECT_TRUE(o[1].integer);
  EXPECT_EQ(o[0].expected(), "a number >= 0");
  EXPECT_EQ(o[1].expected(), "an integer in [1, 1000]");
  EXPECT_EQ(o[3].expected(), "one of: free, alternating");
}

TEST(AdapterOptions, CheckedOptionsFillDefaultsAndNameTheRefusedOne) {
  const std::vector<AdapterOption> o = table().options();
  const AdapterOptions d = checkedOptions(o, {}, "toy");
  EXPECT_EQ(d.at("burn_in"), "5");
  EXPECT_EQ(d.at("clock"), "free");
  EXPECT_EQ(checkedOptions(o, {{"burn_in", "9"}}, "toy").at("burn_in"), "9");
  const std::string range = errorOf([&] { checkedOptions(o, {{"burn_in", "0"}}, "toy"); });
  EXPECT_EQ(range, "toy adapter option 'burn_in': expected an integer in [1, 1000], got '0'");
  const std::string unknown = errorOf([&] { checkedOptions(o, {{"burnin", "3"}}, "toy"); });
  EXPECT_NE(unknown.find("'burnin' is not an option"), std::string::npos) << unknown;
}

TEST(AdapterOptions, TableReadsTheCheckedValuesIntoTheStruct) {
  const detail::OptionTable<Opts> t = table();
  const Opts d = t.read(checkedOptions(t.options(), {}, "toy"));
  EXPECT_EQ(d.duration, 0.0);
  EXPECT_EQ(d.burn_in, 5);
  EXPECT_EQ(d.seed, 7u);
  EXPECT_EQ(d.clock, Clock::Free);
  EXPECT_TRUE(d.outliers);
  const Opts g = t.read(checkedOptions(
      t.options(), {{"duration", "1.5"}, {"seed", "123456789012"}, {"clock", "alternating"}, {"outliers", "none"}}, "toy"));
  EXPECT_EQ(g.duration, 1.5);
  EXPECT_EQ(g.seed, 123456789012u);
  EXPECT_EQ(g.clock, Clock::Alternating);
  EXPECT_FALSE(g.outliers);
}

// A sweep file's `adapter:` map is checked against the same declarations, naming its line.
TEST(AdapterOptions, SweepFileValuesNameTheirLine) {
  int loads = 0;
  const auto adapter = detail::makeAdapter(detail::AdapterInfo{"toy", "toy", "toy", "", "rmse", true, {"rmse"}}, table(),
                                           [&loads](const io::ConfigNode& config, const Opts& o) {
                                             ++loads;
                                             config.finish();
                                             EXPECT_EQ(o.burn_in, 3);
                                             return std::make_unique<toy::Instance>(toy::Config{});
                                           });
  const io::ConfigNode node = io::ConfigNode::fromString("burn_in: 3\nclock: alternating\n", "sweep.yaml");
  const AdapterOptions read = readAdapterOptions(*adapter, &node);
  EXPECT_EQ(read.at("burn_in"), "3");
  EXPECT_EQ(read.at("duration"), "0");
  const io::ConfigNode bad = io::ConfigNode::fromString("clock: free\nburn_in: 0\n", "sweep.yaml");
  const std::string e = errorOf([&] { readAdapterOptions(*adapter, &bad); });
  EXPECT_EQ(e.rfind("sweep.yaml:2:1: key 'burn_in': expected an integer in [1, 1000]", 0), 0u) << e;

  // A direct load checks them too, before the scenario is read.
  const std::string direct = errorOf([&] { adapter->load(YAML::Load("steps: 10"), "toy.yaml", {{"duration", "-1"}}); });
  EXPECT_NE(direct.find("toy adapter option 'duration': expected a number >= 0"), std::string::npos) << direct;
  EXPECT_EQ(loads, 0);
  EXPECT_NE(adapter->load(YAML::Node(), "toy.yaml", {{"burn_in", "3"}}), nullptr);
  EXPECT_EQ(loads, 1);
}
