#pragma once
// Hand-eye calibration with vpHandEyeCalibration, with input validation and residuals.
//
// Eye-in-hand (camera on the end effector, board fixed in the robot base frame r):
//   r_M_e(i) * e_M_c * c_M_o(i) = r_M_o for all i  -> solves e_M_c (and r_M_o).
// Eye-to-hand (camera fixed, board on the end effector):
//   e_M_r(i) * r_M_c * c_M_o(i) = e_M_o for all i  -> solves r_M_c (and e_M_o), by giving
//   vpHandEyeCalibration the inverted robot poses.

#include <Eigen/Geometry>
#include <string>
#include <vector>

namespace viewline::calib {

/// Where the camera is: on the end effector (eye-in-hand) or fixed, looking at a board on the end effector
/// (eye-to-hand).
enum class HandEyeSetup { EyeInHand, EyeToHand };

/// Result of calibrateHandEye(): the hand-eye pose X, the fixed pose and per-pose residuals.
struct HandEyeResult {
  HandEyeSetup setup = HandEyeSetup::EyeInHand;  ///< which problem was solved
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();      ///< e_M_c (eye-in-hand) or r_M_c (eye-to-hand)
  Eigen::Isometry3d fixed = Eigen::Isometry3d::Identity();  ///< r_M_o (eye-in-hand) or e_M_o (eye-to-hand), averaged
  std::vector<double> residual_translation_m;  ///< per pose: |fixed(i) - mean| translation
  std::vector<double> residual_rotation_rad;   ///< per pose: angle between fixed(i) and mean
  double rms_translation_m = 0.0;  ///< RMS of residual_translation_m, m
  double rms_rotation_rad = 0.0;  ///< RMS of residual_rotation_rad, rad
  /// Human-readable report of X, the fixed pose and the residuals.
  std::string report() const;
};

/// Validates (same count, at least 3 poses, finite proper rotations, enough rotation between poses
/// about at least two non-parallel axes) and calibrates. Throws InvalidInput naming the pose.
HandEyeResult calibrateHandEye(const std::vector<Eigen::Isometry3d>& r_M_e, const std::vector<Eigen::Isometry3d>& c_M_o,
                               HandEyeSetup setup, double min_rotation_rad = 0.05);

}  // namespace viewline::calib
