// The nodes as separate processes on loopback (CYCLONEDDS_URI: no multicast, 127.0.0.1 as the
// only peer; each test in its own DDS domain): the track of world + 2 cameras + tracker matches
// the same simulation tracked in one process, and the faults: the tracker killed (the robot halts
// within its set-point deadline), a camera killed (the tracker notes it within the liveliness
// lease and goes on) and restarted (it rejoins), a camera with another rig (refused).
#include <gtest/gtest.h>

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "loopback.h"
#include "viewline/io/config_edit.h"
#include "viewline/nodes/dds.h"
#include "viewline/nodes/simulation.h"
#include "viewline/tracking/tracker.h"

extern char** environ;

using namespace viewline;
using Clock = std::chrono::steady_clock;

namespace {

const std::string kConfig = "config/ball_catching.yaml";

double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// Node processes of one test: each with its log file; every one still running at the end is
// killed and reaped (no process is left behind, whatever the test's outcome).
class Nodes {
public:
  explicit Nodes(std::string tag) : dir_("/tmp/viewline_nodes_" + tag + "_" + std::to_string(getpid())) {
    if (std::system(("mkdir -p " + dir_).c_str()) != 0) ADD_FAILURE() << "cannot make " << dir_;
  }
  ~Nodes() {
    for (auto& [name, pid] : pids_) {
      if (pid <= 0) continue;
      kill(pid, SIGKILL);
      waitpid(pid, nullptr, 0);
    }
    // The logs stay for a failed test (its messages name them), go otherwise.
    if (!::testing::Test::HasFailure()) std::system(("rm -rf " + dir_).c_str());
  }
  std::string path(const std::string& file) const { return dir_ + "/" + file; }

