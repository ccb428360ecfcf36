#include "viewline/robots/pan_tilt_hardware.h"

#include "viewline/core/checks.h"
#include "viewline/core/error.h"

#if defined(VISP_HAVE_FLIR_PTU_SDK)
#include <visp3/robot/vpRobotFlirPtu.h>
#endif
#if defined(VISP_HAVE_PTU46)
#include <visp3/robot/vpRobotPtu46.h>
#endif
#if defined(VISP_HAVE_BICLOPS)
#include <visp3/robot/vpRobotBiclops.h>
#endif
#if defined(VISP_HAVE_FLIR_PTU_SDK) || defined(VISP_HAVE_PTU46) || defined(VISP_HAVE_BICLOPS)
#include <visp3/core/vpColVector.h>
#include <visp3/robot/vpRobot.h>
#endif

namespace viewline::robots {

#if defined(VISP_HAVE_FLIR_PTU_SDK) || defined(VISP_HAVE_PTU46) || defined(VISP_HAVE_BICLOPS)
namespace {
vpColVector toCol(const Eigen::Vector2d& q) {
  vpColVector v(2);
  v[0] = q(0);
  v[1] = q(1);
  return v;
}

// Common wrapper: Robot is a vpRobot with velocity control in the joint (articular) frame.
template <class Robot>
class ViSPPanTiltUnit : public PanTiltUnit {
public:
  ViSPPanTiltUnit(std::string name, std::unique_ptr<Robot> robot, const PanTiltHardwareConfig& cfg)
      : name_(std::move(name)), robot_(std::move(robot)), limits_(cfg.limits), latency_(cfg.latency) {
    limits_.validate();
    robot_->setRobotState(vpRobot::STATE_VELOCITY_CONTROL);
  }
  ~ViSPPanTiltUnit() override {
    try {
      robot_->setRobotState(vpRobot::STATE_STOP);
    } catch (...) {
    }
  }
  std::string name() const override { return name_; }
  const PanTiltLimits& limits() const override { return limits_; }
  double commandLatency() const override { return latency_; }
  void commandVelocity(core::Timestamp t, const Eigen::Vector2d& qdot) override {
    core::requireFinite(t, "PanTiltUnit::commandVelocity: t");
    core::requireFinite(qdot, "PanTiltUnit::commandVelocity: qdot");
    robot_->setVelocity(vpRobot::ARTICULAR_FRAME, toCol(qdot));
  }
  JointState read(core::Timestamp t) override {
    vpColVector q;
    robot_->getPosition(vpRobot::ARTICULAR_FRAME, q);
    JointState s;
    s.t = t;
    s.q = Eigen::Vector2d(q[0], q[1]);
    if (has_last_ && t > last_.t) s.qdot = (s.q - last_.q) / (t - last_.t);  // drivers differ in velocity read-back
    last_ = s;
    has_last_ = true;
    return s;
  }

private:
  std::string name_;
  std::unique_ptr<Robot> robot_;
  PanTiltLimits limits_;
  double latency_;
  JointState last_;
  bool has_last_ = false;
};
}  // namespace
#endif

std::vector<std::string> panTiltHardwareAvailable() {
  std::vector<std::string> out;
#if defined(VISP_HAVE_FLIR_PTU_SDK)
  out.emplace_back("flir_ptu");
#endif
#if defined(VISP_HAVE_PTU46)
  out.emplace_back("ptu46");
#endif
#if defined(VISP_HAVE_BICLOPS)
  out.emplace_back("biclops");
#endif
  return out;
}

std::unique_ptr<PanTiltUnit> openPanTiltHardware(const PanTiltHardwareConfig& config) {
#if defined(VISP_HAVE_FLIR_PTU_SDK)
  if (config.backend == "flir_ptu") {
    auto robot = std::make_unique<vpRobotFlirPtu>();
    robot->connect(config.device, config.baudrate);
    return std::make_unique<ViSPPanTiltUnit<vpRobotFlirPtu>>("FLIR PTU (vpRobotFlirPtu)", std::move(robot), config);
  }
#endif
#if defined(VISP_HAVE_PTU46)
  if (config.backend == "ptu46") {
    auto robot = std::make_unique<vpRobotPtu46>(config.device.c_str());
    return std::make_unique<ViSPPanTiltUnit<vpRobotPtu46>>("PTU-46 (vpRobotPtu46)", std::move(robot), config);
  }
#endif
#if defined(VISP_HAVE_BICLOPS)
  if (config.backend == "biclops") {
    auto robot = std::make_unique<vpRobotBiclops>(config.device);
    return std::make_unique<ViSPPanTiltUnit<vpRobotBiclops>>("Biclops (vpRobotBiclops)", std::move(robot), config);
  }
#endif
  std::string have;
  for (const auto& n : panTiltHardwareAvailable()) have += (have.empty() ? "" : ", ") + n;
  throw core::InvalidInput("pan-tilt hardware backend '" + config.backend +
                           "' is unknown or not compiled into this build (ViSP without its SDK); available: " +
                           (have.empty() ? std::string("none") : have));
}

}  // namespace viewline::robots
