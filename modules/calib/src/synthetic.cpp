#include "viewline/calib/synthetic.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <opencv2/imgproc.hpp>
#include <visp3/core/vpColVector.h>
#include <visp3/robot/vpPtu46.h>

#include "viewline/calib/extrinsics.h"
#include "viewline/calib/render.h"
#include "viewline/core/error.h"
#include "viewline/core/frames.h"
#include "viewline/io/config.h"
#include "viewline/io/rig.h"
#include "viewline/sim/renderer.h"
#include "viewline/sim/scene.h"

namespace viewline::calib {
namespace {

Eigen::Isometry3d rot(const Eigen::Vector3d& axis, double a) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = core::rotation(axis.normalized(), a);
  return T;
}

}  // namespace

const core::Camera& RigTruth::camera(const std::string& n) const {
  for (const auto& c : cameras)
    if (c.name == n) return c;
  throw core::InvalidInput("rig '" + name + "' has no camera '" + n + "'");
}

double fitKdu(double px, double py, double u0, double v0, double kud, unsigned width, unsigned height) {
  // For a grid of undistorted points x (normalised), the forward model gives the pixel, hence
  // x_d = (u - u0) / px; ViSP's back-projection is x = x_d (1 + kdu r_d²): linear in kdu.
  double num = 0.0, den = 0.0;
  const int n = 40;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      const double u = width * (i / double(n)) - 0.5, v = height * (j / double(n)) - 0.5;
      // Exact inverse of the forward model at this pixel (Newton on the radial factor).
      const double xd = (u - u0) / px, yd = (v - v0) / py;
      const double rd2 = xd * xd + yd * yd;
      double s = 1.0;  // x = xd / s with s = 1 + kud r², r² = rd2 / s²
      for (int k = 0; k < 30; ++k) {
        const double f = s - 1.0 - kud * rd2 / (s * s);
        const double df = 1.0 + 2.0 * kud * rd2 / (s * s * s);
        s -= f / df;
      }
      if (!(s > 0.0) || !std::isfinite(s)) continue;
      for (const auto& [d, x] : {std::pair<double, double>{xd, xd / s}, std::pair<double, double>{yd, yd / s}}) {
        const double a = d * rd2;
        num += a * (x - d);
        den += a * a;
      }
    }
  return den > 0.0 ? num / den : 0.0;
}

RigTruth loadRigTruth(const std::string& path) {
  const auto root = io::ConfigNode::loadFile(path);
  RigTruth t;
  t.name = root.get<std::string>("name");
  if (root.has("imaging")) {
    const auto im = root.child("imaging");
    t.imaging.noise_sigma = im.getOr<double>("noise_sigma", t.imaging.noise_sigma);
    t.imaging.blur_sigma_px = im.getOr<double>("blur_sigma_px", t.imaging.blur_sigma_px);
    t.imaging.supersampling = im.getOr<int>("supersampling", t.imaging.supersampling);
    if (!(t.imaging.noise_sigma >= 0.0)) im.fail("noise_sigma", "a number >= 0");
    if (!(t.imaging.blur_sigma_px >= 0.0)) im.fail("blur_sigma_px", "a number >= 0");
    if (t.imaging.supersampling < 1 || t.imaging.supersampling > 16) im.fail("supersampling", "an integer in 1..16");
  }
  if (root.has("hand_eye")) t.e_M_c = io::readPose(root.child("hand_eye").child("e_M_c"));
  for (const auto& c : root.childList("cameras")) {
    core::Camera cam;
    cam.name = c.get<std::string>("name");
    cam.width = c.get<unsigned>("width");
    cam.height = c.get<unsigned>("height");
    if (cam.width < 16 || cam.height < 16) c.fail("width", "an image of at least 16x16 pixels");
    double fx = 0, fy = 0;
    if (c.has("hfov_deg")) {
      const double hfov = c.getAngle("hfov_deg");
      if (!(hfov > 0.0 && hfov < core::deg2rad(170.0))) c.fail("hfov_deg", "an angle in (0, 170)");
      fx = fy = 0.5 * cam.width / std::tan(0.5 * hfov);
    } else {
      fx = c.get<double>("fx");
      fy = c.get<double>("fy");
    }
    if (!(fx > 0.0)) c.fail("fx", "a positive focal length (px)");
    if (!(fy > 0.0)) c.fail("fy", "a positive focal length (px)");
    const double cx = c.getOr<double>("cx", 0.5 * (cam.width - 1.0));
    const double cy = c.getOr<double>("cy", 0.5 * (cam.height - 1.0));
    const double kud = c.getOr<double>("kud", 0.0);
    if (!std::isfinite(kud) || std::abs(kud) > 1.0) c.fail("kud", "a coefficient in [-1, 1]");
    cam.intrinsics.initPersProjWithDistortion(fx, fy, cx, cy, kud, fitKdu(fx, fy, cx, cy, kud, cam.width, cam.height));
    if (c.has("position")) {
      const auto eye = c.get<Eigen::Vector3d>("position");
      const auto target = c.get<Eigen::Vector3d>("look_at");
      cam.c_M_w = core::lookAt(eye, target, Eigen::Vector3d::UnitZ());
      cam.c_M_w = rot(Eigen::Vector3d::UnitZ(), c.getAngleOr("roll_deg", 0.0)) * cam.c_M_w;
    } else if (c.has("c_M_w")) {
      cam.c_M_w = io::readPose(c.child("c_M_w"));
    } else if (c.has("w_M_c")) {
      cam.c_M_w = io::readPose(c.child("w_M_c")).inverse();
    } else if (t.e_M_c) {
      cam.c_M_w = (ptuBaseToEffector(Eigen::Vector2d::Zero()) * *t.e_M_c).inverse();
    } else {
      c.fail("position", "a camera pose (position + look_at, c_M_w or w_M_c)");
    }
    t.cameras.push_back(cam);
  }
  if (t.cameras.empty()) root.fail("cameras", "at least one camera");
  root.finish();
  return t;
}

