#include "viewline/io/camera_io.h"

#include <filesystem>
#include <fstream>
#include <iostream>
#include <mutex>
#include <optional>
#include <sstream>
#include <utility>
#include <yaml-cpp/yaml.h>
#include <opencv2/core.hpp>
#include <visp3/core/vpException.h>
#include <visp3/core/vpXmlParserCamera.h>

#include "viewline/core/error.h"
#include "viewline/io/files.h"

namespace fs = std::filesystem;

namespace viewline::io {
namespace {

// The whole file (calibration files are small); throws when it cannot be read.
std::string readWholeFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw core::InvalidInput(path + ": cannot open for reading");
  std::stringstream buffer;
  buffer << in.rdbuf();
  if (in.bad()) throw core::InvalidInput(path + ": read error");
  return buffer.str();
}

vpCameraParameters::vpCameraParametersProjType toVisp(Projection p) {
  return p == Projection::WithDistortion ? vpCameraParameters::perspectiveProjWithDistortion
                                         : vpCameraParameters::perspectiveProjWithoutDistortion;
}

// vpXmlParserCamera::parse (ViSP 3.5) writes `Found camera with name: "..."` to std::cout for every
// camera in the file, unconditionally: a rig load in each of a sweep's runs filled the terminal.
// std::cout's buffer is swapped for the parse only; the lock serialises concurrent loads (the
// swap is process-wide, so another thread's std::cout output in that instant would be dropped:
// our library code prints progress to std::cerr).
class QuietStdout {
public:
  QuietStdout() : lock_(mutex()), previous_(std::cout.rdbuf(nullptr)) {}
  ~QuietStdout() { std::cout.rdbuf(previous_); std::cout.clear(); }
  QuietStdout(const QuietStdout&) = delete;
  QuietStdout& operator=(const QuietStdout&) = delete;

private:
  static std::mutex& mutex() {
    static std::mutex m;
    return m;
  }
  std::lock_guard<std::mutex> lock_;
  std::streambuf* previous_;
};

std::string extensionOf(const std::string& path) {
  std::string e = fs::path(path).extension().string();
  for (auto& c : e) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return e;
}
// cv::read(FileNode, Mat) sizes the matrix from the node's rows/cols before it looks at the data: a
// 'rows' that is not a plain integer (e.g. "rows:(5") made OpenCV 4.6 allocate and clear gigabytes
// (found by fuzz_opencv_yaml). Our matrices are small: check the header first.
void checkMatrixNode(const cv::FileNode& n, const std::string& path, const char* key) {
  if (n.empty() || n.isNone()) return;  // absent: the caller's checks name it
  const std::string what = path + ": '" + key + "': ";
  if (!n.isMap()) throw core::InvalidInput(what + "expected an OpenCV matrix (rows, cols, dt, data)");
  const cv::FileNode r = n["rows"], c = n["cols"], d = n["data"];
  if (!r.isInt() || !c.isInt() || static_cast<int>(r) < 1 || static_cast<int>(c) < 1 || static_cast<int>(r) > 16 ||
      static_cast<int>(c) > 16)
    throw core::InvalidInput(what + "rows and cols must be integers from 1 to 16");
  if (!d.isSeq() || d.size() != static_cast<std::size_t>(static_cast<int>(r) * static_cast<int>(c)))
    throw core::InvalidInput(what + "data must be a list of rows x cols numbers");
}

// True when the first character that is not white space is '<' (OpenCV's own format test).
bool startsLikeXml(const std::string& text) {
  const auto first = text.find_first_not_of(" \t\r\n\f\v");
  return first != std::string::npos && text[first] == '<';
}

// An XML calibration file through cv::FileStorage; K and D with the file's rows and columns.
void readOpenCvXml(const std::string& path, Eigen::MatrixXd& K, Eigen::MatrixXd& D, OpenCvIntrinsics& out) {
  cv::FileStorage fsr;
  try {
    fsr.open(path, cv::FileStorage::READ);
  } catch (const cv::Exception& e) {
    throw core::InvalidInput(path + ": cannot parse as OpenCV FileStorage: " + e.what());
  } catch (const std::exception& e) {  // OpenCV 4.6 lets std::length_error out of a bad file (fuzz_opencv_yaml)
    throw core::InvalidInput(path + ": cannot parse as OpenCV FileStorage: " + e.what());
  }
  if (!fsr.isOpened()) throw core::InvalidInput(path + ": cannot open as OpenCV FileStorage");
  cv::Mat k, d;
  try {
    checkMatrixNode(fsr["camera_matrix"], path, "camera_matrix");
    checkMatrixNode(fsr["distortion_coefficients"], path, "distortion_coefficients");
    fsr["camera_matrix"] >> k;
    fsr["distortion_coefficients"] >> d;
    int w = 0, h = 0;
    fsr["image_width"] >> w;
    fsr["image_height"] >> h;
    if (w < 0 || h < 0) throw core::InvalidInput(path + ": image_width/image_height must be positive");
    out.width = static_cast<unsigned>(w);
    out.height = static_cast<unsigned>(h);
    if (!fsr["avg_reprojection_error"].empty()) fsr["avg_reprojection_error"] >> out.rms_px;
  } catch (const cv::Exception& e) {
    throw core::InvalidInput(path + ": bad OpenCV intrinsics: " + e.what());
  } catch (const core::InvalidInput&) {
    throw;
  } catch (const std::exception& e) {  // (as open: not only cv::Exception comes out of FileStorage)
    throw core::InvalidInput(path + ": bad OpenCV intrinsics: " + e.what());
  }
  auto toEigen = [](cv::Mat m) {
    Eigen::MatrixXd e(m.rows, m.cols);
    if (m.empty()) return e;
    m = m.reshape(1);
    m.convertTo(m, CV_64F);
    for (int r = 0; r < m.rows; ++r)
      for (int c = 0; c < m.cols; ++c) e(r, c) = m.at<double>(r, c);
    return e;
  };
  K = toEigen(k);
  D = toEigen(d);
}

// An OpenCV matrix node {rows, cols, dt, data} read with yaml-cpp (rows and cols 1-16, as
// checkMatrixNode); empty when the key is absent.
Eigen::MatrixXd yamlMatrix(const YAML::Node& root, const std::string& path, const char* key) {
  const YAML::Node n = root[key];
  if (!n || n.IsNull()) return {};
  const std::string what = path + ": '" + key + "': ";
  if (!n.IsMap()) throw core::InvalidInput(what + "expected an OpenCV matrix (rows, cols, dt, data)");
  int rows = 0, cols = 0;
  try {
    rows = n["rows"].as<int>();
    cols = n["cols"].as<int>();
  } catch (const YAML::Exception&) {
    throw core::InvalidInput(what + "rows and cols must be integers from 1 to 16");
  }
  if (rows < 1 || cols < 1 || rows > 16 || cols > 16)
    throw core::InvalidInput(what + "rows and cols must be integers from 1 to 16");
  const YAML::Node data = n["data"];
  if (!data || !data.IsSequence() || data.size() != static_cast<std::size_t>(rows * cols))
    throw core::InvalidInput(what + "data must be a list of rows x cols numbers");
  Eigen::MatrixXd m(rows, cols);
  for (int i = 0; i < rows * cols; ++i) {
    try {
      m(i / cols, i % cols) = data[static_cast<std::size_t>(i)].as<double>();
    } catch (const YAML::Exception&) {
      throw core::InvalidInput(what + "data item " + std::to_string(i + 1) + " is not a number");
    }
  }
  return m;
}

// The keys of a parsed YAML calibration file (readOpenCvYaml).
void readOpenCvYamlKeys(const YAML::Node& root, const std::string& path, Eigen::MatrixXd& K, Eigen::MatrixXd& D,
                        OpenCvIntrinsics& out) {
  if (!root.IsMap()) throw core::InvalidInput(path + ": expected a map of OpenCV calibration keys (camera_matrix, ...)");
  K = yamlMatrix(root, path, "camera_matrix");
  D = yamlMatrix(root, path, "distortion_coefficients");
  auto integer = [&](const char* key) {
    const YAML::Node n = root[key];
    if (!n || n.IsNull()) return 0;
    try {
      return n.as<int>();
    } catch (const YAML::Exception&) {
      throw core::InvalidInput(path + ": '" + key + "': expected an integer");
    }
  };
  const int w = integer("image_width"), h = integer("image_height");
  if (w < 0 || h < 0) throw core::InvalidInput(path + ": image_width/image_height must be positive");
  out.width = static_cast<unsigned>(w);
  out.height = static_cast<unsigned>(h);
  if (const YAML::Node r = root["avg_reprojection_error"]; r && !r.IsNull()) {
    try {
      out.rms_px = r.as<double>();
    } catch (const YAML::Exception&) {
      throw core::InvalidInput(path + ": 'avg_reprojection_error': expected a number");
    }
  }
}

// A YAML calibration file through yaml-cpp: OpenCV's first line "%YAML:1.0" is not YAML 1.2's
// directive syntax and is skipped; the !!opencv-matrix tags are ignored.
void readOpenCvYaml(std::string text, const std::string& path, Eigen::MatrixXd& K, Eigen::MatrixXd& D,
                    OpenCvIntrinsics& out) {
  if (text.rfind("%YAML", 0) == 0) {
    const auto eol = text.find('\n');
    text = eol == std::string::npos ? std::string() : text.substr(eol + 1);
  }
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw core::InvalidInput(path + ": cannot parse as YAML: " + e.what());
  }
  try {  // yaml-cpp throws on a node it cannot use (e.g. InvalidNode): refused, naming the file
    readOpenCvYamlKeys(root, path, K, D, out);
  } catch (const YAML::Exception& e) {
    throw core::InvalidInput(path + ": bad OpenCV calibration YAML: " + e.what());
  }
}

}  // namespace

