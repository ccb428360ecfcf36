#include "viewline/calib/hand_eye.h"

#include <cmath>
#include <iomanip>
#include <sstream>
#include <visp3/vision/vpHandEyeCalibration.h>

#include "viewline/calib/extrinsics.h"
#include "viewline/core/error.h"
#include "viewline/core/frames.h"

namespace viewline::calib {
namespace {
void checkPose(const Eigen::Isometry3d& T, const std::string& what) {
  if (!T.matrix().allFinite()) throw core::InvalidInput(what + ": contains NaN or Inf");
  const Eigen::Matrix3d R = T.linear();
  if ((R * R.transpose() - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() > 1e-6 || R.determinant() < 0.0)
    throw core::InvalidInput(what + ": rotation is not orthonormal with determinant +1");
}
}  // namespace

HandEyeResult calibrateHandEye(const std::vector<Eigen::Isometry3d>& r_M_e, const std::vector<Eigen::Isometry3d>& c_M_o,
                               HandEyeSetup setup, double min_rotation_rad) {
  if (r_M_e.size() != c_M_o.size())
    throw core::InvalidInput("hand-eye: " + std::to_string(r_M_e.size()) + " robot poses but " +
                             std::to_string(c_M_o.size()) + " camera poses (they must pair up one to one)");
  if (r_M_e.size() < 3)
    throw core::InvalidInput("hand-eye: " + std::to_string(r_M_e.size()) + " pose pairs, need at least 3");
  for (std::size_t i = 0; i < r_M_e.size(); ++i) {
    checkPose(r_M_e[i], "hand-eye: robot pose " + std::to_string(i));
    checkPose(c_M_o[i], "hand-eye: camera pose " + std::to_string(i));
  }
  // Motion between consecutive robot poses: need rotations about >= 2 non-parallel axes.
  std::vector<Eigen::Vector3d> axes;
  for (std::size_t i = 1; i < r_M_e.size(); ++i) {
    const Eigen::AngleAxisd aa(r_M_e[i - 1].linear().transpose() * r_M_e[i].linear());
    if (aa.angle() >= min_rotation_rad) axes.push_back(aa.axis());
  }
  bool two_axes = false;
  for (std::size_t i = 0; i < axes.size() && !two_axes; ++i)
    for (std::size_t j = i + 1; j < axes.size() && !two_axes; ++j)
      two_axes = axes[i].cross(axes[j]).norm() > std::sin(core::deg2rad(10.0));
  if (!two_axes) {
    std::ostringstream os;
    os << "hand-eye: the robot poses must rotate by at least " << std::setprecision(3) << core::rad2deg(min_rotation_rad)
       << " deg between consecutive poses about at least two non-parallel axes (found " << axes.size()
       << " usable motions); add poses with varied orientations";
    throw core::InvalidInput(os.str());
  }
  std::vector<vpHomogeneousMatrix> cMo, rMe;
  for (std::size_t i = 0; i < r_M_e.size(); ++i) {
    cMo.push_back(core::toVisp(c_M_o[i]));
    rMe.push_back(core::toVisp(setup == HandEyeSetup::EyeInHand ? r_M_e[i] : r_M_e[i].inverse()));
  }
  vpHomogeneousMatrix X;
  if (vpHandEyeCalibration::calibrate(cMo, rMe, X) != 0)
    throw core::NumericalError("hand-eye: vpHandEyeCalibration failed (degenerate motions?)");
  HandEyeResult r;
  r.setup = setup;
  r.X = core::toEigen(X);
  std::vector<Eigen::Isometry3d> fixed;
  for (std::size_t i = 0; i < r_M_e.size(); ++i) fixed.push_back(core::toEigen(rMe[i]) * r.X * c_M_o[i]);
  r.fixed = averagePoses(fixed);
  double st = 0, sr = 0;
  for (const auto& f : fixed) {
    const double dt = (f.translation() - r.fixed.translation()).norm();
    const double dr = core::rotationAngle(f.linear(), r.fixed.linear());
    r.residual_translation_m.push_back(dt);
    r.residual_rotation_rad.push_back(dr);
    st += dt * dt;
    sr += dr * dr;
  }
  r.rms_translation_m = std::sqrt(st / static_cast<double>(fixed.size()));
  r.rms_rotation_rad = std::sqrt(sr / static_cast<double>(fixed.size()));
  return r;
}

std::string HandEyeResult::report() const {
  std::ostringstream os;
  os << std::fixed << std::setprecision(5);
  const bool in = setup == HandEyeSetup::EyeInHand;
  const Eigen::AngleAxisd aa(X.linear());
  os << (in ? "eye-in-hand: e_M_c" : "eye-to-hand: r_M_c") << " translation [" << X.translation().transpose()
     << "] m, rotation " << std::setprecision(3) << core::rad2deg(aa.angle()) << " deg about ["
     << aa.axis().transpose() << "]\n";
  os << "consistency of " << (in ? "r_M_o (board in robot base)" : "e_M_o (board on end effector)") << " over "
     << residual_translation_m.size() << " poses: RMS " << std::setprecision(2) << rms_translation_m * 1000.0
     << " mm, " << std::setprecision(3) << core::rad2deg(rms_rotation_rad) << " deg\n";
  for (std::size_t i = 0; i < residual_translation_m.size(); ++i)
    os << "  pose " << i << ": " << std::setprecision(2) << residual_translation_m[i] * 1000.0 << " mm, "
       << std::setprecision(3) << core::rad2deg(residual_rotation_rad[i]) << " deg\n";
  return os.str();
}

}  // namespace viewline::calib