Eigen::Isometry3d ptuNominalEyeInHand() {
  vpPtu46 ptu;
  vpHomogeneousMatrix cMe;
  ptu.get_cMe(cMe);
  return core::toEigen(cMe).inverse();
}

Eigen::Isometry3d ptuBaseToEffector(const Eigen::Vector2d& q) {
  vpPtu46 ptu;
  vpColVector qv(2);
  qv[0] = q.x();
  qv[1] = q.y();
  vpHomogeneousMatrix fMc;
  ptu.computeMGD(qv, fMc);
  vpHomogeneousMatrix cMe;
  ptu.get_cMe(cMe);
  return core::toEigen(fMc * cMe);
}

cv::Mat renderBoardImage(const core::Camera& camera, const Eigen::Isometry3d& c_M_o, const BoardSpec& board,
                         const SyntheticImaging& imaging, core::Rng& rng) {
  // Texture: an integer number of texels per spacing (or tag module) so that every square / tag
  // edge lies on a texel edge; nearest lookup keeps it crisp, the renderer anti-aliases.
  const double unit = board.type == BoardType::AprilTag ? board.tag_size : board.spacing;
  // Tag and marker boards have fine modules: twice the texels per spacing.
  const double texels = board.type == BoardType::AprilTagGrid || board.type == BoardType::AprilTag ||
                                board.type == BoardType::ChArUco
                            ? 80.0
                            : 40.0;
  const double ppm = texels / unit;
  cv::Point2d origin;
  const cv::Mat tex8 = boardTexture(board, ppm, origin);
  auto tex = std::make_shared<sim::Texture>();
  cv::Mat f;
  tex8.convertTo(f, CV_32F, 1.0 / 255.0);
  cv::cvtColor(f, tex->image, cv::COLOR_GRAY2BGR);
  tex->nearest = true;
  const double w = tex8.cols / ppm, h = tex8.rows / ppm;
  // Rectangle centred on its frame; texture u along x, v along y; the camera looks along +z.
  Eigen::Isometry3d o_M_rect = Eigen::Isometry3d::Identity();
  o_M_rect.translation() = Eigen::Vector3d(origin.x + 0.5 * w, origin.y + 0.5 * h, 0.0);
  // A single tag's pose is ViSP's tag frame (y up, z out of the paper); the texture's is y down.
  const Eigen::Isometry3d c_M_tex = board.type == BoardType::AprilTag ? c_M_o * groundFromBoard(BoardType::Chessboard) : c_M_o;
  // Render in the camera frame (world = camera).
  core::Camera cam = camera;
  cam.c_M_w = Eigen::Isometry3d::Identity();
  sim::Scene scene;
  scene.background_bgr = Eigen::Vector3d(0.45, 0.45, 0.45);
  sim::Primitive rect = sim::makeRectangle("board", c_M_tex * o_M_rect, w, h, Eigen::Vector3d(0.9, 0.9, 0.9),
                                           std::shared_ptr<const sim::Texture>(tex));
  rect.material.unlit = true;
  scene.primitives.push_back(rect);
  sim::RenderSettings rs;
  rs.supersampling = imaging.supersampling;
  sim::Renderer renderer(rs);
  const cv::Mat bgr = renderer.renderScene(scene, cam);
  cv::Mat gray;
  cv::cvtColor(bgr, gray, cv::COLOR_BGR2GRAY);
  // Paper is not pure black and white: ink at 10 %.
  cv::Mat g;
  gray.convertTo(g, CV_32F);
  g = 20.0 + g * (225.0 / 255.0);
  if (imaging.blur_sigma_px > 0.0) cv::GaussianBlur(g, g, cv::Size(0, 0), imaging.blur_sigma_px);
  if (imaging.noise_sigma > 0.0)
    for (int v = 0; v < g.rows; ++v)
      for (int u = 0; u < g.cols; ++u) g.at<float>(v, u) += static_cast<float>(core::gaussian(rng, imaging.noise_sigma));
  cv::Mat out;
  g.convertTo(out, CV_8U);  // rounds and saturates
  return out;
}

