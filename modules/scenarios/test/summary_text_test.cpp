// A figure over nothing is "not scored" in the console summary and null in the JSON summary,
// never nan or a made-up 0.

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "viewline/io/config.h"
#include "viewline/scenarios/ball_catching.h"
#include "viewline/scenarios/mobile_capture.h"

using namespace viewline;

TEST(SummaryText, BallCatchingWithNoReachableThrowSaysNotScored) {
  std::vector<scenarios::ThrowResult> throws(2);
  for (auto& r : throws) {
    r.reachable = false;
    r.miss_reason = "not_reachable";
  }
  const scenarios::CatchSummary s = scenarios::summarise(throws, 1, std::nullopt);
  const auto cfg = scenarios::loadBallCatchingConfig(io::ConfigNode::loadFile("config/ball_catching.yaml"));
  const std::string text = scenarios::summaryText(s, cfg);
  EXPECT_EQ(text.find("nan"), std::string::npos) << text;
  EXPECT_NE(text.find("of the reachable throws not scored"), std::string::npos) << text;
  EXPECT_NE(text.find("prediction error at the crossing: not scored"), std::string::npos) << text;
  EXPECT_NE(text.find("decision time not scored"), std::string::npos) << text;
  const nlohmann::json j = scenarios::summaryJson(s, cfg);
  EXPECT_TRUE(j.at("catch_rate_reachable").is_null());
  EXPECT_EQ(j.at("catch_rate_all").get<double>(), 0.0);
}

TEST(SummaryText, MobileCaptureWithoutACaptureSaysNotScored) {
  scenarios::MobileCaptureSummary s;
  s.runs.resize(2);  // neither captured, nor did the oracle
  const auto cfg = scenarios::MobileCaptureConfig::defaults();
  const std::string text = scenarios::summaryText(s, cfg, 2, 1);
  EXPECT_EQ(text.find("nan"), std::string::npos) << text;
  EXPECT_NE(text.find("time not scored (no capture)"), std::string::npos) << text;
  EXPECT_NE(text.find("capture time / oracle: not scored"), std::string::npos) << text;
  const nlohmann::json j = nlohmann::json::parse(scenarios::summaryJson(s, cfg, 0));
  EXPECT_TRUE(j.at("capture_time_s").at("median").is_null());
  EXPECT_TRUE(j.at("capture_time_ratio_to_oracle").at("median").is_null());
  EXPECT_TRUE(j.at("oracle_capture_time_s").at("median").is_null());
}
