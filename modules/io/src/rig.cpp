#include "viewline/io/rig.h"

#include <Eigen/SVD>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <set>
#include <sstream>

#include "viewline/core/error.h"
#include "viewline/core/frames.h"
#include "viewline/io/files.h"

namespace fs = std::filesystem;

namespace viewline::io {

Eigen::Isometry3d readPose(const ConfigNode& node) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = node.get<Eigen::Vector3d>("translation");
  const bool has_r = node.has("rotation");
  const bool has_tu = node.has("theta_u_deg");
  if (has_r == has_tu) node.fail("", "exactly one of 'rotation' (3x3 rows) or 'theta_u_deg' ([rx, ry, rz])");
  if (has_r) {
    const Eigen::Matrix3d R = node.get<Eigen::Matrix3d>("rotation");
    if ((R * R.transpose() - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() > 1e-6 || R.determinant() < 0.0)
      node.fail("rotation", "an orthonormal rotation matrix with determinant +1 (tolerance 1e-6)");
    Eigen::JacobiSVD<Eigen::Matrix3d> svd(R, Eigen::ComputeFullU | Eigen::ComputeFullV);
    T.linear() = svd.matrixU() * svd.matrixV().transpose();
  } else {
    const Eigen::Vector3d tu = node.get<Eigen::Vector3d>("theta_u_deg") * (core::kPi / 180.0);
    const double angle = tu.norm();
    T.linear() = angle > 0.0 ? Eigen::AngleAxisd(angle, tu / angle).toRotationMatrix() : Eigen::Matrix3d::Identity();
  }
  return T;
}

std::vector<core::Camera> loadRig(const ConfigNode& node) {
  std::vector<core::Camera> cameras;
  std::set<std::string> names;
  const auto list = node.childList("cameras");
  if (list.empty()) node.fail("cameras", "at least one camera");
  for (const auto& c : list) {
    core::Camera cam;
    cam.name = c.get<std::string>("name");
    if (cam.name.empty() || !names.insert(cam.name).second) c.fail("name", "a non-empty camera name, unique in the rig");
    const std::string file = c.getPath("intrinsics");
    const std::string in_file_name = c.getOr<std::string>("camera_name", cam.name);
    const Projection proj = projectionFromString(
        c.getChoiceOr("projection", {"with_distortion", "without_distortion"}, "with_distortion"));
    const unsigned w = c.getOr<unsigned>("width", 0);
    const unsigned h = c.getOr<unsigned>("height", 0);
    const std::string ext = fs::path(file).extension().string();
    try {
      if (ext == ".yaml" || ext == ".yml") {
        const OpenCvIntrinsics o = loadOpenCvIntrinsics(file);
        cam.intrinsics = toVispWithoutDistortion(o, file);
        cam.width = o.width;
        cam.height = o.height;
      } else {
        const CameraXml x = loadVispCameraXml(file, in_file_name, proj);  // size checked below
        cam.intrinsics = x.intrinsics;
        cam.width = x.width;
        cam.height = x.height;
      }
    } catch (const core::InvalidInput& e) {
      throw core::InvalidInput(c.location("intrinsics") + ": camera '" + cam.name + "': " + e.what());
    }
    if ((w && cam.width != w) || (h && cam.height != h))
      c.fail("width", "the image size of the intrinsics file (" + std::to_string(cam.width) + "x" +
                          std::to_string(cam.height) + ")");
    if (cam.width == 0 || cam.height == 0) c.fail("intrinsics", "a file that gives the image size");
    const bool has_c = c.has("c_M_w");
    const bool has_w = c.has("w_M_c");
    if (has_c == has_w) c.fail("", "exactly one of 'c_M_w' (world in camera) or 'w_M_c' (camera in world)");
    cam.c_M_w = has_c ? readPose(c.child("c_M_w")) : readPose(c.child("w_M_c")).inverse();
    cameras.push_back(cam);
  }
  return cameras;
}

std::vector<core::Camera> loadRig(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))  // else yaml-cpp's read fails with "basic_filebuf::underflow", unnamed
    throw core::InvalidInput(path + ": is a directory (expected a rig file)");
  const ConfigNode root = ConfigNode::loadFile(path);
  auto cams = loadRig(root);
  root.finish();
  return cams;
}

std::vector<std::string> saveRig(const std::string& path, const std::vector<core::Camera>& cameras,
                                 const std::string& comment) {
  if (cameras.empty()) throw core::InvalidInput(path + ": a rig needs at least one camera");
  std::set<std::string> names;
  for (const auto& c : cameras)
    if (c.name.empty() || c.name.find('/') != std::string::npos || !names.insert(c.name).second)
      throw core::InvalidInput(path + ": camera names must be distinct plain names, got '" + c.name + "'");
  StagedFiles out;
  const fs::path dir = fs::path(path).parent_path();
  std::ostringstream y;
  y << std::setprecision(17);
  y << "# viewline camera rig (io::loadRig). c_M_w maps world to camera coordinates.\n";
  if (!comment.empty()) {
    std::istringstream lines(comment);
    for (std::string l; std::getline(lines, l);) y << "# " << l << "\n";
  }
  y << "cameras:\n";
  for (const auto& c : cameras) {
    const bool dist = c.intrinsics.get_projModel() == vpCameraParameters::perspectiveProjWithDistortion;
    const std::string xml = c.name + ".xml";
    vpCameraParameters without;
    without.initPersProjWithoutDistortion(c.intrinsics.get_px(), c.intrinsics.get_py(), c.intrinsics.get_u0(),
                                          c.intrinsics.get_v0());
    std::optional<vpCameraParameters> with;
    if (dist) with = c.intrinsics;
    std::string tmp = out.stage((dir / xml).string()) + ".xml";
    writeVispCameraXmlTo(tmp, c.name, without, with, c.width, c.height);
    fs::rename(tmp, fs::path(tmp).replace_extension());
    const Eigen::Matrix3d R = c.c_M_w.linear();
    const Eigen::Vector3d t = c.c_M_w.translation();
    y << "  - name: " << c.name << "\n"
      << "    intrinsics: " << xml << "\n"
      << "    projection: " << toString(dist ? Projection::WithDistortion : Projection::WithoutDistortion) << "\n"
      << "    width: " << c.width << "\n"
      << "    height: " << c.height << "\n"
      << "    c_M_w:\n"
      << "      translation: [" << t.x() << ", " << t.y() << ", " << t.z() << "]\n"
      << "      rotation:\n";
    for (int r = 0; r < 3; ++r) y << "        - [" << R(r, 0) << ", " << R(r, 1) << ", " << R(r, 2) << "]\n";
  }
  {
    std::ofstream f(out.stage(path));
    f << y.str();
    if (!f) throw core::InvalidInput(path + ": cannot write the rig file");
  }
  std::vector<std::string> written = out.targets();
  out.commit();
  return written;
}

}  // namespace viewline::io
