// Calibration on real images from Debian packages (opencv-doc, visp-images-data).
// Skips visibly when a package is missing (scripts/install-deps installs both).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <unistd.h>

#include "viewline/calib/board.h"
#include "viewline/calib/extrinsics.h"
#include "viewline/calib/intrinsics.h"
#include "viewline/core/error.h"
#include "viewline/core/frames.h"

using namespace viewline;
using namespace viewline::calib;
namespace fs = std::filesystem;

namespace {
const std::string kOpenCvData = "/usr/share/doc/opencv-doc/examples/data/";
const std::string kVispData = "/usr/share/visp-images-data/ViSP-images/";

std::vector<std::string> stereoFiles(const std::string& side) {
  std::vector<std::string> f;
  for (int i = 1; i <= 14; ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "%s%02d.jpg", side.c_str(), i);
    if (fs::exists(kOpenCvData + name)) f.push_back(kOpenCvData + name);  // left10/right10 are not shipped
  }
  return f;
}

struct TempDir {
  fs::path path = fs::temp_directory_path() / ("viewline_calib_" + std::to_string(::getpid()));
  TempDir() { fs::create_directories(path); }
  ~TempDir() { fs::remove_all(path); }
  std::size_t count() const {
    std::size_t n = 0;
    for ([[maybe_unused]] const auto& e : fs::directory_iterator(path)) ++n;
    return n;
  }
};
}  // namespace

TEST(RealData, OpenCvStereoPairsAgreeWithCvStereoCalibrate) {
  if (!fs::exists(kOpenCvData + "left01.jpg")) GTEST_SKIP() << "opencv-doc not installed: " << kOpenCvData << "left01.jpg missing";
  const BoardSpec board{BoardType::Chessboard, 9, 6, 0.025, "36h11", 0, 0, {}};
  const auto lf = stereoFiles("left"), rf = stereoFiles("right");
  ASSERT_EQ(lf.size(), rf.size());
  // Detect once; keep pairs where both images show the board.
  std::vector<ViewInput> lv, rv;
  RigObservations rig;
  for (std::size_t k = 0; k < lf.size(); ++k) {
    const Detection a = detectBoard(readGray(lf[k]), board), b = detectBoard(readGray(rf[k]), board);
    if (!a.observation || !b.observation) continue;
    lv.push_back({lf[k], *a.observation});
    rv.push_back({rf[k], *b.observation});
    rig.views.push_back({a.observation, b.observation});
  }
  ASSERT_GE(lv.size(), 10u);
  const cv::Size size = readGray(lf[0]).size();
  IntrinsicsOptions no_visp;
  no_visp.fit_visp = false;  // vpCalibration takes seconds per camera: fit ViSP's model on the left only
  const IntrinsicsResult L = calibrateIntrinsics(lv, size), R = calibrateIntrinsics(rv, size, no_visp);
  ASSERT_EQ(L.view_names.size(), lv.size()) << L.report();  // no view rejected on this clean set
  ASSERT_EQ(R.view_names.size(), rv.size()) << R.report();
  rig.cameras = {PoseCamera::fromOpenCv(L.opencv), PoseCamera::fromOpenCv(R.opencv)};
  const RigResult ours = calibrateRig(rig);

  // OpenCV's own stereo calibration of the same points, intrinsics estimated jointly.
  std::vector<std::vector<cv::Point3f>> obj;
  std::vector<std::vector<cv::Point2f>> il, ir;
  for (std::size_t k = 0; k < lv.size(); ++k) {
    obj.push_back(lv[k].observation.object_points);
    il.push_back(lv[k].observation.image_points);
    ir.push_back(rv[k].observation.image_points);
  }
  cv::Mat K1 = cv::initCameraMatrix2D(obj, il, size), K2 = cv::initCameraMatrix2D(obj, ir, size), D1, D2, Rs, Ts, E, F;
  const double cv_rms = cv::stereoCalibrate(obj, il, ir, K1, D1, K2, D2, size, Rs, Ts, E, F, cv::CALIB_FIX_K3,
                                            cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 200, 1e-12));
  const double cv_baseline = cv::norm(Ts), our_baseline = ours.c_M_ref[1].translation().norm();
  std::cout << "[ RESULT   ] stereo pairs used: " << lv.size() << "\n"
            << "[ RESULT   ] left  fx fy cx cy = " << L.opencv.camera_matrix(0, 0) << " " << L.opencv.camera_matrix(1, 1)
            << " " << L.opencv.camera_matrix(0, 2) << " " << L.opencv.camera_matrix(1, 2) << ", RMS " << L.rms_px << " px\n"
            << "[ RESULT   ] right fx fy cx cy = " << R.opencv.camera_matrix(0, 0) << " " << R.opencv.camera_matrix(1, 1)
            << " " << R.opencv.camera_matrix(0, 2) << " " << R.opencv.camera_matrix(1, 2) << ", RMS " << R.rms_px << " px\n"
            << "[ RESULT   ] cv::stereoCalibrate left fx fy cx cy = " << K1.at<double>(0, 0) << " " << K1.at<double>(1, 1)
            << " " << K1.at<double>(0, 2) << " " << K1.at<double>(1, 2) << "; right = " << K2.at<double>(0, 0) << " "
            << K2.at<double>(1, 1) << " " << K2.at<double>(0, 2) << " " << K2.at<double>(1, 2) << "; RMS " << cv_rms << " px\n"
            << "[ RESULT   ] baseline ours " << our_baseline * 1000 << " mm, cv::stereoCalibrate " << cv_baseline * 1000
            << " mm; rig RMS " << ours.rms_px << " px (left " << ours.camera_rms_px[0] << ", right "
            << ours.camera_rms_px[1] << ")\n"
            << "[ RESULT   ] ViSP model with distortion: left px py u0 v0 kud = " << L.visp_with.get_px() << " "
            << L.visp_with.get_py() << " " << L.visp_with.get_u0() << " " << L.visp_with.get_v0() << " "
            << L.visp_with.get_kud() << ", RMS " << L.visp_with_rms_px << " px (without distortion " << L.visp_without_rms_px
            << " px)\n";
  for (const auto& [ours_K, cvK] : {std::pair{L.opencv.camera_matrix, K1}, std::pair{R.opencv.camera_matrix, K2}}) {
    EXPECT_NEAR(ours_K(0, 0), cvK.at<double>(0, 0), 0.005 * cvK.at<double>(0, 0));
    EXPECT_NEAR(ours_K(1, 1), cvK.at<double>(1, 1), 0.005 * cvK.at<double>(1, 1));
    EXPECT_NEAR(ours_K(0, 2), cvK.at<double>(0, 2), 2.0);
    EXPECT_NEAR(ours_K(1, 2), cvK.at<double>(1, 2), 2.0);
  }
  EXPECT_NEAR(our_baseline, cv_baseline, 0.005 * cv_baseline);
  cv::Mat Rours(3, 3, CV_64F);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) Rours.at<double>(i, j) = ours.c_M_ref[1].linear()(i, j);
  cv::Mat dR = Rours * Rs.t(), rv_;
  cv::Rodrigues(dR, rv_);
  EXPECT_LT(core::rad2deg(cv::norm(rv_)), 0.5);
  EXPECT_LT(L.rms_px, 0.5);
  EXPECT_LT(ours.rms_px, 0.6);
  // ViSP's one-coefficient model fits these lenses better than no distortion at all.
  EXPECT_LT(L.visp_with_rms_px, L.visp_without_rms_px);
  EXPECT_GT(L.std_dev(0), 0.0);
}