std::vector<Eigen::Vector3d> boardOutline(const BoardSpec& board) {
  board.validate();
  if (board.type == BoardType::AprilTag) {
    const double a = board.tag_size;
    return {{-a, -a, 0}, {a, -a, 0}, {a, a, 0}, {-a, a, 0}};
  }
  const double s = board.spacing;
  const int inner = board.type == BoardType::ChArUco ? 1 : 0;  // charuco: cols x rows are squares
  const double w =
      board.type == BoardType::AsymmetricCirclesGrid ? (2 * board.cols - 1) * s : (board.cols - 1 - inner) * s;
  const double h = (board.rows - 1 - inner) * s;
  return {{-s, -s, 0}, {w + s, -s, 0}, {w + s, h + s, 0}, {-s, h + s, 0}};
}

bool boardFullyVisible(const core::Camera& camera, const Eigen::Isometry3d& c_M_o, const BoardSpec& board,
                       double margin_px, double max_obliquity_rad) {
  const auto outline = boardOutline(board);
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const auto& p : outline) {
    const Eigen::Vector3d pc = c_M_o * p;
    centre += pc / 4.0;
    if (pc.z() < 0.05) return false;
    core::Camera cam = camera;
    cam.c_M_w = Eigen::Isometry3d::Identity();
    const auto uv = cam.project(pc);
    if (!uv || !cam.inImage(*uv, margin_px)) return false;
  }
  const Eigen::Vector3d n = c_M_o.linear().col(2);  // into the board (single tag: out of it)
  const double c = std::abs(n.dot(centre.normalized()));
  return std::acos(std::min(1.0, c)) <= max_obliquity_rad;
}

