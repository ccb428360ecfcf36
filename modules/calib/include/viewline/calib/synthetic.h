#pragma once
// Synthetic calibration data for the default simulated rigs: the "true" rig the simulator renders
// with (calib/rigs/<rig>/truth.yaml), board images rendered through it by the simulator's ray-cast
// renderer (sim::Renderer: exact ViSP kud projection, anti-aliased edges), then optical blur and
// sensor noise, and the board poses at which they are taken. The calibration tools then estimate
// the rig from these images exactly as from real ones; estimators never read the truth.
//
// Truth file (strict keys; angles in keys ending _deg):
//   name: dart
//   imaging:                       # how the calibration images are made
//     noise_sigma: 2.0             # grey levels, additive Gaussian per pixel
//     blur_sigma_px: 0.5           # Gaussian optical blur, px
//     supersampling: 4             # renderer anti-aliasing on edge pixels (n x n)
//   cameras:
//     - name: side
//       width: 656
//       height: 480
//       hfov_deg: 62               # or fx and fy (px)
//       cx: 330.0                  # optional, default (width - 1) / 2
//       cy: 236.0                  # optional, default (height - 1) / 2
//       kud: 0.03                  # ViSP forward radial coefficient (what the renderer projects with)
//       position: [1.2, -2.6, 1.6] # camera centre in the world, m ...
//       look_at: [1.2, 0.0, 1.75]  # ... looking at this world point (image x horizontal, world z up)
//       roll_deg: 0.0              # optional rotation about the optical axis
//       # or instead of position/look_at: c_M_w / w_M_c {translation, rotation | theta_u_deg}
//       # or, with a hand_eye section and no pose keys: the camera on the PTU at q = (0, 0)
//   hand_eye:                      # optional: camera on a pan-tilt unit (vpPtu46 frames)
//     e_M_c: {translation: [..], theta_u_deg: [..]}
//
// The truth's kdu (ViSP's back-projection coefficient, unused by the renderer) is the least-squares
// fit of the exact inverse of the kud model over the image (fitKdu), so that core::Camera's
// pixelToNormalized of the truth is as good as ViSP's model allows.

#include <Eigen/Geometry>
#include <optional>
#include <string>
#include <vector>
#include <opencv2/core.hpp>
#include <visp3/core/vpCameraParameters.h>

#include "viewline/calib/board.h"
#include "viewline/core/camera.h"
#include "viewline/core/random.h"