TEST(RealData, ViSPCircleGrid) {
  const std::string first = kVispData + "calibration/grid36-01.pgm";
  if (!fs::exists(first)) GTEST_SKIP() << "visp-images-data not installed: " << first << " missing";
  // ViSP's example calibrate2dGrid.cpp: a 6x6 grid of dots, centres 0.03 m apart.
  const BoardSpec board{BoardType::CirclesGrid, 6, 6, 0.03, "36h11", 0, 0, {}};
  std::vector<std::string> files;
  for (int i = 1; i <= 4; ++i) files.push_back(kVispData + "calibration/grid36-0" + std::to_string(i) + ".pgm");
  const IntrinsicsResult r = calibrateFromImages(files, board);
  std::cout << "[ RESULT   ] grid36 (" << r.view_names.size() << " views):\n" << r.report();
  EXPECT_EQ(r.view_names.size(), 4u);
  EXPECT_LT(r.rms_px, 0.5);
  EXPECT_LT(r.visp_with_rms_px, 0.5);
  EXPECT_GT(r.visp_with.get_px(), 300.0);
  EXPECT_LT(r.visp_with.get_px(), 2000.0);
}

TEST(RealData, AprilTagPosesMatchViSPGroundTruth) {
  const std::string img = kVispData + "AprilTag/AprilTag.pgm", gt = kVispData + "AprilTag/ground_truth_pose.txt";
  if (!fs::exists(img)) GTEST_SKIP() << "visp-images-data not installed: " << img << " missing";
  // Intrinsics and tag size of ViSP's testAprilTag.cpp.
  vpCameraParameters cam;
  cam.initPersProjWithoutDistortion(615.1674805, 615.1675415, 312.1889954, 243.4373779);
  BoardSpec board;
  board.type = BoardType::AprilTag;
  board.tag_size = 0.053;
  const auto poses = estimateTagPoses(PoseCamera::fromVisp(cam), readGray(img), board);
  std::ifstream f(gt);
  std::string name;
  double tx, ty, tz, ux, uy, uz;
  int compared = 0;
  double worst_t = 0, worst_r = 0;
  while (f >> name >> tx >> ty >> tz >> ux >> uy >> uz) {
    const int id = std::stoi(name.substr(name.rfind('_') + 1));
    ASSERT_EQ(poses.count(id), 1u) << "tag " << id << " not detected";
    const Eigen::Vector3d tu(ux, uy, uz);
    const Eigen::Matrix3d Rgt = Eigen::AngleAxisd(tu.norm(), tu.normalized()).toRotationMatrix();
    const auto& p = poses.at(id).c_M_o;
    const double dt = (p.translation() - Eigen::Vector3d(tx, ty, tz)).norm();
    const double dr = core::rad2deg(core::rotationAngle(p.linear(), Rgt));
    worst_t = std::max(worst_t, dt);
    worst_r = std::max(worst_r, dr);
    EXPECT_LT(dt, 0.002) << name;
    EXPECT_LT(dr, 1.0) << name;
    ++compared;
  }
  std::cout << "[ RESULT   ] AprilTag.pgm: " << compared << " tags, worst translation error " << worst_t * 1000
            << " mm, worst rotation error " << worst_r << " deg\n";
  EXPECT_EQ(compared, 12);
}