std::vector<Eigen::Isometry3d> sampleIntrinsicsPoses(const core::Camera& camera, const BoardSpec& board, int n,
                                                     core::Rng& rng, const IntrinsicsViewOptions& o) {
  const auto outline = boardOutline(board);
  const Eigen::Vector3d centre_o = 0.5 * (outline[0] + outline[2]);
  const double board_w = (outline[1] - outline[0]).norm();
  std::vector<Eigen::Isometry3d> poses;
  core::Camera cam = camera;
  cam.c_M_w = Eigen::Isometry3d::Identity();
  for (int attempt = 0; static_cast<int>(poses.size()) < n; ++attempt) {
    if (attempt > 2000 * std::max(1, n)) throw core::NumericalError("sampleIntrinsicsPoses: no visible pose found");
    const double fill = core::uniform(rng, o.min_fill, o.max_fill);
    const double depth = cam.intrinsics.get_px() * board_w / (fill * cam.width);
    const Eigen::Vector2d uv(core::uniform(rng, 0.25, 0.75) * cam.width, core::uniform(rng, 0.25, 0.75) * cam.height);
    const Eigen::Vector2d xy = cam.pixelToNormalized(uv);
    // Alternate the sign of the dominant tilt so the views are balanced.
    const double tx = core::uniform(rng, -o.max_tilt_rad, o.max_tilt_rad);
    const double ty = core::uniform(rng, -o.max_tilt_rad, o.max_tilt_rad);
    const double rz = core::uniform(rng, -0.35, 0.35) + (poses.size() % 4 == 3 ? core::kPi / 2 : 0.0);
    Eigen::Isometry3d c_M_o = rot(Eigen::Vector3d::UnitX(), tx) * rot(Eigen::Vector3d::UnitY(), ty) *
                              rot(Eigen::Vector3d::UnitZ(), rz);
    c_M_o.translation() = depth * Eigen::Vector3d(xy.x(), xy.y(), 1.0) - c_M_o.linear() * centre_o;
    if (board.type == BoardType::AprilTag) c_M_o = c_M_o * groundFromBoard(BoardType::Chessboard);
    if (boardFullyVisible(cam, c_M_o, board, o.margin_px, o.max_obliquity_rad)) poses.push_back(c_M_o);
  }
  return poses;
}

Eigen::Vector3d commonViewPoint(const std::vector<core::Camera>& cameras) {
  // Minimise Σ |(I - d dᵀ)(p - c)|² over p: Σ (I - d dᵀ) p = Σ (I - d dᵀ) c.
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (const auto& cam : cameras) {
    const Eigen::Vector3d c = cam.center_w();
    const Eigen::Vector3d d = cam.c_M_w.linear().transpose().col(2);
    const Eigen::Matrix3d P = Eigen::Matrix3d::Identity() - d * d.transpose();
    A += P;
    b += P * c;
  }
  if (cameras.size() < 2 || std::abs(A.determinant()) < 1e-9) {
    const auto& cam = cameras.front();
    return cam.center_w() + 2.0 * cam.c_M_w.linear().transpose().col(2);
  }
  return A.ldlt().solve(b);
}

std::vector<Eigen::Isometry3d> sampleRigPoses(const std::vector<core::Camera>& cameras, const BoardSpec& board, int n,
                                              core::Rng& rng, const RigViewOptions& o) {
  const auto outline = boardOutline(board);
  const Eigen::Vector3d centre_o = 0.5 * (outline[0] + outline[2]);
  std::vector<Eigen::Isometry3d> poses;
  for (int attempt = 0; static_cast<int>(poses.size()) < n; ++attempt) {
    if (attempt > 5000 * std::max(1, n)) throw core::NumericalError("sampleRigPoses: no pose seen by every camera found");
    const Eigen::Vector3d p = o.center_w + Eigen::Vector3d(core::uniform(rng, -o.radius, o.radius),
                                                           core::uniform(rng, -o.radius, o.radius),
                                                           core::uniform(rng, -o.radius, o.radius));
    // Board z (into the paper) points away from the cameras: minus the mean unit direction to them.
    Eigen::Vector3d towards = Eigen::Vector3d::Zero();
    for (const auto& cam : cameras) towards += (cam.center_w() - p).normalized();
    Eigen::Vector3d z = -towards.normalized();
    const Eigen::Vector3d axis(core::gaussian(rng), core::gaussian(rng), core::gaussian(rng));
    z = core::rotation(axis.normalized(), core::uniform(rng, 0.0, o.max_tilt_rad)) * z;
    // x roughly horizontal (board rows level), y down the columns; in-plane rotation ±20°.
    Eigen::Vector3d x = Eigen::Vector3d::UnitZ().cross(z);
    if (x.norm() < 1e-6) x = Eigen::Vector3d::UnitX();
    x.normalize();
    if (x.dot(Eigen::Vector3d::UnitZ().cross(-z)) < 0.0) x = -x;
    Eigen::Matrix3d R;
    R.col(0) = x;
    R.col(2) = z;
    R.col(1) = z.cross(x);
    if (R.col(1).z() > 0.0) {  // keep y pointing down in the world (rows below each other)
      R.col(0) = -R.col(0);
      R.col(1) = -R.col(1);
    }
    R = core::rotation(z, core::uniform(rng, -0.35, 0.35)) * R;
    Eigen::Isometry3d w_M_o = Eigen::Isometry3d::Identity();
    w_M_o.linear() = R;
    w_M_o.translation() = p - R * centre_o;
    if (board.type == BoardType::AprilTag) w_M_o = w_M_o * groundFromBoard(BoardType::Chessboard);
    bool ok = true;
    for (const auto& cam : cameras) ok = ok && boardFullyVisible(cam, cam.c_M_w * w_M_o, board, o.margin_px, o.max_obliquity_rad);
    if (ok) poses.push_back(w_M_o);
  }
  return poses;
}

