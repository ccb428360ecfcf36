// The default-rig pipeline in small: a two-camera 320x240 truth rig, board images rendered by the
// simulator through it (calib::renderBoardImage), intrinsics from 6 views per camera, rig
// extrinsics from 5 shared views with the world anchored on the board of instant 0 (surveyed), and
// the recovered parameters checked against the truth.
//
// Tolerances come from the noise, not from the result:
//  - intrinsics: the OpenCV model contains the truth exactly (ViSP's forward kud model is OpenCV's
//    k1 with k2 = p1 = p2 = 0), so each of fx, fy, cx, cy, k1 must lie within 4 standard deviations
//    (cv::calibrateCamera's stdDeviationsIntrinsics, from the residuals of these very images);
//  - extrinsics: the world frame hangs on one board pose at distance d seen in N corners with
//    reprojection RMS σ (px): its angle is known to about σ_θ = σ / (f (L/d) sqrt(N/2)) (corners
//    spread over a board of size L) and its depth to σ d² / (f L sqrt(N/2)). The intrinsics' own
//    uncertainty adds to that: a principal point off by σ_c turns the camera by σ_c / f and moves
//    its centre sideways by d σ_c / f; a focal length off by σ_f scales depths by σ_f / f. A camera
//    rotation must be within 4 sqrt(σ_θ² + (σ_c/f)²) of the truth (twice: the camera's own pose and
//    the anchor), its centre within 4 sqrt((σ_θ d)² + σ_depth² + (d σ_f/f)² + (d σ_c/f)²).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <unistd.h>

#include "viewline/calib/extrinsics.h"
#include "viewline/calib/intrinsics.h"
#include "viewline/calib/synthetic.h"
#include "viewline/core/error.h"
#include "viewline/core/frames.h"

using namespace viewline;

namespace {
const char* kTruth = R"(name: small
imaging: {noise_sigma: 2.0, blur_sigma_px: 0.5, supersampling: 4}
cameras:
  - {name: a, width: 320, height: 240, hfov_deg: 60, cx: 161.5, cy: 118.2, kud: -0.05, position: [-0.5, -2.0, 1.5], look_at: [0.0, 0.0, 1.2]}
  - {name: b, width: 320, height: 240, hfov_deg: 55, cx: 157.9, cy: 121.4, kud: 0.03, position: [0.6, -2.1, 1.4], look_at: [0.0, 0.0, 1.2]}
)";

calib::BoardSpec chessboard(double spacing) {
  calib::BoardSpec b;
  b.type = calib::BoardType::Chessboard;
  b.cols = 9;
  b.rows = 6;
  b.spacing = spacing;
  return b;
}
}  // namespace