  void start(const std::string& name, std::vector<std::string> args) {
    args.insert(args.begin(), VIEWLINE_NODE_BIN);
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    const std::string log = path(name + ".log");
    posix_spawn_file_actions_addopen(&fa, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_adddup2(&fa, 1, 2);
    pid_t pid = 0;
    const int rc = posix_spawn(&pid, argv[0], &fa, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&fa);
    ASSERT_EQ(rc, 0) << "posix_spawn " << argv[0];
    pids_[name] = pid;
  }
  // Exit status of node `name` once it ends (-1: still running after timeout_s, then killed).
  int wait(const std::string& name, double timeout_s) {
    pid_t& pid = pids_.at(name);
    const auto t0 = Clock::now();
    while (since(t0) < timeout_s) {
      int st = 0;
      if (waitpid(pid, &st, WNOHANG) == pid) {
        pid = 0;
        return WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return -1;
  }
  void killNode(const std::string& name) {
    pid_t& pid = pids_.at(name);
    kill(pid, SIGKILL);
    waitpid(pid, nullptr, 0);
    pid = 0;
  }
  std::string log(const std::string& name) const {
    std::ifstream f(path(name + ".log"));
    std::stringstream ss;
    ss << f.rdbuf();
    return ss.str();
  }
  // Waits until node `name`'s log contains `text`.
  bool waitForLog(const std::string& name, const std::string& text, double timeout_s) const {
    const auto t0 = Clock::now();
    while (since(t0) < timeout_s) {
      if (log(name).find(text) != std::string::npos) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return false;
  }
  nlohmann::json summary(const std::string& name) const {
    std::ifstream f(path(name + ".json"));
    if (!f) return {};
    return nlohmann::json::parse(f);
  }
  // The common arguments of node `name` (role, config, domain, seed, summary file). The tracker
  // skips the camera-to-robot registration unless `registered` (the in-process references below
  // track with the calibrated rig, and it saves seconds).
  std::vector<std::string> args(const std::string& role, const std::string& name, int domain,
                                std::vector<std::string> more = {}, bool registered = false,
                                const std::string& seed = "3") const {
    std::vector<std::string> a{role, "--config", kConfig, "--domain", std::to_string(domain), "--seed", seed,
                               "--summary", path(name + ".json"), "--max-wall", "40"};
    if (role == "tracker" && !registered) a.insert(a.end(), {"--set", "registration.enabled=false"});
    a.insert(a.end(), more.begin(), more.end());
    return a;
  }

private:
  std::string dir_;
  std::map<std::string, pid_t> pids_;
};

class NodesLoopback : public ::testing::Test {
protected:
  static void SetUpTestSuite() { xml_ = nodes::test::useLoopback(); }
  static void TearDownTestSuite() { std::remove(xml_.c_str()); }
  static inline std::string xml_;
};

}  // namespace

TEST_F(NodesLoopback, TrackOfTwoCameraNodesMatchesTheInProcessTrack) {
  const int domain = nodes::test::testDomain(11);
  Nodes n("track");
  n.start("tracker", n.args("tracker", "tracker", domain));
  n.start("camera0", n.args("camera", "camera0", domain, {"--camera", "0"}));
  n.start("camera1", n.args("camera", "camera1", domain, {"--camera", "1"}));
  n.start("world", n.args("world", "world", domain, {"--expect", "3", "--duration", "1.5"}));
  ASSERT_EQ(n.wait("world", 30.0), 0) << n.log("world");
  for (const char* name : {"tracker", "camera0", "camera1"}) ASSERT_EQ(n.wait(name, 10.0), 0) << n.log(name);

  const nlohmann::json tr = n.summary("tracker");
  ASSERT_TRUE(tr.contains("x") && tr.at("initialised") == true) << tr.dump(1);
  for (int c = 0; c < 2; ++c) {
    const nlohmann::json cam = n.summary("camera" + std::to_string(c));
    const auto frames = cam.at("frames").get<std::uint64_t>();
    const auto received = tr.at("cameras").at(c).at("received").get<std::uint64_t>();
    EXPECT_GE(frames, 70u);                        // 1.5 s at 50 Hz
    EXPECT_GE(received, frames * 95 / 100) << c;  // best effort on loopback: nearly all
    EXPECT_LE(received, frames) << c;
    // Clocks in step: −min(delay) is minus the smallest transport delay (loopback: well under 1 ms).
    EXPECT_NEAR(tr.at("cameras").at(c).at("apparent_clock_offset_s").get<double>(), 0.0, 1e-3) << c;
  }

  // The same simulation in one process: every frame of both generators, in capture order, into
  // the tracker the scenario builds, up to the nodes' last estimate.
  const auto cfg = scenarios::loadBallCatchingConfig(io::loadConfigWithValues(kConfig, {}));
  const double t_dds = tr.at("t").get<double>();
  const nodes::WorldTruth truth(cfg, 3, 0.2);
  std::vector<nodes::DetectionGenerator> gens;
  std::vector<core::Camera> cams;
  for (std::size_t i = 0; i < 2; ++i) {
    gens.emplace_back(cfg, i, 3, 0.5);
    cams.push_back(cfg.cameras[i].estimatorCamera());
  }
  tracking::ViewlineTracker ref(cams, cfg.tracker);
  std::uint64_t id = 1;
  for (int j = 0; j * 0.002 <= 1.5; ++j) {
    const double t = j * 0.002;
    std::optional<Eigen::Vector3d> p;
    if (truth.inFlight(t)) p = truth.state(t).p;
    for (std::size_t i = 0; i < 2; ++i) {
      const auto f = gens[i].onTick(t, p);
      if (!f || !f->pixel || f->stamp > t_dds) continue;
      ref.submit({id++, i, f->stamp, *f->pixel, std::max(cfg.sigma_px_floor, f->sigma_px)});
    }
  }
  ASSERT_TRUE(ref.initialised());
  const estimation::StateEstimate r = ref.predictAt(t_dds);
  Eigen::Matrix<double, 6, 1> x_dds;
  Eigen::Matrix<double, 6, 6> P_dds;
  for (int k = 0; k < 6; ++k) x_dds(k) = tr.at("x").at(k).get<double>();
  for (int k = 0; k < 36; ++k) P_dds(k) = tr.at("P").at(k).get<double>();
  const Eigen::Matrix<double, 6, 1> d = x_dds - r.x().head<6>();
  const double d2 = d.dot(P_dds.ldlt().solve(d));
  RecordProperty("mahalanobis2", std::to_string(d2));
  std::printf("nodes vs in-process: d2 = %.3g over %d fused images\n", d2, tr.at("fused_in_track").get<int>());
  // Within the filter's own covariance: χ²(6) at 99.9 % is 22.46.
  EXPECT_LT(d2, 22.46) << "nodes x = " << x_dds.transpose() << "\nin-process x = " << r.x().transpose();
  EXPECT_GE(tr.at("fused_in_track").get<int>(), 20);
}

TEST_F(NodesLoopback, RobotHaltsWithinItsDeadlineWhenTheTrackerIsKilled) {
  const int domain = nodes::test::testDomain(12);
  const double deadline = 0.1;
  Nodes n("halt");
  n.start("tracker", n.args("tracker", "tracker", domain));
  n.start("robot", n.args("robot", "robot", domain, {"--deadline", "0.1"}));
  n.start("camera0", n.args("camera", "camera0", domain, {"--camera", "0"}));
  n.start("world", n.args("world", "world", domain, {"--expect", "3", "--duration", "1.5"}));
  ASSERT_TRUE(n.waitForLog("world", "nodes follow the clock", 20.0)) << n.log("world");
  std::this_thread::sleep_for(std::chrono::milliseconds(600));
  n.killNode("tracker");
  ASSERT_EQ(n.wait("world", 30.0), 0) << n.log("world");
  ASSERT_EQ(n.wait("robot", 10.0), 0) << n.log("robot");
  const nlohmann::json rb = n.summary("robot");
  ASSERT_GT(rb.at("setpoints").get<int>(), 50) << rb.dump(1);  // it did follow the tracker first
  ASSERT_FALSE(rb.at("halts").empty()) << n.log("robot");
  const double after = rb.at("halts").at(0).at("after_last_setpoint_s").get<double>();
  EXPECT_GE(after, deadline - 0.01);
  EXPECT_LT(after, deadline + 0.05) << n.log("robot");  // the deadline, plus one waitset wake
  EXPECT_TRUE(rb.at("halted").get<bool>());
}

TEST_F(NodesLoopback, TrackerNotesACameraLeavingWithinTheLeaseGoesOnAndTakesItBackWhenRestarted) {
  const int domain = nodes::test::testDomain(13);
  Nodes n("leave");
  const auto t_tracker = Clock::now();
  n.start("tracker", n.args("tracker", "tracker", domain));
  // Camera 0's clock runs 4 ms ahead of the time base: the tracker sees it as its apparent offset.
  n.start("camera0", n.args("camera", "camera0", domain, {"--camera", "0", "--clock-offset", "0.004"}));
  n.start("camera1", n.args("camera", "camera1", domain, {"--camera", "1"}));
  // 3 s: the kill at ~0.4 s, noted within the lease, the restart, and a second of frames after it.
  n.start("world", n.args("world", "world", domain, {"--expect", "3", "--duration", "3.0"}));
  ASSERT_TRUE(n.waitForLog("world", "nodes follow the clock", 20.0)) << n.log("world");
  std::this_thread::sleep_for(std::chrono::milliseconds(400));
  const double t_kill = since(t_tracker);
  n.killNode("camera1");
  ASSERT_TRUE(n.waitForLog("tracker", "left (liveliness lost", 5.0)) << n.log("tracker");
  n.start("camera1b", n.args("camera", "camera1b", domain, {"--camera", "1"}));  // the same camera, restarted
  ASSERT_EQ(n.wait("world", 30.0), 0) << n.log("world");
  ASSERT_EQ(n.wait("tracker", 10.0), 0) << n.log("tracker");
  ASSERT_EQ(n.wait("camera0", 10.0), 0) << n.log("camera0");
  ASSERT_EQ(n.wait("camera1b", 10.0), 0) << n.log("camera1b");
  const nlohmann::json tr = n.summary("tracker");
  ASSERT_EQ(tr.at("cameras_left").size(), 1u) << n.log("tracker");
  const nlohmann::json& ev = tr.at("cameras_left").at(0);
  EXPECT_EQ(ev.at("camera").get<std::string>(), tr.at("cameras").at(1).at("name").get<std::string>());
  // Noted within the lease (measured from the kill on the tracker's wall clock; the tracker
  // started a little after t_tracker, so this bound is conservative by the start-up time).
  EXPECT_LT(ev.at("wall_s").get<double>() - t_kill, nodes::dds::Qos::kCameraLeaseS + 0.1) << n.log("tracker");
  EXPECT_NE(n.log("tracker").find("left (liveliness lost"), std::string::npos);
  // And it went on: camera 0's frames after the kill reached it.
  const auto frames0 = n.summary("camera0").at("frames").get<std::uint64_t>();
  EXPECT_GE(tr.at("cameras").at(0).at("received").get<std::uint64_t>(), frames0 * 95 / 100);
  EXPECT_GE(frames0, 140u);  // 3 s at 50 Hz
  // The restarted camera rejoined: noted once, and its frames reach the tracker again.
  ASSERT_EQ(tr.at("cameras_rejoined").size(), 1u) << n.log("tracker");
  EXPECT_EQ(tr.at("cameras_rejoined").at(0).at("camera"), tr.at("cameras").at(1).at("name"));
  const auto frames1b = n.summary("camera1b").at("frames").get<std::uint64_t>();
  EXPECT_GE(frames1b, 25u) << n.log("camera1b");  // at least half a second of frames after the restart
  const auto received1 = tr.at("cameras").at(1).at("received").get<std::uint64_t>();
  EXPECT_GE(received1, frames1b + 10);  // the frames before the kill, and nearly all after the restart
  EXPECT_LE(tr.at("cameras").at(1).at("lost").get<std::uint64_t>(), 3u);
  // −min(delay) = offset − the smallest transport delay (loopback: well under 1 ms).
  EXPECT_NEAR(tr.at("cameras").at(0).at("apparent_clock_offset_s").get<double>(), 0.004, 1e-3);
}

TEST_F(NodesLoopback, ACameraWithAnotherRigIsRefused) {
  const int domain = nodes::test::testDomain(14);
  Nodes n("rig");
  n.start("tracker", n.args("tracker", "tracker", domain));
  n.start("camera0", n.args("camera", "camera0", domain, {"--camera", "0", "--set", "camera_count=3"}));
  n.start("world", n.args("world", "world", domain, {"--expect", "1", "--duration", "1.0"}));
  EXPECT_EQ(n.wait("camera0", 30.0), 1) << n.log("camera0");
  EXPECT_NE(n.log("camera0").find("differs from the tracker's"), std::string::npos) << n.log("camera0");
  ASSERT_EQ(n.wait("world", 30.0), 0) << n.log("world");
  ASSERT_EQ(n.wait("tracker", 10.0), 0) << n.log("tracker");
  EXPECT_EQ(n.summary("tracker").at("cameras_refused").size(), 1u) << n.log("tracker");
  EXPECT_NE(n.log("tracker").find("REFUSED camera0"), std::string::npos);
}

TEST_F(NodesLoopback, ASessionOfThrowsIsScoredByTheWorldWithEveryNodeStartingAfreshPerThrow) {
  const int domain = nodes::test::testDomain(15);
  Nodes n("session");
  n.start("tracker", n.args("tracker", "tracker", domain, {}, /*registered=*/true, "1"));
  n.start("robot", n.args("robot", "robot", domain, {}, false, "1"));
  n.start("camera0", n.args("camera", "camera0", domain, {"--camera", "0"}, false, "1"));
  n.start("camera1", n.args("camera", "camera1", domain, {"--camera", "1"}, false, "1"));
  n.start("world", n.args("world", "world", domain, {"--expect", "4", "--duration", "1.5", "--throws", "3"}, false, "1"));
  ASSERT_EQ(n.wait("world", 40.0), 0) << n.log("world");
  for (const char* name : {"tracker", "robot", "camera0", "camera1"}) ASSERT_EQ(n.wait(name, 10.0), 0) << n.log(name);
  const nlohmann::json w = n.summary("world"), tr = n.summary("tracker"), rb = n.summary("robot");
  EXPECT_EQ(w.at("throws_scored").get<int>(), 3) << w.dump(1);
  EXPECT_EQ(tr.at("episodes").get<int>(), 3);
  EXPECT_EQ(rb.at("episodes").get<int>(), 3);
  ASSERT_FALSE(tr.at("registration").is_null());
  EXPECT_LT(tr.at("registration").at("reprojection_px_after").get<double>(), 0.5);
  // Every set point within the limits across the resets (none from an old plan after a new start).
  EXPECT_EQ(rb.at("velocity_violations").get<int>() + rb.at("acceleration_violations").get<int>(), 0) << n.log("robot");
  // The throws of seed 1 the oracle can reach (the first two of three) are caught through the
  // nodes (the clearance is 5 mm). One may be missed when the shared machine stalls a node at the
  // wrong moment: the catch rate itself is bench/nodes/catch-session's figure.
  const int reachable = w.at("reachable_throws").get<int>();
  ASSERT_EQ(reachable, 2) << w.dump(1);
  EXPECT_GE(w.at("caught_reachable").get<int>(), reachable - 1) << w.dump(1);
  for (const nlohmann::json& t : w.at("per_throw"))
    if (t.at("caught").get<bool>()) {
      EXPECT_LE(t.at("miss_distance_mm").get<double>(), 5.0);
    }
}