std::string toString(Projection p) {
  return p == Projection::WithDistortion ? "with_distortion" : "without_distortion";
}

Projection projectionFromString(const std::string& s) {
  if (s == "with_distortion") return Projection::WithDistortion;
  if (s == "without_distortion") return Projection::WithoutDistortion;
  throw core::InvalidInput("projection '" + s + "': expected with_distortion or without_distortion");
}

CameraXml loadVispCameraXml(const std::string& path, const std::string& camera_name, Projection projection,
                            unsigned width, unsigned height) {
  std::error_code ec;  // the throwing overload raised filesystem_error on e.g. a name too long (found by fuzz_rig)
  if (!fs::is_regular_file(path, ec)) throw core::InvalidInput(path + ": camera XML file does not exist");
  vpXmlParserCamera parser;
  vpCameraParameters cam;
  int status = vpXmlParserCamera::SEQUENCE_ERROR;
  try {
    const QuietStdout quiet;
    status = parser.parse(cam, path, camera_name, toVisp(projection), width, height);
  } catch (const vpException& e) {
    throw core::InvalidInput(path + ": cannot parse the ViSP camera XML: " + e.getStringMessage());
  }
  if (status != vpXmlParserCamera::SEQUENCE_OK || cam.get_projModel() != toVisp(projection)) {
    std::string size = (width || height) ? " of size " + std::to_string(width) + "x" + std::to_string(height) : "";
    throw core::InvalidInput(path + ": no camera named '" + camera_name + "'" + size + " with model " +
                             toString(projection) + " (vpXmlParserCamera)");
  }
  if (!(cam.get_px() > 0.0) || !(cam.get_py() > 0.0))
    throw core::InvalidInput(path + ": camera '" + camera_name + "': px and py must be positive");
  CameraXml out;
  out.intrinsics = cam;
  out.width = parser.getWidth();
  out.height = parser.getHeight();
  return out;
}