TEST(SyntheticRig, PipelineRecoversTheTrueRigWithinItsNoise) {
  const std::string path = (std::filesystem::temp_directory_path() / ("viewline_small_truth_" + std::to_string(getpid()) + ".yaml")).string();
  std::ofstream(path) << kTruth;
  const calib::RigTruth truth = calib::loadRigTruth(path);
  std::filesystem::remove(path);
  ASSERT_EQ(truth.cameras.size(), 2u);
  core::Rng rng = core::makeRng(7);

  // ---- intrinsics, each camera ----
  const calib::BoardSpec small = chessboard(0.025);
  std::vector<calib::PoseCamera> pose_cams;
  std::vector<core::Camera> calibrated;
  std::vector<double> sd_f, sd_c;  // per camera: std dev of the focal length and principal point (px)
  for (const auto& cam : truth.cameras) {
    std::vector<calib::ViewInput> views;
    for (const auto& c_M_o : calib::sampleIntrinsicsPoses(cam, small, 6, rng)) {
      const cv::Mat img = calib::renderBoardImage(cam, c_M_o, small, truth.imaging, rng);
      const calib::Detection d = calib::detectBoard(img, small);
      ASSERT_TRUE(d.observation) << cam.name << ": " << d.reason;
      views.push_back({cam.name, *d.observation});
    }
    calib::IntrinsicsOptions opt;
    opt.fit_visp = true;
    const calib::IntrinsicsResult r = calib::calibrateIntrinsics(views, cv::Size(320, 240), opt);
    const auto& K = r.opencv.camera_matrix;
    const auto& t = cam.intrinsics;
    const double est[5] = {K(0, 0), K(1, 1), K(0, 2), K(1, 2), r.opencv.distortion(0)};
    const double tru[5] = {t.get_px(), t.get_py(), t.get_u0(), t.get_v0(), t.get_kud()};
    const char* names[5] = {"fx", "fy", "cx", "cy", "k1"};
    for (int i = 0; i < 5; ++i) {
      const double sd = r.std_dev(i);
      EXPECT_LT(std::abs(est[i] - tru[i]), 4.0 * sd)
          << cam.name << " " << names[i] << ": true " << tru[i] << ", estimated " << est[i] << " +- " << sd;
    }
    std::printf("%s: fx %.3f (true %.3f, sd %.3f) cx %.3f (true %.3f, sd %.3f) k1 %.4f (true %.4f, sd %.4f), RMS %.3f px\n",
                cam.name.c_str(), est[0], tru[0], r.std_dev(0), est[2], tru[2], r.std_dev(2), est[4], tru[4], r.std_dev(4), r.rms_px);
    sd_f.push_back(std::max(r.std_dev(0), r.std_dev(1)));
    sd_c.push_back(std::max(r.std_dev(2), r.std_dev(3)));
    pose_cams.push_back(calib::PoseCamera::fromOpenCv(r.opencv));
    core::Camera c = cam;
    c.intrinsics = r.visp_with;
    calibrated.push_back(c);
    // The ViSP model written into the rig files: its rays within 0.5 px of the truth's over the image
    // (its kdu back-projection is an approximation; the truth's own fitted kdu is the floor).
    const auto e = calib::compareCamera(cam, c);
    const double floor = calib::compareCamera(cam, cam).ray_rms_px;
    EXPECT_LT(e.ray_rms_px, floor + 0.5) << cam.name;
  }

  // ---- rig extrinsics: shared views of a larger board, world anchored on instant 0 ----
  const calib::BoardSpec big = chessboard(0.1);
  calib::RigViewOptions ro;
  ro.center_w = calib::commonViewPoint(truth.cameras);
  ro.radius = 0.2;
  const int n_views = 5;
  const auto w_M_o = calib::sampleRigPoses(truth.cameras, big, n_views, rng, ro);
  calib::RigObservations obs;
  obs.cameras = pose_cams;
  obs.views.assign(n_views, std::vector<std::optional<calib::BoardObservation>>(2));
  for (int k = 0; k < n_views; ++k)
    for (std::size_t i = 0; i < 2; ++i) {
      const auto& cam = truth.cameras[i];
      const cv::Mat img = calib::renderBoardImage(cam, cam.c_M_w * w_M_o[static_cast<std::size_t>(k)], big, truth.imaging, rng);
      const calib::Detection d = calib::detectBoard(img, big);
      ASSERT_TRUE(d.observation) << cam.name << " view " << k << ": " << d.reason;
      obs.views[static_cast<std::size_t>(k)][i] = d.observation;
    }
  const calib::RigResult rig = calib::calibrateRig(obs, 0);
  const Eigen::Isometry3d ref_M_w = rig.ref_M_board[0] * w_M_o[0].inverse();
  for (std::size_t i = 0; i < 2; ++i) calibrated[i].c_M_w = rig.c_M_ref[i] * ref_M_w;

  const auto errs = calib::compareRig(truth.cameras, calibrated);
  const double N = 54.0, L = 8 * big.spacing;
  for (std::size_t i = 0; i < errs.size(); ++i) {
    const auto& e = errs[i];
    const core::Camera& t = truth.camera(e.name);
    const double f = t.focalPx();
    const double d = (t.c_M_w * (w_M_o[0] * Eigen::Vector3d(4 * big.spacing, 2.5 * big.spacing, 0))).z();
    const double sigma_theta = rig.rms_px / (f * (L / d) * std::sqrt(N / 2));
    const double sigma_depth = rig.rms_px * d * d / (f * L * std::sqrt(N / 2));
    const double rot_bound = 4.0 * std::sqrt(2.0) * std::hypot(sigma_theta, sd_c[i] / f);
    const double pos_bound = 4.0 * std::sqrt(std::pow(sigma_theta * d, 2) + std::pow(sigma_depth, 2) +
                                             std::pow(d * sd_f[i] / f, 2) + std::pow(d * sd_c[i] / f, 2));
    std::printf("%s: centre error %.2f mm (bound %.2f), rotation error %.4f deg (bound %.4f), world-ray RMS %.2f px\n",
                e.name.c_str(), 1e3 * e.position_error_m, 1e3 * pos_bound, core::rad2deg(e.rotation_error_rad),
                core::rad2deg(rot_bound), e.world_ray_rms_px);
    EXPECT_LT(e.rotation_error_rad, rot_bound) << e.name;
    EXPECT_LT(e.position_error_m, pos_bound) << e.name;
  }
}

TEST(SyntheticRig, TruthFileErrorsNameTheKey) {
  const std::string path = (std::filesystem::temp_directory_path() / ("viewline_bad_truth_" + std::to_string(getpid()) + ".yaml")).string();
  std::ofstream(path) << "name: x\ncameras:\n  - {name: a, width: 320, height: 240, hfov_deg: 60, kud: 0, position: [0, 0, 1], look_at: [1, 0, 1], focus: 3}\n";
  try {
    calib::loadRigTruth(path);
    FAIL() << "unknown key accepted";
  } catch (const core::InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("focus"), std::string::npos) << e.what();
  }
  std::filesystem::remove(path);
}

TEST(SyntheticRig, FittedKduInvertsKudBestAmongNeighbours) {
  // fitKdu is a least-squares optimum: nudging it either way makes the ray error worse.
  core::Camera c;
  c.width = 320;
  c.height = 240;
  const double kdu = calib::fitKdu(300, 300, 160, 120, -0.08, 320, 240);
  EXPECT_GT(kdu, 0.0);
  auto err = [&](double k) {
    c.intrinsics.initPersProjWithDistortion(300, 300, 160, 120, -0.08, k);
    return calib::compareCamera(c, c).ray_rms_px;
  };
  EXPECT_LT(err(kdu), err(kdu * 1.05));
  EXPECT_LT(err(kdu), err(kdu * 0.95));
}
