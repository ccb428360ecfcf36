// Regressions for parser defects found by the fuzz targets (fuzz/README.md, "Findings"): each
// input must be refused with core::InvalidInput naming what was wrong, never another exception.

#include <gtest/gtest.h>

#include <filesystem>
#include <opencv2/core.hpp>
#include <string>

#include "viewline/core/error.h"
#include "viewline/io/camera_io.h"
#include "viewline/io/config_edit.h"
#include "viewline/io/rig.h"

namespace io = viewline::io;

namespace {
template <class F>
std::string invalidInputMessage(F&& f) {
  try {
    f();
  } catch (const viewline::core::InvalidInput& e) {
    return e.what();
  }
  return "(no InvalidInput)";
}
}  // namespace

// F1: std::stoi threw std::out_of_range on a list index beyond int; nothing caught it.
TEST(FuzzRegression, ListIndexBeyondIntIsInvalidInput) {
  const std::string msg = invalidInputMessage([] { io::parseKeyValue("cameras[99999999999].sigma_px=1"); });
  EXPECT_NE(msg.find("cameras[99999999999].sigma_px"), std::string::npos) << msg;
  EXPECT_NE(msg.find("too large"), std::string::npos) << msg;
  EXPECT_NO_THROW(io::parseDottedKey("cameras[999999999].sigma_px"));  // 9 digits: still an index
}

// F3: a file name the file system refuses (a component over NAME_MAX: ENAMETOOLONG) made the
// throwing std::filesystem queries raise filesystem_error instead of "does not exist".
TEST(FuzzRegression, FileNameTooLongIsInvalidInput) {
  const std::string name(300, 'x');
  EXPECT_THROW(io::loadVispCameraXml(name + ".xml", "cam", io::Projection::WithDistortion), viewline::core::InvalidInput);
  EXPECT_THROW(io::loadOpenCvIntrinsics(name + ".yaml"), viewline::core::InvalidInput);
  EXPECT_THROW(io::ConfigNode::loadFile(name + ".yaml"), viewline::core::InvalidInput);
  const io::ConfigNode rig = io::ConfigNode::fromString(
      "cameras:\n  - name: a\n    intrinsics: " + name + ".xml\n    c_M_w: {translation: [0, 0, 1], theta_u_deg: [0, 0, 0]}\n",
      "rig.yaml", "/tmp");
  const std::string msg = invalidInputMessage([&] { io::loadRig(rig); });
  EXPECT_NE(msg.find("rig.yaml:3:"), std::string::npos) << msg;  // names the line of the intrinsics key
}

// F5: a matrix header whose rows is not a plain integer ("rows:(5") made cv::read allocate and clear
// gigabytes (a 10 s timeout under the fuzzer); the header is now checked before OpenCV reads it
// (XML). A YAML file no longer reaches OpenCV (F9): yaml-cpp refuses it, naming the line.
TEST(FuzzRegression, OpenCvMatrixHeaderIsCheckedBeforeReading) {
  const std::string dir = std::string(VIEWLINE_SOURCE_DIR) + "/fuzz/corpus/opencv_yaml/";
  const std::string xml = invalidInputMessage([&] { io::loadOpenCvIntrinsics(dir + "regression_rows_not_an_integer.xml"); });
  EXPECT_NE(xml.find("'distortion_coefficients': rows and cols must be integers"), std::string::npos) << xml;
  const std::string yaml = invalidInputMessage([&] { io::loadOpenCvIntrinsics(dir + "regression_rows_not_an_integer.yaml"); });
  EXPECT_NE(yaml.find("line 12"), std::string::npos) << yaml;
  // A good file still reads.
  EXPECT_NO_THROW(io::loadOpenCvIntrinsics(std::string(VIEWLINE_SOURCE_DIR) + "/fuzz/corpus/opencv_yaml/side.yaml"));
  EXPECT_NO_THROW(io::loadOpenCvIntrinsics(std::string(VIEWLINE_SOURCE_DIR) + "/fuzz/corpus/opencv_yaml/zero_distortion.xml"));
}