void writeVispCameraXmlTo(const std::string& path, const std::string& camera_name,
                          const vpCameraParameters& without_distortion,
                          const std::optional<vpCameraParameters>& with_distortion, unsigned width,
                          unsigned height, const std::string& additional_info) {
  if (camera_name.empty()) throw core::InvalidInput(path + ": camera name must not be empty");
  if (without_distortion.get_projModel() != vpCameraParameters::perspectiveProjWithoutDistortion)
    throw core::InvalidInput(path + ": the first model must be the one without distortion");
  if (with_distortion && with_distortion->get_projModel() != vpCameraParameters::perspectiveProjWithDistortion)
    throw core::InvalidInput(path + ": the second model must be the one with distortion");
  std::error_code ec;
  fs::remove(path, ec);  // vpXmlParserCamera::save merges into an existing file: start afresh
  vpXmlParserCamera parser;
  if (parser.save(without_distortion, path, camera_name, width, height, additional_info) !=
      vpXmlParserCamera::SEQUENCE_OK)
    throw core::InvalidInput(path + ": vpXmlParserCamera could not save camera '" + camera_name + "'");
  if (with_distortion && parser.save(*with_distortion, path, camera_name, width, height) !=
                             vpXmlParserCamera::SEQUENCE_OK)
    throw core::InvalidInput(path + ": vpXmlParserCamera could not save the distortion model of '" +
                             camera_name + "'");
}

void saveVispCameraXml(const std::string& path, const std::string& camera_name,
                       const vpCameraParameters& without_distortion,
                       const std::optional<vpCameraParameters>& with_distortion, unsigned width, unsigned height,
                       const std::string& additional_info) {
  StagedFiles out;
  std::string tmp = out.stage(path);
  tmp += ".xml";  // vpXmlParserCamera wants an .xml name
  writeVispCameraXmlTo(tmp, camera_name, without_distortion, with_distortion, width, height, additional_info);
  std::error_code ec;
  fs::rename(tmp, fs::path(tmp).replace_extension().string(), ec);
  if (ec) throwFileError(path + ": cannot write", ec.value());
  out.commit();
}

