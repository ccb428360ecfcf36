#include "tool_common.h"

#include <filesystem>
#include <iomanip>

#include "viewline/io/camera_io.h"

namespace viewline::calib::tools {

PoseCamera loadPoseCamera(const std::string& path, const std::string& camera_name, const std::string& projection) {
  const std::string ext = std::filesystem::path(path).extension().string();
  if (ext == ".yaml" || ext == ".yml") return PoseCamera::fromOpenCv(io::loadOpenCvIntrinsics(path));
  return PoseCamera::fromVisp(io::loadVispCameraXml(path, camera_name, io::projectionFromString(projection)).intrinsics);
}

std::string poseYaml(const Eigen::Isometry3d& T, int indent) {
  const std::string pad(static_cast<std::size_t>(indent), ' ');
  std::ostringstream os;
  os << std::setprecision(12);
  const Eigen::Vector3d t = T.translation();
  const Eigen::Matrix3d R = T.linear();
  os << pad << "translation: [" << t.x() << ", " << t.y() << ", " << t.z() << "]\n" << pad << "rotation:\n";
  for (int r = 0; r < 3; ++r) os << pad << "  - [" << R(r, 0) << ", " << R(r, 1) << ", " << R(r, 2) << "]\n";
  return os.str();
}

}  // namespace viewline::calib::tools