// F6: nested aliases (10 lists of 10 aliases of the list above, 8 levels, 452 bytes) made the
// duplicate-key check visit 10^8 nodes (over 30 s; 9 levels: minutes). Each map/list is checked once.
TEST(FuzzRegression, NestedAliasesAreCheckedOnce) {
  const std::string path = std::string(VIEWLINE_SOURCE_DIR) + "/fuzz/corpus/scenario_yaml/regression_nested_aliases.yaml";
  EXPECT_NO_THROW(io::ConfigNode::loadFile(path));  // seconds before the fix: the test's timeout catches it
  EXPECT_THROW(io::ConfigNode::fromString("a: &a {x: 1}\nb: [*a, {y: 1, y: 2}]\n"), viewline::core::InvalidInput);
}

// F9: OpenCV 4.6's YAML parser never returned on a line like "b?x-" after an indented map
// (regression_opencv_parser_hang.yaml). YAML calibration files are read with yaml-cpp: refused at once, and the
// shipped OpenCV YAML files (the rigs' intrinsics) read as before.
TEST(FuzzRegression, OpenCvYamlThatHungOpenCvIsRefusedAndRealFilesRead) {
  const std::string hang = std::string(VIEWLINE_SOURCE_DIR) + "/fuzz/corpus/opencv_yaml/regression_opencv_parser_hang.yaml";
  EXPECT_THROW(io::loadOpenCvIntrinsics(hang), viewline::core::InvalidInput);
  // Every shipped YAML calibration reads exactly as cv::FileStorage reads it.
  int files = 0;
  for (const auto& e : std::filesystem::recursive_directory_iterator(std::string(VIEWLINE_SOURCE_DIR) + "/calib/rigs")) {
    if (e.path().extension() != ".yaml" || e.path().parent_path().filename() != "intrinsics") continue;
    const std::string path = e.path().string();
    const io::OpenCvIntrinsics ours = io::loadOpenCvIntrinsics(path);
    cv::FileStorage fs(path, cv::FileStorage::READ);
    ASSERT_TRUE(fs.isOpened()) << path;
    cv::Mat K, D;
    fs["camera_matrix"] >> K;
    fs["distortion_coefficients"] >> D;
    EXPECT_EQ(static_cast<int>(ours.width), static_cast<int>(fs["image_width"])) << path;
    EXPECT_EQ(static_cast<int>(ours.height), static_cast<int>(fs["image_height"])) << path;
    EXPECT_EQ(ours.rms_px, static_cast<double>(fs["avg_reprojection_error"])) << path;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) EXPECT_EQ(ours.camera_matrix(r, c), K.at<double>(r, c)) << path;
    ASSERT_EQ(ours.distortion.size(), static_cast<Eigen::Index>(D.total())) << path;
    for (int i = 0; i < static_cast<int>(D.total()); ++i) EXPECT_EQ(ours.distortion(i), D.at<double>(i)) << path;
    ++files;
  }
  EXPECT_GE(files, 8);
}

// F11: the yaml-cpp reader of F9's fix let YAML::InvalidNode out of a matrix without 'data'
// (terminate): every yaml-cpp exception is now a refusal naming the file.
TEST(FuzzRegression, OpenCvYamlMatrixWithoutDataIsRefused) {
  const std::string path = std::string(VIEWLINE_SOURCE_DIR) + "/fuzz/corpus/opencv_yaml/regression_yaml_invalid_node.yaml";
  const std::string msg = invalidInputMessage([&] { io::loadOpenCvIntrinsics(path); });
  EXPECT_NE(msg.find("regression_yaml_invalid_node.yaml"), std::string::npos) << msg;
}

// F7: cv::FileStorage::open let a std::length_error (not a cv::Exception) out of a malformed file.
TEST(FuzzRegression, OpenCvStandardExceptionsBecomeInvalidInput) {
  const std::string path = std::string(VIEWLINE_SOURCE_DIR) + "/fuzz/corpus/opencv_yaml/regression_length_error.yaml";
  EXPECT_THROW(io::loadOpenCvIntrinsics(path), viewline::core::InvalidInput);
}

// F10: NUL bytes inside an XML declaration sent OpenCV 4.6's XML parser through a null pointer
// (SEGV in cv::FileStorage::open). A calibration file with a NUL byte is refused, naming its offset.
TEST(FuzzRegression, OpenCvFileWithANulByteIsRefusedBeforeOpenCvReadsIt) {
  const std::string path = std::string(VIEWLINE_SOURCE_DIR) + "/fuzz/corpus/opencv_yaml/regression_nul_in_xml_declaration.xml";
  const std::string msg = invalidInputMessage([&] { io::loadOpenCvIntrinsics(path); });
  EXPECT_NE(msg.find("NUL byte at offset 14"), std::string::npos) << msg;
}