namespace viewline::calib {

/// How the synthetic calibration images are made: sensor noise, blur and anti-aliasing.
struct SyntheticImaging {
  double noise_sigma = 2.0;   ///< grey levels
  double blur_sigma_px = 0.5; ///< Gaussian optical blur
  int supersampling = 4;      ///< renderer anti-aliasing
};

/// The true rig a simulated scenario renders with (`calib/rigs/<rig>/truth.yaml`).
struct RigTruth {
  std::string name;  ///< rig name
  std::vector<core::Camera> cameras;        ///< true intrinsics (kud, fitted kdu), size, c_M_w
  SyntheticImaging imaging;  ///< how its calibration images are made
  std::optional<Eigen::Isometry3d> e_M_c;   ///< pan-tilt: camera on the PTU end effector
  const core::Camera& camera(const std::string& name) const;  ///< throws InvalidInput
};

/// Reads a truth file (keys above); unknown keys are errors naming file:line:key.
RigTruth loadRigTruth(const std::string& path);

/// Least-squares kdu such that ViSP's back-projection x = x_d (1 + kdu r_d²) best inverts the
/// forward model u = u0 + px x (1 + kud r²) over a grid of the image.
double fitKdu(double px, double py, double u0, double v0, double kud, unsigned width, unsigned height);

// ---- pan-tilt unit (ViSP's vpPtu46 geometry) ----------------------------------------------------

/// End effector in the PTU base frame at joint angles q = (pan, tilt): vpPtu46's f_M_c(q) times its
/// nominal c_M_e (the kinematic chain without the camera mount).
Eigen::Isometry3d ptuBaseToEffector(const Eigen::Vector2d& q);
/// vpPtu46's nominal e_M_c (its built-in camera mount).
Eigen::Isometry3d ptuNominalEyeInHand();

// ---- rendering -----------------------------------------------------------------------------------

/// 8-bit grey image of `board` at c_M_o (board -> camera) seen by `camera` through the simulator's
/// renderer (camera's kud model), grey background, then blur and noise drawn from rng.
cv::Mat renderBoardImage(const core::Camera& camera, const Eigen::Isometry3d& c_M_o, const BoardSpec& board,
                         const SyntheticImaging& imaging, core::Rng& rng);

/// The four outer corners (one spacing / tag margin beyond the pattern) of the board, board frame.
std::vector<Eigen::Vector3d> boardOutline(const BoardSpec& board);
/// True when the whole outline projects inside the image with `margin_px` and the board faces the
/// camera with at most `max_obliquity_rad` between its normal and the line of sight to its centre.
bool boardFullyVisible(const core::Camera& camera, const Eigen::Isometry3d& c_M_o, const BoardSpec& board,
                       double margin_px, double max_obliquity_rad);

/// Sampling of board poses for intrinsic calibration (board fill, tilt, obliquity, margin).
struct IntrinsicsViewOptions {
  double min_fill = 0.45,   ///< smallest board width / image width (at a fronto-parallel view)
         max_fill = 0.85;   ///< largest board width / image width (at a fronto-parallel view)
  double max_tilt_rad = 0.75;               ///< per axis (about the board's x and y)
  double max_obliquity_rad = 1.05;  ///< board normal to line-of-sight angle limit, rad
  double margin_px = 6.0;  ///< outline kept this many pixels inside the image
};
/// n board poses c_M_o for intrinsic calibration: the board filling a random part of the image,
/// tilted about both axes, rotated in plane; every one fully visible. Throws NumericalError when
/// the sampler cannot find such poses.
std::vector<Eigen::Isometry3d> sampleIntrinsicsPoses(const core::Camera& camera, const BoardSpec& board, int n,
                                                     core::Rng& rng, const IntrinsicsViewOptions& options = {});

/// Sampling of board poses seen by every camera of a rig (for rig calibration).
struct RigViewOptions {
  Eigen::Vector3d center_w = Eigen::Vector3d::Zero();  ///< region of the shared views (world)
  double radius = 0.4;                                 ///< board centre within ±radius per axis
  double max_tilt_rad = 0.3;                           ///< normal perturbation around the best one
  double max_obliquity_rad = 1.2;                      ///< per camera
  double margin_px = 6.0;  ///< outline kept this many pixels inside every image
};
/// The world point closest (least squares) to every camera's optical axis.
Eigen::Vector3d commonViewPoint(const std::vector<core::Camera>& cameras);
/// n board poses w_M_o seen fully by every camera: centred around options.center_w, facing the
/// cameras (normal near the one that equalises the viewing angles), in-plane rotation ±20°.
std::vector<Eigen::Isometry3d> sampleRigPoses(const std::vector<core::Camera>& cameras, const BoardSpec& board, int n,
                                              core::Rng& rng, const RigViewOptions& options);

/// Board lying on the floor (world z = 0, z up) printed side up, its origin at `origin_w` and its x
/// axis along world x rotated by `yaw_rad` about z: w_M_o.
Eigen::Isometry3d floorBoardPose(const BoardSpec& board, const Eigen::Vector2d& origin_w, double yaw_rad = 0.0);

// ---- calibrated vs true ------------------------------------------------------------------------

/// Errors of a calibrated camera against the true one (same name, same world frame).
struct CameraErrors {
  std::string name;  ///< camera name
  vpCameraParameters truth,    ///< true intrinsics
                     calibrated;  ///< calibrated intrinsics
  double position_error_m = 0.0;   ///< |centre_cal - centre_true|
  double rotation_error_rad = 0.0; ///< angle of R_cal R_trueᵀ
  /// Over a 33x25 grid of pixels of the image: angle between the true ray (exact inverse of the
  /// kud model) and the calibrated camera's ray (ViSP back-projection with kdu), expressed in pixels
  /// (angle x mean focal length): in the camera frame (intrinsics only) and in the world (with the
  /// pose's rotation error). RMS and maximum.
  double ray_rms_px = 0.0,        ///< RMS ray error in the camera frame, px
         ray_max_px = 0.0;        ///< largest ray error in the camera frame, px
  double world_ray_rms_px = 0.0,  ///< RMS ray error in the world (with the rotation error), px
         world_ray_max_px = 0.0;  ///< largest ray error in the world, px
};
/// Errors of one calibrated camera against the true one (same world frame).
CameraErrors compareCamera(const core::Camera& truth, const core::Camera& calibrated);
/// compareCamera for each true camera and the calibrated one of the same name (InvalidInput when
/// missing or of another image size).
std::vector<CameraErrors> compareRig(const std::vector<core::Camera>& truth, const std::vector<core::Camera>& calibrated);

}  // namespace viewline::calib