Eigen::Isometry3d floorBoardPose(const BoardSpec& board, const Eigen::Vector2d& origin_w, double yaw_rad) {
  Eigen::Isometry3d w_M_g = rot(Eigen::Vector3d::UnitZ(), yaw_rad);
  w_M_g.translation() = Eigen::Vector3d(origin_w.x(), origin_w.y(), 0.0);
  return w_M_g * groundFromBoard(board.type).inverse();
}

CameraErrors compareCamera(const core::Camera& truth, const core::Camera& cal) {
  if (truth.width != cal.width || truth.height != cal.height)
    throw core::InvalidInput("camera '" + cal.name + "': calibrated image size " + std::to_string(cal.width) + "x" +
                             std::to_string(cal.height) + " differs from the truth's");
  CameraErrors e;
  e.name = truth.name;
  e.truth = truth.intrinsics;
  e.calibrated = cal.intrinsics;
  e.position_error_m = (cal.center_w() - truth.center_w()).norm();
  e.rotation_error_rad = core::rotationAngle(cal.c_M_w.linear(), truth.c_M_w.linear());
  const double f = truth.focalPx();
  double s2 = 0.0, w2 = 0.0;
  int n = 0;
  const Eigen::Matrix3d w_R_ct = truth.c_M_w.linear().transpose(), w_R_cc = cal.c_M_w.linear().transpose();
  for (int j = 0; j <= 24; ++j)
    for (int i = 0; i <= 32; ++i) {
      const Eigen::Vector2d uv(i / 32.0 * (truth.width - 1.0), j / 24.0 * (truth.height - 1.0));
      const Eigen::Vector2d xt = sim::undistortExact(truth, uv);
      if (!xt.allFinite()) continue;
      const Eigen::Vector2d xc = cal.pixelToNormalized(uv);
      const Eigen::Vector3d rt = Eigen::Vector3d(xt.x(), xt.y(), 1.0).normalized();
      const Eigen::Vector3d rc = Eigen::Vector3d(xc.x(), xc.y(), 1.0).normalized();
      const double a = f * std::atan2(rt.cross(rc).norm(), rt.dot(rc));
      const Eigen::Vector3d wt = w_R_ct * rt, wc = w_R_cc * rc;
      const double b = f * std::atan2(wt.cross(wc).norm(), wt.dot(wc));
      s2 += a * a;
      w2 += b * b;
      e.ray_max_px = std::max(e.ray_max_px, a);
      e.world_ray_max_px = std::max(e.world_ray_max_px, b);
      ++n;
    }
  e.ray_rms_px = std::sqrt(s2 / std::max(1, n));
  e.world_ray_rms_px = std::sqrt(w2 / std::max(1, n));
  return e;
}

std::vector<CameraErrors> compareRig(const std::vector<core::Camera>& truth, const std::vector<core::Camera>& calibrated) {
  std::vector<CameraErrors> out;
  for (const auto& t : truth) {
    const core::Camera* c = nullptr;
    for (const auto& k : calibrated)
      if (k.name == t.name) c = &k;
    if (!c) throw core::InvalidInput("calibrated rig has no camera '" + t.name + "'");
    out.push_back(compareCamera(t, *c));
  }
  return out;
}

}  // namespace viewline::calib