OpenCvIntrinsics loadOpenCvIntrinsics(const std::string& path) {
  std::error_code ec;  // (as loadVispCameraXml: no filesystem_error on a bad name)
  if (!fs::is_regular_file(path, ec)) throw core::InvalidInput(path + ": OpenCV intrinsics file does not exist");
  // OpenCV 4.6's FileStorage parsers read lines as C strings: a NUL byte inside an XML
  // declaration sent its XML parser through a null pointer (fuzz_opencv_yaml). A calibration
  // file is text, so a NUL byte is refused before any parser sees the file.
  std::string text = readWholeFile(path);
  if (const auto offset = text.find('\0'); offset != std::string::npos) {
    throw core::InvalidInput(path + ": not a text file (a NUL byte at offset " + std::to_string(offset) +
                             "); expected an OpenCV calibration file (YAML or XML)");
  }
  // XML goes to cv::FileStorage. YAML goes to yaml-cpp: OpenCV 4.6's own YAML parser loops forever
  // on some malformed files (a line "b?x-" after an indented map; fuzz_opencv_yaml, fuzz/README.md
  // F9), and the calibration keys are plain YAML (OpenCV's "%YAML:1.0" line and !!opencv-matrix
  // tags aside).
  OpenCvIntrinsics out;
  Eigen::MatrixXd K, D;
  if (startsLikeXml(text)) {
    readOpenCvXml(path, K, D, out);  // cv::FileStorage reads the file itself
  } else {
    readOpenCvYaml(std::move(text), path, K, D, out);
  }
  if (K.rows() != 3 || K.cols() != 3)
    throw core::InvalidInput(path + ": 'camera_matrix' missing or not a 3x3 matrix");
  out.camera_matrix = K;
  if (D.size() > 0) {
    out.distortion.resize(D.size());  // the file's order (row-major), whatever the matrix's shape
    for (Eigen::Index r = 0; r < D.rows(); ++r)
      for (Eigen::Index c = 0; c < D.cols(); ++c) out.distortion(r * D.cols() + c) = D(r, c);
  } else {
    out.distortion = Eigen::VectorXd::Zero(5);
  }
  if (!(out.camera_matrix(0, 0) > 0.0) || !(out.camera_matrix(1, 1) > 0.0) || !out.camera_matrix.allFinite())
    throw core::InvalidInput(path + ": 'camera_matrix' must have positive finite focal lengths");
  return out;
}

void writeOpenCvIntrinsicsTo(const std::string& path, const OpenCvIntrinsics& intr, const std::string& format_path) {
  const std::string ext = extensionOf(format_path);
  int flags = cv::FileStorage::WRITE | cv::FileStorage::MEMORY;
  flags |= (ext == ".xml") ? cv::FileStorage::FORMAT_XML : cv::FileStorage::FORMAT_YAML;
  cv::FileStorage fsw(".yaml", flags);
  fsw << "image_width" << static_cast<int>(intr.width);
  fsw << "image_height" << static_cast<int>(intr.height);
  cv::Mat K(3, 3, CV_64F);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) K.at<double>(r, c) = intr.camera_matrix(r, c);
  cv::Mat D(static_cast<int>(intr.distortion.size()), 1, CV_64F);
  for (int i = 0; i < D.rows; ++i) D.at<double>(i) = intr.distortion(i);
  fsw << "camera_matrix" << K;
  fsw << "distortion_coefficients" << D;
  if (intr.rms_px >= 0.0) fsw << "avg_reprojection_error" << intr.rms_px;
  const std::string text = fsw.releaseAndGetString();
  writeTextFileAtomic(path, text);
}

void saveOpenCvIntrinsics(const std::string& path, const OpenCvIntrinsics& intrinsics) {
  writeOpenCvIntrinsicsTo(path, intrinsics, path);
}

vpCameraParameters toVispWithoutDistortion(const OpenCvIntrinsics& intr, const std::string& what, double tolerance) {
  if (intr.distortion.size() > 0 && intr.distortion.cwiseAbs().maxCoeff() > tolerance)
    throw core::InvalidInput(what + ": OpenCV distortion coefficients are not zero; ViSP's radial model cannot "
                                    "represent them: use the ViSP XML written by calibrate-camera instead");
  vpCameraParameters cam;
  cam.initPersProjWithoutDistortion(intr.camera_matrix(0, 0), intr.camera_matrix(1, 1), intr.camera_matrix(0, 2),
                                    intr.camera_matrix(1, 2));
  return cam;
}

}  // namespace viewline::io
