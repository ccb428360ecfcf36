// The DDS wrapper on loopback: round trip of a message, a deadline miss, errors that name the call.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <thread>

#include "loopback.h"
#include "viewline/nodes/dds.h"
#include "viewline/nodes/messages.h"

using namespace viewline::nodes;

namespace {

class DdsTest : public ::testing::Test {
protected:
  static void SetUpTestSuite() { xml_ = test::useLoopback(); }
  static void TearDownTestSuite() { std::remove(xml_.c_str()); }
  static inline std::string xml_;
};

// Waits until the writer has matched the reader (discovery is asynchronous).
template <class W>
bool waitMatched(const W& w, double timeout_s) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (w.matched().current < 1) {
    if (std::chrono::steady_clock::now() > end) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return true;
}

}  // namespace

TEST_F(DdsTest, DetectionRoundTripKeepsEveryField) {
  dds::Participant p(test::testDomain(1));
  dds::Topic t(p, viewline_msg_dds__Detection__desc, topic::kDetections);
  dds::Writer<DetectionMsg> w(p, t, dds::Qos::cameraWriter());
  dds::Reader<DetectionMsg> r(p, t, dds::Qos::detections());
  ASSERT_TRUE(waitMatched(w, 5.0));
  const std::string name = "right";
  DetectionMsg d{};
  d.header.stamp = toTimeMsg(1.25);
  d.header.frame_id = messageString(name);
  d.camera = 1;
  d.frame_number = 42;
  d.detected = true;
  d.pixel[0] = 320.5;
  d.pixel[1] = 200.25;
  d.covariance[0] = d.covariance[3] = 0.25;
  d.quality = 0.9;
  w.write(d);
  dds::WaitSet ws(p);
  ws.attachData(r);
  int got = 0;
  for (int i = 0; i < 50 && got == 0; ++i) {
    ws.wait(0.1);
    got += r.take([&](const DetectionMsg& m, const dds_sample_info_t&) {
      EXPECT_STREQ(m.header.frame_id, "right");
      EXPECT_DOUBLE_EQ(fromTimeMsg(m.header.stamp), 1.25);
      EXPECT_EQ(m.camera, 1u);
      EXPECT_EQ(m.frame_number, 42u);
      EXPECT_TRUE(m.detected);
      EXPECT_DOUBLE_EQ(m.pixel[0], 320.5);
      EXPECT_DOUBLE_EQ(m.pixel[1], 200.25);
      EXPECT_DOUBLE_EQ(m.covariance[3], 0.25);
    });
  }
  EXPECT_EQ(got, 1);
}

TEST_F(DdsTest, SetPointReaderNotesTheDeadlineMiss) {
  dds::Participant p(test::testDomain(2));
  dds::Topic t(p, viewline_msg_dds__SetPoint__desc, topic::kSetPoint);
  dds::Writer<SetPointMsg> w(p, t, dds::Qos::setpoints(0.05));
  dds::Reader<SetPointMsg> r(p, t, dds::Qos::setpoints(0.05));
  ASSERT_TRUE(waitMatched(w, 5.0));
  dds::WaitSet ws(p);
  ws.attachStatus(r, DDS_REQUESTED_DEADLINE_MISSED_STATUS);
  SetPointMsg m{};
  m.header.frame_id = messageString("world");
  w.write(m);
  const auto t0 = std::chrono::steady_clock::now();
  int missed = 0;
  while (missed == 0 && std::chrono::steady_clock::now() - t0 < std::chrono::seconds(2)) {
    ws.wait(0.5);
    missed = r.deadlinesMissed();
  }
  const double after = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_GE(missed, 1);
  EXPECT_GE(after, 0.05 - 0.005);  // not before the deadline
  EXPECT_LT(after, 0.05 + 0.1);    // and noticed promptly after it
}

TEST_F(DdsTest, AnInvalidDomainThrowsAnErrorNamingTheCall) {
  try {
    dds::Participant p(5000);  // beyond Cyclone's port mapping
    FAIL() << "expected a DdsError";
  } catch (const dds::DdsError& e) {
    EXPECT_NE(std::string(e.what()).find("dds_create_participant"), std::string::npos) << e.what();
    EXPECT_LT(e.code(), 0);
  }
}

TEST(Messages, TimeAndCovarianceFactorRoundTrip) {
  for (double t : {0.0, 1.5, 12.000000001, -0.25}) EXPECT_NEAR(fromTimeMsg(toTimeMsg(t)), t, 1e-9) << t;
  EXPECT_EQ(toTimeMsg(-0.25).sec, -1);
  EXPECT_EQ(toTimeMsg(-0.25).nanosec, 750000000u);
  Eigen::Matrix<double, 6, 6> A = Eigen::Matrix<double, 6, 6>::Random();
  const Eigen::Matrix<double, 6, 6> P = A * A.transpose() + 0.1 * Eigen::Matrix<double, 6, 6>::Identity();
  double packed[21];
  packCovarianceFactor(P, packed);
  EXPECT_LT((unpackCovarianceFactor(packed) - P).norm(), 1e-9 * P.norm());
  // Positive semi-definite (rank 5): still a factor with the same product.
  Eigen::Matrix<double, 6, 6> B = A;
  B.col(5).setZero();
  const Eigen::Matrix<double, 6, 6> Q = B * B.transpose();
  packCovarianceFactor(Q, packed);
  EXPECT_LT((unpackCovarianceFactor(packed) - Q).norm(), 1e-9 * Q.norm());
}