TEST(RealData, BadInputGivesClearErrorsAndWritesNothing) {
  if (!fs::exists(kOpenCvData + "left01.jpg")) GTEST_SKIP() << "opencv-doc not installed";
  TempDir dir;
  const BoardSpec board{BoardType::Chessboard, 9, 6, 0.025, "36h11", 0, 0, {}};
  auto attempt = [&](const std::vector<std::string>& files) {
    try {
      const auto r = calibrateFromImages(files, board);
      saveIntrinsics(r, "cam", (dir.path / "cam.xml").string(), (dir.path / "cam.yaml").string());
    } catch (const core::InvalidInput& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  // Unreadable image.
  std::ofstream(dir.path / "broken.jpg") << "not a jpeg";
  std::string m = attempt({kOpenCvData + "left01.jpg", (dir.path / "broken.jpg").string()});
  EXPECT_NE(m.find("broken.jpg: cannot decode the image"), std::string::npos) << m;
  m = attempt({kOpenCvData + "left01.jpg", kOpenCvData + "nonexistent.jpg"});
  EXPECT_NE(m.find("nonexistent.jpg: image file does not exist"), std::string::npos) << m;
  // Too few views.
  m = attempt({kOpenCvData + "left01.jpg", kOpenCvData + "left02.jpg"});
  EXPECT_NE(m.find("too few usable views: 2, need at least 3"), std::string::npos) << m;
  // Board not found (wrong size given): every view rejected with the reason.
  const BoardSpec wrong{BoardType::Chessboard, 7, 5, 0.025, "36h11", 0, 0, {}};
  try {
    calibrateFromImages({kOpenCvData + "left01.jpg", kOpenCvData + "left02.jpg", kOpenCvData + "left03.jpg"}, wrong);
    m = "no error";
  } catch (const core::InvalidInput& e) {
    m = e.what();
  }
  EXPECT_NE(m.find("left02.jpg: chessboard 7x5 inner corners not found"), std::string::npos) << m;
  // Mismatched sizes.
  if (fs::exists(kVispData + "calibration/grid36-01.pgm")) {
    cv::Mat small;
    cv::resize(readGray(kOpenCvData + "left02.jpg"), small, cv::Size(320, 240));
    cv::imwrite((dir.path / "small.png").string(), small);
    m = attempt({kOpenCvData + "left01.jpg", (dir.path / "small.png").string(), kOpenCvData + "left03.jpg"});
    EXPECT_NE(m.find("small.png: image size 320x240 differs from 640x480"), std::string::npos) << m;
  }
  // No output was written by any failed attempt (only the inputs made above are there).
  EXPECT_FALSE(fs::exists(dir.path / "cam.xml"));
  EXPECT_FALSE(fs::exists(dir.path / "cam.yaml"));
  std::size_t others = 0;
  for (const auto& e : fs::directory_iterator(dir.path))
    if (e.path().filename() != "broken.jpg" && e.path().filename() != "small.png") ++others;
  EXPECT_EQ(others, 0u);
}
